"""The pass rule and the shot's lane (``modules/behavior/passing.py``), alone and in SoccerBehavior's striker."""

from __future__ import annotations

import math

import pytest

from tafel.core.testing import ModuleHarness
from tafel.modules.behavior.passing import PassParameters, best_shot, choose_pass, lane_clearance, pass_kick
from tafel.modules.behavior.soccer_behavior import SoccerBehavior
from tafel.representations.game import GameState, RobotInfo, State, TeamInfo
from tafel.representations.modeling import BallModel, RobotPose
from tafel.representations.motion_control import MotionInfo, MotionRequest, MotionType, WalkKick
from tafel.representations.obstacles import Obstacle, ObstacleKind, Obstacles
from tafel.representations.team import PlayerRole, Role, TeamMate, TeamMates, TeamMessage

P = PassParameters()


def test_a_robot_beside_the_lane_or_behind_the_ball_leaves_it_clear() -> None:
    assert lane_clearance((0.0, 0.0), (2000.0, 0.0), [(1000.0, 300.0)]) == pytest.approx(300.0)
    assert lane_clearance((0.0, 0.0), (2000.0, 0.0), [(-100.0, 0.0)]) == math.inf  # behind the kicker's ball
    assert lane_clearance((0.0, 0.0), (2000.0, 0.0), [(2300.0, 400.0)]) == pytest.approx(500.0)  # beyond the end


def test_a_teammate_better_placed_open_and_in_reach_gets_the_ball_when_the_shot_is_far() -> None:
    ball, mate = (-2000.0, 0.0), (0.0, 1000.0)
    target = choose_pass(ball, [mate], [], P)
    assert target is not None and math.dist(target, mate) == pytest.approx(P.pass_lead) and target[0] > mate[0]


@pytest.mark.parametrize("why, ball, mates, opponents", [
    ("not 1 m nearer the goal", (-2000.0, 0.0), [(-1500.0, 1500.0)], []),
    ("too far", (-3000.0, 0.0), [(1500.0, 0.0)], []),
    ("too near", (-2000.0, 0.0), [(-1300.0, 0.0)], []),
    ("marked", (-2000.0, 0.0), [(0.0, 1000.0)], [(300.0, 1200.0)]),
    ("the lane is blocked", (-2000.0, 0.0), [(0.0, 1000.0)], [(-1000.0, 550.0)]),
    ("an open shot near the goal", (2500.0, 500.0), [(3800.0, -800.0)], []),
])
def test_no_pass_when_a_condition_of_the_rule_fails(why: str, ball: tuple[float, float], mates: list, opponents: list) -> None:
    assert choose_pass(ball, mates, opponents, P) is None, why


def test_near_the_goal_a_blocked_shot_is_passed_and_the_shot_takes_the_open_side() -> None:
    ball, blocker = (1500.0, 0.0), (2300.0, 0.0)  # the goal 3 m away, a robot 0.8 m ahead on its line
    assert choose_pass(ball, [(3500.0, -1500.0)], [blocker], P) is not None
    assert choose_pass(ball, [(3500.0, -1500.0)], [], P) is None  # the same, unblocked: shoot
    aim, clearance = best_shot(ball, [blocker], P)
    assert abs(aim[1]) > 300.0 and clearance > 0.0  # past the blocker, not at the centre
    assert best_shot(ball, [], P)[0] == (4500.0, 0.0)  # nobody in the way: the centre


def test_the_kick_grows_with_the_pass() -> None:
    assert [pass_kick(d, P) for d in (1000.0, 2000.0, 3200.0)] == [WalkKick.short, WalkKick.long, WalkKick.none]


def striker(mates: list[TeamMessage], opponents: list[Obstacle] | None = None) -> MotionRequest:
    """The striker at (-3000, 0) facing the opponent goal, the ball 500 mm ahead of it."""
    team = TeamInfo(team_number=1, players=[RobotInfo() for _ in range(20)])
    state = GameState(state=State.playing, teams=[team, TeamInfo(team_number=2)], team_number=1, player_number=2, kicking_team=1)
    harness = ModuleHarness(SoccerBehavior, state, PlayerRole(role=Role.striker), RobotPose(valid=True, x=-3000.0, y=0.0),
                            BallModel(valid=True, seen=True, x=500.0, y=0.0), TeamMates(mates=[TeamMate(m, age=0.3) for m in mates]),
                            MotionInfo(), Obstacles(obstacles=opponents or []))
    return harness.execute()[MotionRequest]


def test_the_striker_turns_its_kick_to_a_better_placed_teammate_with_a_walk_kick_and_shoots_when_none_is() -> None:
    shot = striker([])
    assert shot.motion is MotionType.walk_to and shot.target_rotation == pytest.approx(0.0, abs=0.1)  # at the goal
    mate = TeamMessage(team=1, player=3, pose_valid=True, x=-1000.0, y=1500.0)
    passing = striker([mate])
    ball_x, ball_y = -2500.0, 0.0
    aim = math.atan2(1500.0 - ball_y, -1000.0 - ball_x)  # about 0.79 rad (the lead turns it a little towards the goal)
    assert passing.motion is MotionType.walk_to and passing.target_rotation == pytest.approx(aim, abs=0.1)  # the long walk kick faces it
    marked = striker([mate], [Obstacle(x=2500.0, y=1500.0, kind=ObstacleKind.robot),  # the teammate seen 0.5 m on from where it said
                              Obstacle(x=2600.0, y=1800.0, kind=ObstacleKind.robot)])  # an opponent beside it: a shot (through the open side)
    assert marked.target_rotation == pytest.approx(0.0, abs=0.1)
    fallen = striker([TeamMessage(team=1, player=3, pose_valid=True, fallen=True, x=-1000.0, y=1500.0)])
    assert fallen.target_rotation == pytest.approx(0.0, abs=0.1)


def test_the_goalkeeper_clearing_passes_out_to_an_open_striker_ahead() -> None:
    """In a 2v2 the striker is the teammate better placed to score: the keeper's clearance goes to it."""
    team = TeamInfo(team_number=1, players=[RobotInfo() for _ in range(20)])
    state = GameState(state=State.playing, teams=[team, TeamInfo(team_number=2)], team_number=1, player_number=1, kicking_team=1)

    def keeper(mates: list[TeamMessage]) -> MotionRequest:
        harness = ModuleHarness(SoccerBehavior, state, PlayerRole(role=Role.goalkeeper), RobotPose(valid=True, x=-4200.0, y=0.0),
                                BallModel(valid=True, seen=True, x=500.0, y=0.0), TeamMates(mates=[TeamMate(m, age=0.3) for m in mates]),
                                MotionInfo(), Obstacles())
        return harness.execute()[MotionRequest]

    clear = keeper([])
    assert clear.motion is MotionType.walk_to and clear.target_rotation == pytest.approx(0.0, abs=0.1)  # up the field
    out = keeper([TeamMessage(team=1, player=2, pose_valid=True, x=-2200.0, y=-1500.0)])
    aim = math.atan2(-1500.0, -2200.0 + 3700.0)  # from the ball at (-3700, 0) to the striker: about -0.79 rad
    assert out.motion is MotionType.walk_to and out.target_rotation == pytest.approx(aim, abs=0.15)


def supporter(opponents: list[Obstacle]) -> tuple[float, float]:
    """Where the supporter at (-1000, 0) walks (field mm) with the ball at the centre spot."""
    team = TeamInfo(team_number=1, players=[RobotInfo() for _ in range(20)])
    state = GameState(state=State.playing, teams=[team, TeamInfo(team_number=2)], team_number=1, player_number=2, kicking_team=1)
    pose = RobotPose(valid=True, x=-1000.0, y=0.0)
    harness = ModuleHarness(SoccerBehavior, state, PlayerRole(role=Role.supporter), pose, BallModel(valid=True, seen=True, x=1000.0, y=0.0),
                            TeamMates(), MotionInfo(), Obstacles(obstacles=opponents))
    out = harness.execute()[MotionRequest]
    assert out.motion is MotionType.walk_to
    return pose.to_field(out.target_x, out.target_y)


def test_the_supporter_waits_ahead_and_beside_the_ball_on_the_side_open_to_a_pass() -> None:
    free = supporter([])
    assert free == pytest.approx((1400.0, 1400.0), abs=1.0)  # supporter_offset ahead, beside
    assert choose_pass((0.0, 0.0), [free], [], P) is not None  # a place the pass rule passes to
    marked = supporter([Obstacle(x=2600.0, y=1500.0, kind=ObstacleKind.robot)])  # an opponent at (1600, 1500)
    assert marked == pytest.approx((1400.0, -1400.0), abs=1.0)
    both = supporter([Obstacle(x=2600.0, y=1500.0, kind=ObstacleKind.robot), Obstacle(x=2600.0, y=-1500.0, kind=ObstacleKind.robot)])
    assert both[0] > 1000.0 and both[1] > 500.0  # neither open: the usual side (stopping short of the robot standing there)
