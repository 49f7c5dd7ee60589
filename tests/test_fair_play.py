"""Playing without fouls (issue 32), through the mocked blackboard: the way round robots (``paths``), the
striker that holds back while an opponent nearer the ball plays it, and stopping short of a robot on
the target. The referee's side of the same rules is in ``test_referee.py``; whole games in ``test_match.py``."""

from __future__ import annotations

import math

import pytest
from hypothesis import given
from hypothesis import strategies as st

from tafel.core.testing import ModuleHarness
from tafel.modules.behavior.paths import LEFT, RIGHT, detour, waypoint
from tafel.modules.behavior.role_provider import RoleProvider
from tafel.modules.behavior.soccer_behavior import SoccerBehavior
from tafel.modules.modeling.obstacle_modeler import ObstacleModeler
from tafel.representations.behavior import ActivationGraph
from tafel.representations.game import GameState, Penalty, RobotInfo, State, TeamInfo
from tafel.representations.modeling import BallModel, RobotPose
from tafel.representations.motion_control import MotionInfo, MotionRequest, MotionType
from tafel.representations.obstacles import ROBOT_RADIUS, Obstacle, ObstacleKind, Obstacles, RobotsPercept, SeenRobot
from tafel.representations.team import PlayerRole, Role, TeamMate, TeamMates, TeamMessage

CONTACT = 330.0  # mm between two torsos: the simulated referee's contact (tools/simulation/fouls.py)


def playing() -> GameState:
    team = TeamInfo(team_number=1, players=[RobotInfo() for _ in range(20)])
    return GameState(state=State.playing, teams=[team, TeamInfo(team_number=2)], team_number=1, player_number=2, kicking_team=1)


def striker(pose: RobotPose, ball_field: tuple[float, float], obstacles: list[Obstacle]) -> ModuleHarness:
    """The striker in PLAYING (after the kick-off's wait), the ball at ``ball_field`` (field mm), the given
    obstacles (robot frame)."""
    ball = BallModel(valid=True, seen=True, x=pose.to_robot(*ball_field)[0], y=pose.to_robot(*ball_field)[1])
    return ModuleHarness(SoccerBehavior, playing(), PlayerRole(role=Role.striker), pose, ball, TeamMates(), MotionInfo(),
                         Obstacles(obstacles=obstacles))


def states(harness: ModuleHarness) -> list[tuple[str, str]]:
    return [(o.name, o.state) for o in harness[ActivationGraph].options]


def segment_distance(x: float, y: float, cx: float, cy: float) -> float:
    """mm from (cx, cy) to the straight way from the origin to (x, y)."""
    t = max(0.0, min(1.0, (cx * x + cy * y) / max(x * x + y * y, 1e-9)))
    return math.hypot(t * x - cx, t * y - cy)


# ------------------------------------------------------------------------------------ paths
@given(st.floats(0.0, 2 * math.pi), st.floats(0.0, 440.0), st.floats(-3000.0, 3000.0), st.floats(-3000.0, 3000.0))
def test_a_robot_too_near_another_never_walks_further_in(bearing: float, distance: float, x: float, y: float) -> None:
    """Within the grown disc of another robot (say after it walked up), the way never leads nearer its
    centre: sideways and out (before: the disc was left out and the robot walked on into it)."""
    cx, cy = distance * math.cos(bearing), distance * math.sin(bearing)
    disc = (cx, cy, 2 * ROBOT_RADIUS + 150.0)
    if math.hypot(x - cx, y - cy) < disc[2]:
        return  # the target is in the disc: the caller moves it out first
    way_x, way_y = waypoint(x, y, [disc], margin=0.0)
    assert cx * way_x + cy * way_y <= 1e-6 * max(1.0, math.hypot(cx, cy))  # not towards its centre


def test_two_robots_walking_at_each_other_both_step_to_their_right_and_keep_a_side_asked_for() -> None:
    ahead = [(800.0, 0.0, 450.0)]
    x, y, side = detour(2000.0, 0.0, ahead, 0.0)
    assert side == RIGHT and y < 0.0 and segment_distance(x, y, 800.0, 0.0) >= 450.0
    assert detour(2000.0, 10.0, ahead, 0.0, prefer=LEFT)[2] == LEFT  # dead ahead: the side kept from before
    assert detour(2000.0, -600.0, ahead, 0.0, prefer=LEFT)[2] == RIGHT  # clearly on one side: that side


def test_a_robot_between_two_others_finds_the_free_way_out_or_stands() -> None:
    x, y, _ = detour(1500.0, 0.0, [(200.0, 250.0, 450.0), (200.0, -250.0, 450.0)], 0.0)
    assert x <= 1e-6  # both ahead: back out, never between them
    assert detour(1500.0, 0.0, [(300.0 * math.cos(a), 300.0 * math.sin(a), 450.0) for a in (0.0, 2.1, 4.2)], 0.0)[:2] == (0.0, 0.0)


# ------------------------------------------------------------------------------ the striker
def test_the_striker_walks_round_an_opponent_between_it_and_the_ball_keeping_clear_of_contact() -> None:
    pose = RobotPose(valid=True, x=-2000.0, y=0.0)
    opponent = Obstacle(x=700.0, y=60.0, radius=ROBOT_RADIUS, kind=ObstacleKind.robot)
    harness = striker(pose, (0.0, 0.0), [opponent])
    out = harness.execute()[MotionRequest]
    assert out.motion is MotionType.walk_to and states(harness)[-1] == ("Striker", "kick")
    # clear of contact by what two robots walking at each other close in before they have stopped (~0.2 m)
    assert segment_distance(out.target_x, out.target_y, opponent.x, opponent.y) > CONTACT + 200.0
    assert out.target_rotation == pytest.approx(math.atan2(out.target_y, out.target_x))  # facing the way round


def test_the_striker_holds_back_while_an_opponent_nearer_the_ball_plays_it_then_challenges() -> None:
    pose = RobotPose(valid=True, x=-1500.0, y=300.0)
    ball_field = (-500.0, 0.0)
    bx, by = pose.to_robot(*ball_field)
    opponent = Obstacle(x=bx + 300.0, y=by, kind=ObstacleKind.robot)  # behind the ball, 300 mm from it: nearer than this robot
    harness = striker(pose, ball_field, [opponent])
    out = harness.execute()[MotionRequest]
    assert states(harness)[-2:] == [("Striker", "hold_back"), ("GoTo", "walk")]
    p = SoccerBehavior.Parameters()
    goal_side = pose.to_field(out.target_x, out.target_y)
    # the waiting place: hold_distance from the ball, between it and the own goal (on the line to it)
    assert math.hypot(goal_side[0] - ball_field[0], goal_side[1] - ball_field[1]) == pytest.approx(p.hold_distance, abs=1.0)
    assert goal_side[0] < ball_field[0]
    harness.advance(p.hold_max_s - 1.0)
    assert states(harness)[1:] != [] and ("Striker", "hold_back") in states(harness)
    harness.advance(2.0)  # held back too long: go for the ball, contested or not
    assert ("Striker", "challenge") in states(harness)
    harness.advance(p.challenge_s + 0.5)
    assert ("Striker", "hold_back") in states(harness)  # and wait again while it is still contested


@pytest.mark.parametrize("opponent_distance, holds", [(300.0, True), (980.0, False), (1200.0, False)])
def test_only_an_opponent_nearer_the_ball_makes_the_striker_hold_back_and_never_a_teammate(opponent_distance: float, holds: bool) -> None:
    pose = RobotPose(valid=True, x=-1000.0, y=0.0)  # 1000 mm from the ball: 980 is within contest_margin
    bx, by = pose.to_robot(0.0, 0.0)
    for kind in (ObstacleKind.robot, ObstacleKind.teammate):
        harness = striker(pose, (0.0, 0.0), [Obstacle(x=bx + opponent_distance, y=by, kind=kind)])
        harness.execute()
        assert (("Striker", "hold_back") in states(harness)) is (holds and kind is ObstacleKind.robot), (opponent_distance, kind)


def test_a_robot_on_the_place_to_go_stops_the_walk_short_of_it() -> None:
    pose = RobotPose(valid=True, x=-3000.0, y=0.0)  # READY: the striker's place is (-1000, 0), where another robot stands
    other = Obstacle(x=2000.0, y=0.0, kind=ObstacleKind.robot)
    harness = ModuleHarness(SoccerBehavior, GameState(state=State.ready, teams=[TeamInfo(team_number=1, players=[RobotInfo()] * 20),
                                                                                TeamInfo(team_number=2)],
                                                      team_number=1, player_number=2, kicking_team=2),
                            PlayerRole(role=Role.striker), pose, BallModel(), TeamMates(), MotionInfo(), Obstacles(obstacles=[other]))
    for _ in range(5):
        out = harness.execute()[MotionRequest]
        assert out.motion is MotionType.walk_to
        assert math.hypot(out.target_x - other.x, out.target_y - other.y) > CONTACT + 100.0
        assert segment_distance(out.target_x, out.target_y, other.x, other.y) > CONTACT + 100.0


def test_a_walk_never_leads_more_than_field_margin_beyond_a_line() -> None:
    """The ball on the touchline, the kick's spot behind it beyond the line: the walk stops at the margin
    (leaving the carpet, 0.7 m beyond a line, is a foul)."""
    pose = RobotPose(valid=True, x=2000.0, y=2600.0, rotation=2.5)
    harness = striker(pose, (1000.0, 3120.0), [])
    out = harness.execute()[MotionRequest]
    assert out.motion is MotionType.walk_to
    x, y = pose.to_field(out.target_x, out.target_y)
    assert abs(y) <= 3000.0 + SoccerBehavior.Parameters().field_margin + 1e-6 and abs(x) <= 4500.0


# ------------------------------------------------------------------------------ the roles
def team_game(state: State, player: int, players: int, penalized: tuple[int, ...] = ()) -> GameState:
    """The GameController's view: ``players`` a team, those in ``penalized`` off the field."""
    own = TeamInfo(team_number=1, goalkeeper=1, players=[RobotInfo() for _ in range(20)])
    for number in penalized:
        own.players[number - 1].penalty = Penalty.player_pushing
    return GameState(state=state, players_per_team=players, teams=[own, TeamInfo(team_number=2)], team_number=1, player_number=player,
                     kicking_team=2)


def role(game: GameState, mates: list[TeamMessage] | None = None) -> Role:
    said = TeamMates(mates=[TeamMate(m, age=0.5) for m in mates or []])
    return ModuleHarness(RoleProvider, game, said, BallModel(valid=True, x=1500.0), PlayerRole()).execute()[PlayerRole].role


def test_in_ready_nobody_talks_so_the_roles_go_by_the_numbers_and_the_keeper_stays_in_goal() -> None:
    """Messages are spent in PLAYING only: in READY every robot heard nobody for a while. Before, each then
    thought it was alone and all walked to the striker's place, the keeper too."""
    assert [role(team_game(State.ready, n, 5)) for n in range(1, 6)] == [Role.goalkeeper, Role.striker, Role.supporter, Role.defender,
                                                                        Role.defender]
    assert [role(team_game(State.ready, n, 2)) for n in (1, 2)] == [Role.goalkeeper, Role.striker]
    assert [role(team_game(State.ready, n, 3, penalized=(2,))) for n in (1, 3)] == [Role.goalkeeper, Role.striker]


def test_the_keeper_plays_striker_only_when_the_game_controller_has_it_alone_on_the_field() -> None:
    fallen = TeamMessage(team=1, player=2, pose_valid=True, fallen=True)
    assert role(team_game(State.playing, 1, 2), [fallen]) is Role.goalkeeper  # a teammate down is still on the field
    assert role(team_game(State.playing, 1, 2)) is Role.goalkeeper  # and one not heard for a while
    assert role(team_game(State.playing, 1, 2, penalized=(2,))) is Role.striker  # alone: it plays the ball
    assert role(team_game(State.ready, 1, 2, penalized=(2,))) is Role.striker


def test_two_defenders_walk_to_places_on_either_side_in_ready_and_in_play() -> None:
    places = []
    for player in (4, 5):
        for state in (State.ready, State.playing):
            game = team_game(state, player, 5)
            pose = RobotPose(valid=True, x=-3000.0, y=0.0)
            harness = ModuleHarness(SoccerBehavior, game, PlayerRole(role=Role.defender), pose, BallModel(valid=True, seen=True, x=2000.0),
                                    TeamMates(), MotionInfo(), Obstacles())
            out = harness.execute()[MotionRequest]
            assert out.motion is MotionType.walk_to
            places.append((state, pose.to_field(out.target_x, out.target_y)))
    (_, ready_4), (_, play_4), (_, ready_5), (_, play_5) = places
    assert math.hypot(ready_4[0] - ready_5[0], ready_4[1] - ready_5[1]) > 1000.0
    assert math.hypot(play_4[0] - play_5[0], play_4[1] - play_5[1]) > 500.0


def test_a_robot_out_of_view_is_still_walked_round_for_a_while() -> None:
    """Walking sideways or backwards to the ball the robot no longer sees the one beside it (the view is
    +-100 degrees): it is kept for ``memory_s`` (2 s; before, 1 s)."""
    harness = ModuleHarness(ObstacleModeler, RobotPose(valid=True), RobotsPercept(robots=[SeenRobot(600.0, 0.0)]))
    harness.execute()
    harness.set(RobotsPercept(robots=[]))
    harness.execute(45)  # 1.5 s at 30 Hz
    assert len(harness[Obstacles].obstacles) == 1


@pytest.mark.parametrize("start", [(2500.0, 200.0, math.pi), (600.0, -100.0, 0.0), (3000.0, 2000.0, 2.0)])
def test_in_ready_from_the_opponent_half_it_crosses_the_halfway_line_first_beside_the_centre(start: tuple[float, float, float]) -> None:
    """After a goal the striker walks back from near the opponent goal; the straight way runs through the
    centre, where the other team's kick-off places are: before, it was still in the other half at SET
    (penalized) when it had to walk round them."""
    pose = RobotPose(valid=True, x=start[0], y=start[1], rotation=start[2])
    game = team_game(State.ready, 2, 2)
    harness = ModuleHarness(SoccerBehavior, game, PlayerRole(role=Role.striker), pose, BallModel(), TeamMates(), MotionInfo(), Obstacles())
    out = harness.execute()[MotionRequest]
    assert out.motion is MotionType.walk_to
    x, y = pose.to_field(out.target_x, out.target_y)
    assert x < 0.0 and abs(y) >= 1250.0 - 1e-6  # into the own half, beside the centre circle (and the kick-off places)
    assert abs(y - start[1]) <= max(0.0, 1250.0 - abs(start[1])) + 1e-6  # on its own side: no walk across the field
    back = RobotPose(valid=True, x=-400.0, y=math.copysign(1250.0, start[1]))  # once over the line: to its place
    harness.set(back)
    out = harness.execute()[MotionRequest]
    assert back.to_field(out.target_x, out.target_y) == pytest.approx((-1000.0, 0.0), abs=1e-6)
