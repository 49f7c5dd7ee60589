"""SoccerBehavior through the mocked blackboard: what it asks of motion in every game state and role."""

from __future__ import annotations

import copy
import math

import pytest
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st

from tafel.core.testing import ModuleHarness
from tafel.modules.behavior.soccer_behavior import SoccerBehavior
from tafel.representations import field as pitch
from tafel.representations.behavior import ActivationGraph, OptionGraph
from tafel.representations.game import GamePhase, GameState, Penalty, RobotInfo, SetPlay, State, TeamInfo
from tafel.representations.modeling import BallModel, RobotPose
from tafel.representations.motion_control import MotionInfo, MotionRequest, MotionType
from tafel.representations.obstacles import ROBOT_RADIUS, Obstacle, Obstacles
from tafel.representations.team import PlayerRole, Role, TeamMate, TeamMates, TeamMessage


def game(state: State, *, penalty: Penalty = Penalty.none, kicking_team: int = 2) -> GameState:
    team = TeamInfo(team_number=1, players=[RobotInfo() for _ in range(20)])
    team.players[1].penalty = penalty
    return GameState(state=state, teams=[team, TeamInfo(team_number=2)], team_number=1, player_number=2, kicking_team=kicking_team)


def request(state: State, role: Role = Role.striker, *, pose: RobotPose | None = None, ball: BallModel | None = None,
            mates: TeamMates | None = None, **options: object) -> MotionRequest:
    harness = ModuleHarness(SoccerBehavior, game(state, **options), PlayerRole(role=role), pose or RobotPose(valid=True, x=-3000.0, y=0.0),
                            ball or BallModel(), mates or TeamMates(), MotionInfo())
    return harness.execute()[MotionRequest]


@pytest.mark.parametrize("state", [State.initial, State.standby, State.set])
def test_it_stands_before_play(state: State) -> None:
    assert request(state, ball=BallModel(valid=True, x=500.0)).motion is MotionType.stand


def test_it_sits_when_the_game_is_finished_and_stands_still_while_penalized() -> None:
    assert request(State.finished).motion is MotionType.sit
    assert request(State.playing, ball=BallModel(valid=True, x=500.0), penalty=Penalty.player_pushing).motion is MotionType.stand


@pytest.mark.parametrize("role, kicking_team, position", [
    (Role.goalkeeper, 2, (-4200.0, 0.0)), (Role.striker, 2, (-1000.0, 0.0)), (Role.striker, 1, (-300.0, 0.0)),
    (Role.supporter, 1, (-1500.0, -1300.0)), (Role.defender, 1, (-2800.0, 1000.0)),
])
def test_in_ready_each_role_walks_to_its_kickoff_position(role: Role, kicking_team: int, position: tuple[float, float]) -> None:
    pose = RobotPose(valid=True, x=-3000.0, y=2500.0, rotation=math.pi / 2)
    out = request(State.ready, role, pose=pose, kicking_team=kicking_team)
    assert out.motion is MotionType.walk_to
    assert pose.to_field(out.target_x, out.target_y) == pytest.approx(position, abs=1e-6)
    assert math.remainder(pose.rotation + out.target_rotation, math.tau) == pytest.approx(0.0, abs=1e-9)  # facing the opponent goal


def test_in_ready_it_stands_once_there_and_looks_around_without_a_pose() -> None:
    assert request(State.ready, pose=RobotPose(valid=True, x=-1000.0, y=30.0)).motion is MotionType.stand
    lost = request(State.ready, pose=RobotPose(valid=False))
    assert lost.motion is MotionType.walk and lost.walk_x == 0.0 and lost.walk_rotation > 0


def test_the_striker_goes_for_the_ball_and_searches_by_turning_without_one() -> None:
    out = request(State.playing, ball=BallModel(valid=True, x=1500.0, y=0.0))
    assert out.motion is MotionType.walk_to and 1000.0 < out.target_x < 1500.0
    assert request(State.playing, ball=BallModel(valid=True, x=190.0, y=-50.0)).motion is MotionType.kick
    search = request(State.playing)
    assert search.motion is MotionType.walk and search.walk_rotation > 0


def test_the_striker_searches_towards_the_side_it_last_saw_the_ball_on() -> None:
    """Lost on its right, the ball is searched by turning right (and on its left, left), not always left."""
    for y, sign in ((-900.0, -1.0), (900.0, 1.0)):
        harness = ModuleHarness(SoccerBehavior, game(State.playing), PlayerRole(role=Role.striker), RobotPose(valid=True, x=-3000.0),
                                BallModel(valid=True, seen=True, x=1500.0, y=y), TeamMates(), MotionInfo())
        harness.execute()
        harness.set(BallModel(valid=False, x=300.0, y=y, time_since_seen=2.0))
        search = harness.execute()[MotionRequest]
        assert search.motion is MotionType.walk and search.walk_x == 0.0 and math.copysign(1.0, search.walk_rotation) == sign


def test_without_its_own_sighting_the_striker_goes_by_a_teammates_ball() -> None:
    said = TeamMessage(team=1, player=3, pose_valid=True, ball_seen=True, ball_x=500.0, ball_y=1000.0, ball_age=0.5)
    out = request(State.playing, pose=RobotPose(valid=True, x=-2000.0, y=0.0), mates=TeamMates(mates=[TeamMate(said, age=0.4)]))
    assert out.motion is MotionType.walk_to and (out.target_x, out.target_y) == pytest.approx((2500.0, 1000.0))
    stale = TeamMates(mates=[TeamMate(said, age=5.0)])
    assert request(State.playing, pose=RobotPose(valid=True, x=-2000.0), mates=stale).motion is MotionType.walk  # too old: search


def test_the_goalkeeper_stays_between_ball_and_goal_and_clears_a_near_ball_in_its_area() -> None:
    pose = RobotPose(valid=True, x=-4200.0, y=0.0)
    far = request(State.playing, Role.goalkeeper, pose=pose, ball=BallModel(valid=True, x=5000.0, y=1000.0))
    x, y = pose.to_field(far.target_x, far.target_y)
    assert far.motion is MotionType.walk_to and x == pytest.approx(-4200.0) and 0.0 < y <= 500.0
    near = request(State.playing, Role.goalkeeper, pose=pose, ball=BallModel(valid=True, x=600.0, y=0.0))
    assert near.motion is MotionType.walk_to and near.target_x > 300.0  # goes for it


def test_supporters_wait_ahead_of_the_ball_for_a_pass_and_defenders_behind_it_both_at_a_distance() -> None:
    pose = RobotPose(valid=True, x=-1000.0, y=0.0)
    ball = BallModel(valid=True, x=2000.0, y=1500.0)  # on the field: (1000, 1500)
    for role, ahead in ((Role.supporter, True), (Role.defender, False)):
        out = request(State.playing, role, pose=pose, ball=ball)
        x, y = pose.to_field(out.target_x, out.target_y)
        assert out.motion is MotionType.walk_to and math.hypot(x - 1000.0, y - 1500.0) > 1000.0 and (x > 1000.0) is ahead, role


# ------------------------------------------------------------------------------ the rules' set plays
ROLES = (Role.striker, Role.supporter, Role.defender, Role.goalkeeper)


def set_play_game(state: State, set_play: SetPlay, kicking_team: int, phase: GamePhase = GamePhase.normal) -> GameState:
    out = game(state, kicking_team=kicking_team)
    out.set_play, out.game_phase = set_play, phase
    return out


def targets(harness: ModuleHarness, pose: RobotPose, frames: int) -> list[tuple[MotionType, float, float]]:
    """Each frame's motion and where it walks to (field mm; the robot's own place when it does not)."""
    out = []
    for _ in range(frames):
        motion = harness.execute()[MotionRequest]
        x, y = pose.to_field(motion.target_x, motion.target_y) if motion.motion is MotionType.walk_to else (pose.x, pose.y)
        out.append((motion.motion, x, y))
    return out


@pytest.mark.parametrize("role", ROLES)
def test_at_the_opponents_kick_off_nobody_heads_into_the_centre_circle_for_10_s_unless_the_ball_moved(role: Role) -> None:
    pose = RobotPose(valid=True, x=-1000.0, y=200.0)
    centre = BallModel(valid=True, seen=True, x=1000.0, y=-200.0)  # on the centre spot
    harness = ModuleHarness(SoccerBehavior, game(State.set, kicking_team=2), PlayerRole(role=role), pose, centre, TeamMates(), MotionInfo())
    harness.execute(5)
    harness.set(game(State.playing, kicking_team=2))
    waiting = targets(harness, pose, 9 * 30)  # 9 s of PLAYING, the ball still on the spot
    assert all(math.hypot(x, y) > pitch.CENTER_CIRCLE_DIAMETER / 2 for _, x, y in waiting), role
    if role is Role.striker:
        harness.execute(2 * 30)  # past 10 s: the ball is free
        assert harness.execute()[MotionRequest].target_x > 800.0
        harness = ModuleHarness(SoccerBehavior, game(State.set, kicking_team=2), PlayerRole(role=role), pose, centre, TeamMates(),
                                MotionInfo())
        harness.execute(5)
        harness.set(game(State.playing, kicking_team=2), BallModel(valid=True, seen=True, x=1000.0, y=-600.0))  # it moved
        assert harness.execute()[MotionRequest].target_x > 700.0  # goes at once


def test_at_the_own_kick_off_the_striker_goes_for_the_ball_at_once() -> None:
    pose = RobotPose(valid=True, x=-300.0, y=0.0)
    harness = ModuleHarness(SoccerBehavior, game(State.set, kicking_team=1), PlayerRole(role=Role.striker), pose,
                            BallModel(valid=True, seen=True, x=300.0, y=0.0), TeamMates(), MotionInfo())
    harness.execute(5)
    harness.set(game(State.playing, kicking_team=1))
    assert harness.execute()[MotionRequest].target_x > 0.0


@pytest.mark.parametrize("set_play", [SetPlay.goal_kick, SetPlay.pushing_free_kick, SetPlay.corner_kick, SetPlay.kick_in,
                                      SetPlay.penalty_kick])
@pytest.mark.parametrize("role", ROLES)
def test_at_the_opponents_set_plays_everybody_keeps_0_75_m_from_the_ball(set_play: SetPlay, role: Role) -> None:
    ball_field = {SetPlay.goal_kick: (3900.0, 1100.0), SetPlay.corner_kick: (-4450.0, 2950.0), SetPlay.kick_in: (0.0, -2950.0),
                  SetPlay.pushing_free_kick: (-1000.0, 500.0), SetPlay.penalty_kick: (-3200.0, 0.0)}[set_play]
    for start in ((-2000.0, 0.0), (ball_field[0] + 300.0, ball_field[1] * 0.9), (0.0, 1500.0)):
        pose = RobotPose(valid=True, x=start[0], y=start[1])
        ball = BallModel(valid=True, seen=True, x=pose.to_robot(*ball_field)[0], y=pose.to_robot(*ball_field)[1])
        harness = ModuleHarness(SoccerBehavior, set_play_game(State.playing, set_play, 2), PlayerRole(role=role), pose, ball,
                                TeamMates(), MotionInfo())
        for motion, x, y in targets(harness, pose, 5):
            assert motion is not MotionType.kick
            assert math.hypot(x - ball_field[0], y - ball_field[1]) >= 750.0, (role, start, x, y)


def test_the_own_free_kicks_are_indirect_the_striker_never_plays_the_ball_at_the_goal() -> None:
    for bx, by in ((3000.0, 2950.0), (4450.0, -2950.0), (0.0, 2950.0), (2500.0, 0.0)):
        pose = RobotPose(valid=True, x=bx - 190.0, y=by)  # right behind the ball
        ball = BallModel(valid=True, seen=True, x=190.0, y=0.0)
        out = ModuleHarness(SoccerBehavior, set_play_game(State.playing, SetPlay.corner_kick, 1), PlayerRole(role=Role.striker), pose,
                            ball, TeamMates(), MotionInfo()).execute()[MotionRequest]
        direction = pose.rotation + (out.kick_direction if out.motion is MotionType.kick else out.target_rotation)
        # where the ball would cross the goal line, if it got there at all
        if math.cos(direction) > 1e-6:
            crossing = by + math.tan(direction) * (pitch.LENGTH / 2 - bx)
            assert abs(crossing) > pitch.GOAL_INNER_WIDTH / 2 + 100.0, (bx, by, direction)


@pytest.mark.parametrize("role", ROLES)
def test_in_ready_at_a_penalty_kick_only_the_keeper_is_in_the_penalty_area_on_its_goal_line(role: Role) -> None:
    pose = RobotPose(valid=True, x=-2000.0, y=1000.0)
    against = request(State.ready, role, pose=pose, kicking_team=2)  # defending: placed as for a kick-off
    harness = ModuleHarness(SoccerBehavior, set_play_game(State.ready, SetPlay.penalty_kick, 2), PlayerRole(role=role), pose,
                            BallModel(), TeamMates(), MotionInfo())
    out = harness.execute()[MotionRequest]
    x, y = pose.to_field(out.target_x, out.target_y)
    in_area = x < -pitch.LENGTH / 2 + pitch.PENALTY_AREA_LENGTH and abs(y) < pitch.PENALTY_AREA_WIDTH / 2
    if role is Role.goalkeeper:
        assert in_area and x <= -pitch.LENGTH / 2 + 150.0 and abs(y) < pitch.GOAL_INNER_WIDTH / 2
    else:
        assert not in_area, (role, x, y)
    assert against.motion is MotionType.walk_to
    kicker = ModuleHarness(SoccerBehavior, set_play_game(State.ready, SetPlay.penalty_kick, 1), PlayerRole(role=Role.striker), pose,
                           BallModel(), TeamMates(), MotionInfo()).execute()[MotionRequest]
    kx, ky = pose.to_field(kicker.target_x, kicker.target_y)
    penalty_mark = pitch.LENGTH / 2 - pitch.PENALTY_MARK_DISTANCE
    assert penalty_mark - 700.0 < kx < penalty_mark and abs(ky) < 100.0  # behind the ball on the mark


def test_in_a_penalty_shoot_out_the_striker_kicks_at_a_goal_corner_and_the_keeper_keeps_its_line() -> None:
    pose = RobotPose(valid=True, x=2900.0, y=0.0)
    ball = BallModel(valid=True, seen=True, x=300.0, y=0.0)  # on the penalty mark
    shooter = ModuleHarness(SoccerBehavior, set_play_game(State.playing, SetPlay.none, 1, GamePhase.penalty_shoot),
                            PlayerRole(role=Role.goalkeeper), pose, ball, TeamMates(), MotionInfo()).execute()[MotionRequest]
    assert shooter.motion is MotionType.walk_to
    aim = math.tan(shooter.target_rotation) * (pitch.LENGTH / 2 - 3200.0)  # where it would cross the goal line
    assert 200.0 < abs(aim) < pitch.GOAL_INNER_WIDTH / 2 - 100.0
    keeper_pose = RobotPose(valid=True, x=-4000.0, y=0.0)
    kept = ModuleHarness(SoccerBehavior, set_play_game(State.playing, SetPlay.none, 2, GamePhase.penalty_shoot),
                         PlayerRole(role=Role.striker), keeper_pose, BallModel(valid=True, seen=True, x=800.0, y=300.0), TeamMates(),
                         MotionInfo()).execute()[MotionRequest]
    x, y = keeper_pose.to_field(kept.target_x, kept.target_y)
    assert x == pytest.approx(-pitch.LENGTH / 2 + 100.0) and 0.0 < y < pitch.GOAL_INNER_WIDTH / 2
    for state in (State.set, State.ready):
        still = ModuleHarness(SoccerBehavior, set_play_game(state, SetPlay.none, 1, GamePhase.penalty_shoot),
                              PlayerRole(role=Role.striker), pose, ball, TeamMates(), MotionInfo()).execute()[MotionRequest]
        assert still.motion is MotionType.stand


# ------------------------------------------------------------------------------ walking around others
def test_it_walks_around_a_robot_in_its_way_and_straight_when_the_way_is_free() -> None:
    pose = RobotPose(valid=True, x=-3000.0, y=0.0)
    blocked = Obstacles(obstacles=[Obstacle(x=1000.0, y=50.0, radius=150.0)])  # on the way to the supporter's place
    for obstacles in (Obstacles(), blocked):
        harness = ModuleHarness(SoccerBehavior, game(State.ready), PlayerRole(role=Role.striker), pose, BallModel(), TeamMates(),
                                MotionInfo(), obstacles)
        out = harness.execute()[MotionRequest]
        assert out.motion is MotionType.walk_to
        for o in obstacles.obstacles:  # the straight way to the waypoint passes the robot with room to spare
            t = max(0.0, min(1.0, (o.x * out.target_x + o.y * out.target_y) / (out.target_x ** 2 + out.target_y ** 2)))
            assert math.hypot(t * out.target_x - o.x, t * out.target_y - o.y) >= o.radius + ROBOT_RADIUS
        if not obstacles.obstacles:
            assert (out.target_x, out.target_y) == pytest.approx((2000.0, 0.0))


# ------------------------------------------------------------------------------ the options, watched
def active(harness: ModuleHarness) -> list[tuple[str, str]]:
    return [(o.name, o.state) for o in harness[ActivationGraph].options]


def test_the_activation_graph_shows_the_kick_off_wait_and_its_end_after_10_s() -> None:
    pose = RobotPose(valid=True, x=-1000.0, y=200.0)
    harness = ModuleHarness(SoccerBehavior, game(State.set, kicking_team=2), PlayerRole(role=Role.striker), pose,
                            BallModel(valid=True, seen=True, x=1000.0, y=-200.0), TeamMates(), MotionInfo())
    harness.advance(1.0)
    assert active(harness) == [("PlaySoccer", "set")]
    harness.set(game(State.playing, kicking_team=2))
    harness.advance(9.5)
    assert active(harness) == [("PlaySoccer", "opponents_kick_off"), ("Play", "play"), ("Striker", "wait_outside"), ("GoTo", "walk")]
    root = harness[ActivationGraph].options[0]
    assert root.time_in_state == pytest.approx(9.5, abs=0.05) and root.time_in_option == pytest.approx(harness.time_s)
    assert harness[ActivationGraph].options[1].parameters == "role=striker"
    harness.advance(0.6)
    assert active(harness) == [("PlaySoccer", "playing"), ("Play", "play"), ("Striker", "kick")]
    assert harness[OptionGraph].root == "PlaySoccer" and "Striker" in [o.name for o in harness[OptionGraph].options]


def test_the_opponents_free_kick_is_over_after_30_s_whatever_the_game_controller_says() -> None:
    pose = RobotPose(valid=True, x=-1000.0, y=0.0)
    harness = ModuleHarness(SoccerBehavior, set_play_game(State.playing, SetPlay.kick_in, 2), PlayerRole(role=Role.striker), pose,
                            BallModel(valid=True, seen=True, x=500.0, y=0.0), TeamMates(), MotionInfo())
    harness.advance(29.0)
    assert active(harness)[1] == ("Play", "opponents_set_play") and harness[MotionRequest].motion is not MotionType.kick
    harness.advance(1.5)
    assert active(harness)[1:3] == [("Play", "set_play_over"), ("Striker", "kick")]
    harness.set(set_play_game(State.playing, SetPlay.none, 2))
    harness.execute()
    assert active(harness)[1] == ("Play", "play")


def test_while_a_kick_plays_the_options_go_on_and_the_request_stays() -> None:
    harness = ModuleHarness(SoccerBehavior, game(State.playing), PlayerRole(role=Role.striker), RobotPose(valid=True, x=-3000.0),
                            BallModel(valid=True, x=190.0, y=-50.0), TeamMates(), MotionInfo())
    assert harness.execute()[MotionRequest].motion is MotionType.kick
    harness.set(MotionInfo(busy=True), BallModel())
    harness.advance(1.0)
    assert harness[MotionRequest].motion is MotionType.kick and active(harness)[-1] == ("Striker", "search")


# A situation the robot may be in: the game, its role, what it knows, and for how long. Places and
# times lean towards where the rules and roles decide something (the own penalty area, the centre, a
# ball at the foot; the rules' 10 s and 30 s).
PLACES = st.sampled_from([(-4200.0, 0.0, 0.0), (-1000.0, 200.0, 0.0), (-300.0, 0.0, 0.0), (2900.0, 0.0, 0.0), (3000.0, 1500.0, 3.0)])
BALLS = st.sampled_from([(190.0, 50.0), (600.0, 0.0), (1000.0, -200.0), (2500.0, 0.0)])
SITUATIONS = st.fixed_dictionaries({
    "state": st.sampled_from([State.initial, State.standby, State.ready, State.set, State.playing, State.playing, State.finished]),
    "set_play": st.sampled_from(list(SetPlay)),
    "kicking_team": st.sampled_from([1, 2]),
    "shoot_out": st.sampled_from([False, False, False, True]),
    "penalized": st.sampled_from([False, False, False, True]),
    "role": st.sampled_from(list(Role)),
    "ball": st.none() | BALLS | st.tuples(st.floats(-4000.0, 4000.0), st.floats(-3000.0, 3000.0)),
    "pose": st.none() | PLACES | st.tuples(st.floats(-4500.0, 4500.0), st.floats(-3000.0, 3000.0), st.floats(-3.1, 3.1)),
    "mate_ball": st.none() | st.tuples(st.floats(-4500.0, 4500.0), st.floats(-3000.0, 3000.0)),
    "seconds": st.sampled_from([0.2, 1.0, 4.0, 11.0, 31.0]),
})


def case(state: State = State.playing, set_play: SetPlay = SetPlay.none, kicking_team: int = 2, role: Role = Role.striker,
         ball: tuple[float, float] | None = (600.0, 0.0), pose: tuple[float, float, float] | None = (-4200.0, 0.0, 0.0),
         seconds: float = 1.0) -> dict[str, object]:
    """One situation written out, for the examples every run tries."""
    return {"state": state, "set_play": set_play, "kicking_team": kicking_team, "shoot_out": False, "penalized": False, "role": role,
            "ball": ball, "pose": pose, "mate_ball": None, "seconds": seconds}


def situation(s: dict[str, object]) -> tuple[object, ...]:
    phase = GamePhase.penalty_shoot if s["shoot_out"] else GamePhase.normal
    out = set_play_game(s["state"], s["set_play"], s["kicking_team"], phase)
    if s["penalized"]:
        out.teams[0].players[1].penalty = Penalty.player_pushing
    pose = RobotPose(valid=True, x=s["pose"][0], y=s["pose"][1], rotation=s["pose"][2]) if s["pose"] else RobotPose()
    ball = BallModel(valid=True, seen=True, x=s["ball"][0], y=s["ball"][1]) if s["ball"] else BallModel()
    said = [TeamMate(TeamMessage(team=1, player=3, pose_valid=True, ball_seen=True, ball_x=s["mate_ball"][0], ball_y=s["mate_ball"][1]),
                     age=0.2)] if s["mate_ball"] else []
    return out, PlayerRole(role=s["role"]), pose, ball, TeamMates(mates=said)


def arrive(pose: RobotPose, ball: BallModel, target: dict[str, str]) -> tuple[RobotPose, BallModel]:
    """The robot at ``target`` (field x, y, rotation), the ball where it was on the field."""
    there = RobotPose(valid=True, **{name: float(value) for name, value in target.items()})
    if not (ball.valid and pose.valid):
        return there, ball
    x, y = there.to_robot(*pose.to_field(ball.x, ball.y))
    return there, BallModel(valid=True, seen=True, x=x, y=y)


def ways_out(harness: ModuleHarness) -> list[tuple[float, tuple[object, ...]]]:
    """What may change next, and how long to wait for a state to be left: time alone, the robot arriving
    where it walks to, the ball, the pose, the set play, the kicking team, the GameController's state."""
    def changed(**fields: object) -> GameState:
        out = copy.deepcopy(game_now)
        out.__dict__.update(fields)
        return out
    keeper_area = (RobotPose(valid=True, x=-4200.0, y=0.0), BallModel(valid=True, seen=True, x=600.0, y=0.0))
    game_now = harness[GameState]
    walking = [dict(item.split("=") for item in o.parameters.split()) for o in harness[ActivationGraph].options if o.name == "GoTo"]
    arrived = [(0.5, arrive(harness[RobotPose], harness[BallModel], target)) for target in walking]
    return [*arrived,
        (31.0, ()), (0.5, (BallModel(), TeamMates())), (0.5, (BallModel(valid=True, seen=True, x=190.0, y=50.0),)),
        (0.5, (BallModel(valid=True, seen=True, x=2500.0, y=0.0),)), (0.5, keeper_area), (0.5, (RobotPose(),)),
        (0.5, (RobotPose(valid=True, x=1000.0, y=-2000.0, rotation=2.0),)), (0.5, (changed(set_play=SetPlay.none),)),
        (0.5, (changed(set_play=SetPlay.kick_in, kicking_team=2),)), (0.5, (changed(set_play=SetPlay.penalty_kick),)),
        (0.5, (changed(kicking_team=3 - game_now.kicking_team),)),
        *((0.5, (changed(state=state, teams=game(state).teams),)) for state in (State.ready, State.playing, State.finished)),
    ]


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.lists(SITUATIONS, min_size=1, max_size=3))
@example([case(set_play=SetPlay.kick_in, seconds=31.0)])  # past the opponents' set play
@example([case(role=Role.goalkeeper)])  # the keeper clears
@example([case(State.set), case(ball=(1000.0, -200.0), pose=(-1000.0, 200.0, 0.0), seconds=4.0)])  # the opponents' kick-off
@example([case(set_play=SetPlay.corner_kick, kicking_team=1, ball=(190.0, 50.0), pose=(4200.0, 2900.0, 0.0))])  # own free kick
def test_every_reachable_state_has_a_way_out_or_is_meant_to_be_final(situations: list[dict[str, object]]) -> None:
    """Whatever happened before, an active state that is not final is left when time passes or
    something changes while its caller goes on calling it (an option of one state has nothing to leave)."""
    harness = ModuleHarness(SoccerBehavior, *situation(situations[0]), MotionInfo(), rate_hz=5)
    harness._history.clear()  # no copies of every frame's outputs: each trial below copies the harness
    for s in situations:
        harness.set(*situation(s))
        harness.advance(s["seconds"])
    graph = {o.name: o for o in harness[OptionGraph].options}
    final = {(o.name, s.name) for o in graph.values() for s in o.states if s.final}
    stuck = {(o.name, o.state): harness.time_s - o.time_in_state for o in harness[ActivationGraph].options
             if len(graph[o.name].states) > 1 and (o.name, o.state) not in final}
    for seconds, change in ways_out(harness):
        if not stuck:
            break
        trial = copy.deepcopy(harness)
        trial.set(*change)
        for _ in range(max(1, round(seconds * 5))):
            trial.execute()
            now = {o.name: (o.state, trial.time_s - o.time_in_state) for o in trial[ActivationGraph].options}
            # left: the option, still called, is in another state or entered this one anew (an option
            # its caller stops calling has not found a way out of its state)
            stuck = {(name, state): entered for (name, state), entered in stuck.items()
                     if name not in now or (now[name][0] == state and now[name][1] == pytest.approx(entered, abs=1e-6))}
    assert not stuck, f"no way out of {sorted(stuck)} after {situations}"
