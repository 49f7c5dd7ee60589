"""SoccerBehavior through the mocked blackboard: what it asks of motion in every game state and role."""

from __future__ import annotations

import math

import pytest

from tafel.core.testing import ModuleHarness
from tafel.modules.behavior.soccer_behavior import SoccerBehavior
from tafel.representations import field as pitch
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


def test_supporters_and_defenders_keep_their_distance_from_the_ball() -> None:
    pose = RobotPose(valid=True, x=-1000.0, y=0.0)
    ball = BallModel(valid=True, x=2000.0, y=1500.0)  # on the field: (1000, 1500)
    for role in (Role.supporter, Role.defender):
        out = request(State.playing, role, pose=pose, ball=ball)
        x, y = pose.to_field(out.target_x, out.target_y)
        assert out.motion is MotionType.walk_to and math.hypot(x - 1000.0, y - 1500.0) > 1000.0 and x < 1000.0, role


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
