"""Keeping away from opponents while not playing the ball (issue 32, the pushing fouls of ``tafel match``),
through ``paths`` and the mocked blackboard. The situations are the ones the simulated referee called."""

from __future__ import annotations

import math

from hypothesis import given
from hypothesis import strategies as st

from tafel.core.testing import ModuleHarness
from tafel.modules.behavior.paths import detour, outside
from tafel.modules.behavior.soccer_behavior import SoccerBehavior
from tafel.modules.modeling.obstacle_modeler import ObstacleModeler
from tafel.representations.game import GameState, RobotInfo, SetPlay, State, TeamInfo
from tafel.representations.modeling import BallModel, RobotPose
from tafel.representations.motion_control import MotionInfo, MotionRequest, MotionType
from tafel.representations.obstacles import Obstacle, ObstacleKind, Obstacles, RobotsPercept, SeenRobot
from tafel.representations.team import PlayerRole, Role, TeamMates

GROWN = 550.0  # mm: a robot's disc as SoccerBehavior grows it (150 + 150 + obstacle_margin 250)


def playing() -> GameState:
    team = TeamInfo(team_number=1, players=[RobotInfo() for _ in range(20)])
    return GameState(state=State.playing, teams=[team, TeamInfo(team_number=2)], team_number=1, player_number=2, kicking_team=1)


def further_in(way: tuple[float, float], centre: tuple[float, float]) -> bool:
    """Whether a step from the origin towards ``way`` leads nearer ``centre``."""
    return centre[0] * way[0] + centre[1] * way[1] > 1e-6 * max(1.0, math.hypot(*centre))


@given(st.floats(0.0, 2 * math.pi), st.floats(100.0, 500.0), st.floats(0.0, 2 * math.pi), st.floats(300.0, 900.0),
       st.floats(-2000.0, 2000.0), st.floats(-2000.0, 2000.0))
def test_within_a_robots_disc_the_way_never_leads_further_in_even_to_a_target_moved_into_it(
        bearing: float, distance: float, other_bearing: float, other_distance: float, x: float, y: float) -> None:
    """The robot stands within an opponent's grown disc; a second robot's disc overlaps it. The target,
    moved out of the discs as the behaviour moves it, may land in the first disc again; the way still
    never leads nearer that opponent (before: a disc that held the target was left out, and a striker
    holding back walked on into the opponent beside it for 2 s until the referee called pushing)."""
    near = (distance * math.cos(bearing), distance * math.sin(bearing))
    other = (near[0] + other_distance * math.cos(other_bearing), near[1] + other_distance * math.sin(other_bearing))
    discs = [(*near, GROWN), (*other, GROWN)]
    tx, ty = outside(x, y, discs, 1.0)
    way_x, way_y, _ = detour(tx, ty, discs, 0.0)
    for cx, cy, reach in discs:
        if math.hypot(cx, cy) < reach:
            assert not further_in((way_x, way_y), (cx, cy)), ((cx, cy), (tx, ty), (way_x, way_y))


def test_a_target_pushed_from_one_disc_into_an_overlapping_one_is_moved_out_of_both() -> None:
    discs = [(344.0, -45.0, 550.0), (73.0, -781.0, 587.0)]  # an opponent beside the robot, a teammate behind it
    x, y = outside(437.0, -572.0, discs, 1.0)  # where the striker wanted to wait
    assert all(math.hypot(x - cx, y - cy) >= reach for cx, cy, reach in discs)


def test_the_striker_holding_back_beside_an_opponent_steps_away_from_it() -> None:
    """Recorded in a 2v2 (seed 2, 73.8 s): the striker held back, its waiting place beyond an opponent that
    was playing the ball 350 mm beside it and a teammate behind; it walked towards the opponent."""
    pose = RobotPose(valid=True, x=2156.0, y=694.0, rotation=math.radians(-91.0))
    ball = BallModel(valid=True, seen=True, x=394.0, y=127.0)
    opponent = Obstacle(x=344.0, y=-45.0, kind=ObstacleKind.robot)
    mate = Obstacle(x=73.0, y=-781.0, radius=187.0, kind=ObstacleKind.teammate)
    harness = ModuleHarness(SoccerBehavior, playing(), PlayerRole(role=Role.striker), pose, ball, TeamMates(), MotionInfo(),
                            Obstacles(obstacles=[opponent, mate]))
    out = harness.execute()[MotionRequest]
    assert out.motion in (MotionType.walk_to, MotionType.stand)
    if out.motion is MotionType.walk_to:
        assert not further_in((out.target_x, out.target_y), (opponent.x, opponent.y))


def test_a_robot_left_behind_is_remembered_longer_than_one_in_view_that_is_no_longer_seen() -> None:
    """A robot that turned away from another (now behind it, where nothing is seen) keeps it for
    ``unseen_memory_s``: walking backwards it would walk into it. One still in view but no longer seen
    there has gone, and is forgotten after ``memory_s`` (before: both after 2 s)."""
    p = ObstacleModeler.Parameters()
    harnesses = {}
    for turned, kept in ((math.pi, True), (math.pi / 2, False)):  # behind it, or beside it within the view (100 degrees)
        harness = harnesses[turned] = ModuleHarness(ObstacleModeler, RobotPose(valid=True), RobotsPercept(robots=[SeenRobot(600.0, 0.0)]))
        harness.execute()
        harness.set(RobotsPercept(robots=[]), RobotPose(valid=True, rotation=turned))
        harness.advance(p.memory_s + 1.0)
        assert (len(harness[Obstacles].obstacles) == 1) is kept, turned
    harnesses[math.pi].advance(p.unseen_memory_s)  # and then forgotten too
    assert harnesses[math.pi][Obstacles].obstacles == []


def test_a_way_brought_back_onto_the_field_does_not_lead_into_the_opponent_beside_the_robot() -> None:
    """Recorded in a 2v2 (seed 1, 541.8 s): at its own corner kick the striker stood just beyond the goal line,
    an opponent 0.4 m to its left; the way round the opponent led further beyond the line, and bringing that
    target back onto the field turned it into the opponent, which the referee called pushing."""
    game = playing()
    game.set_play = SetPlay.corner_kick
    pose = RobotPose(valid=True, x=4661.0, y=1548.0, rotation=math.radians(23.0))
    ball = BallModel(valid=True, seen=True, x=326.0, y=1353.0)
    opponent = Obstacle(x=-121.0, y=397.0, kind=ObstacleKind.robot)
    others = [Obstacle(x=-811.0, y=-725.0, kind=ObstacleKind.robot), Obstacle(x=-1516.0, y=689.0, radius=209.0, kind=ObstacleKind.teammate)]
    harness = ModuleHarness(SoccerBehavior, game, PlayerRole(role=Role.striker), pose, ball, TeamMates(), MotionInfo(),
                            Obstacles(obstacles=[opponent, *others]))
    out = harness.execute()[MotionRequest]
    if out.motion is MotionType.walk_to:
        assert not further_in((out.target_x, out.target_y), (opponent.x, opponent.y))
        x, y = pose.to_field(out.target_x, out.target_y)
        assert x <= pose.x + 1e-6  # and no further beyond the goal line
    else:
        assert out.motion is MotionType.stand
