"""ObstacleModeler and the way round obstacles (``paths``), through the mocked blackboard."""

from __future__ import annotations

import math

import pytest
from hypothesis import given
from hypothesis import strategies as st

from tafel.core.testing import ModuleHarness
from tafel.modules.behavior.paths import blocking, outside, waypoint
from tafel.modules.modeling.obstacle_modeler import GOAL_POSTS, ObstacleModeler
from tafel.modules.motion.sonar_filter import SonarFilter
from tafel.representations.modeling import RobotPose
from tafel.representations.motion_control import FallPhase, FallState, Odometry
from tafel.representations.obstacles import ROBOT_RADIUS, ObstacleKind, Obstacles, RobotsPercept, SeenRobot, same_robots
from tafel.representations.sonar import SONAR_ANGLE, SonarData, SonarEcho, SonarPercept
from tafel.representations.team import TeamMate, TeamMates, TeamMessage


def mate(player: int, x: float, y: float, *, age: float = 0.5, penalized: bool = False) -> TeamMate:
    return TeamMate(TeamMessage(team=1, player=player, pose_valid=True, x=x, y=y, penalized=penalized), age=age)


def test_teammates_are_obstacles_where_they_said_they_were_growing_with_the_age_of_the_news() -> None:
    pose = RobotPose(valid=True, x=-1000.0, y=0.0, rotation=math.pi / 2)
    mates = TeamMates(mates=[mate(3, -1000.0, 1000.0, age=0.5), mate(4, 0.0, 0.0, age=4.0), mate(5, 500.0, 0.0, penalized=True)])
    found = ModuleHarness(ObstacleModeler, pose, mates).execute()[Obstacles].obstacles
    assert [(round(o.x), round(o.y), o.kind) for o in found] == [(1000, 0, ObstacleKind.teammate), (0, -1000, ObstacleKind.teammate)]
    assert found[0].radius < found[1].radius  # four-second-old news is less sure


def test_seen_robots_stay_put_on_the_field_while_this_robot_turns_and_are_forgotten_after_a_while() -> None:
    harness = ModuleHarness(ObstacleModeler, RobotPose(valid=True), RobotsPercept(robots=[SeenRobot(800.0, 0.0)]))
    harness.execute()
    harness.set(RobotsPercept(robots=[]), RobotPose(valid=True, rotation=math.pi / 2))  # turned left, no longer seen
    held = harness.execute()[Obstacles].obstacles
    assert len(held) == 1 and (held[0].x, held[0].y) == pytest.approx((0.0, -800.0), abs=1e-6)
    harness.execute(70)  # > 2 s later
    assert harness.blackboard[Obstacles].obstacles == []


def test_a_robot_seen_where_a_teammate_is_counts_once() -> None:
    harness = ModuleHarness(ObstacleModeler, RobotPose(valid=True), RobotsPercept(robots=[SeenRobot(1000.0, 100.0)]),
                            TeamMates(mates=[mate(3, 1050.0, 0.0)]))
    for _ in range(10):  # seen again every frame: one obstacle, not one per frame
        found = harness.execute()[Obstacles].obstacles
    assert len(found) == 1 and found[0].kind is ObstacleKind.teammate


discs = st.lists(st.tuples(st.floats(-3000, 3000), st.floats(-3000, 3000), st.floats(100, 600)), max_size=4)


@given(discs, st.floats(-4000, 4000), st.floats(-4000, 4000))
def test_the_first_waypoint_never_leads_through_the_first_disc_in_the_way(obstacles: list, x: float, y: float) -> None:
    way = waypoint(x, y, obstacles, margin=100.0)
    first = blocking(x, y, obstacles, margin=100.0)
    if first is None:
        assert way == (x, y)
    else:
        _, disc = first
        hit = blocking(*way, [disc], margin=100.0)
        assert hit is None  # past the disc that was in the way, with the margin


@given(discs, st.floats(-4000, 4000), st.floats(-4000, 4000))
def test_a_target_in_a_forbidden_disc_moves_to_its_edge(zones: list, x: float, y: float) -> None:
    zones = zones[:1]
    ox, oy = outside(x, y, zones)
    for cx, cy, radius in zones:
        assert math.hypot(ox - cx, oy - cy) >= radius - 1e-6


def sonar_filter(left_m: float, right_m: float, *, frames: int = 30, upright: bool = True) -> SonarPercept:
    harness = ModuleHarness(SonarFilter, SonarData(left=left_m, right=right_m, valid=True),
                            FallState() if upright else FallState(phase=FallPhase.lying_front))
    return harness.execute(frames)[SonarPercept]


def test_a_near_echo_is_an_obstacle_in_the_middle_of_its_sonars_cone_and_both_alike_one_straight_ahead() -> None:
    left = sonar_filter(0.6, 5.0)
    assert len(left.echoes) == 1 and left.right == 0.0
    echo = left.echoes[0]
    assert math.hypot(echo.x, echo.y) == pytest.approx(600.0) and math.atan2(echo.y, echo.x) == pytest.approx(SONAR_ANGLE)
    right = sonar_filter(5.0, 0.9).echoes
    assert len(right) == 1 and math.atan2(right[0].y, right[0].x) == pytest.approx(-SONAR_ANGLE)
    both = sonar_filter(0.7, 0.75).echoes
    assert [(round(e.x), round(e.y)) for e in both] == [(725, 0)]


def test_echoes_of_the_own_arms_far_ones_and_any_while_not_upright_are_no_obstacles() -> None:
    assert sonar_filter(0.15, 0.2).echoes == []  # the own arms, the floor
    assert sonar_filter(2.4, 5.0).echoes == []  # beyond what the sonars measure reliably
    assert sonar_filter(0.6, 0.6, upright=False).echoes == []


def test_one_stray_packet_is_no_obstacle_but_an_echo_that_stays_is() -> None:
    harness = ModuleHarness(SonarFilter, SonarData(left=5.0, right=5.0, valid=True), FallState())
    harness.execute(10)
    harness.set(SonarData(left=0.5, right=5.0, valid=True))
    assert harness.execute()[SonarPercept].echoes == []  # smoothed: one packet moves the distance a little
    assert harness.execute(20)[SonarPercept].echoes != []


def test_sonar_echoes_become_obstacles_and_stay_put_while_the_robot_turns() -> None:
    harness = ModuleHarness(ObstacleModeler, RobotPose(valid=True), SonarPercept(echoes=[SonarEcho(500.0, 0.0)]))
    found = harness.execute()[Obstacles].obstacles
    assert [(round(o.x), round(o.y), o.kind) for o in found] == [(500, 0, ObstacleKind.robot)]
    assert harness.blackboard[Obstacles].clearance == pytest.approx(500.0 - ROBOT_RADIUS)
    harness.set(SonarPercept(echoes=[]), RobotPose(valid=True, rotation=math.pi / 2))
    held = harness.execute()[Obstacles].obstacles
    assert len(held) == 1 and (held[0].x, held[0].y) == pytest.approx((0.0, -500.0), abs=1e-6)


def test_a_robot_seen_at_a_goal_post_is_the_post() -> None:
    post = GOAL_POSTS[0]
    pose = RobotPose(valid=True, x=post[0] + 1000.0, y=post[1], rotation=math.pi)  # facing the post, 1 m away
    seen = RobotsPercept(robots=[SeenRobot(1000.0, 0.0), SeenRobot(1000.0, 600.0)])
    found = ModuleHarness(ObstacleModeler, pose, seen).execute()[Obstacles].obstacles
    assert [(round(o.x), round(o.y)) for o in found] == [(1000, 600)]


def test_without_a_pose_a_robot_seen_now_and_then_stays_where_odometry_puts_it() -> None:
    """The localization is not sure yet (after a kick-off, a fall) and the robot is seen only in some
    frames: it must not vanish in between while this robot walks towards it."""
    harness = ModuleHarness(ObstacleModeler, RobotPose(valid=False), Odometry(), RobotsPercept(robots=[SeenRobot(800.0, 0.0)]))
    harness.execute()
    harness.set(RobotsPercept(robots=[]), Odometry(x=300.0, rotation=math.pi / 2))  # walked 300 mm ahead, turned left
    held = harness.execute()[Obstacles].obstacles
    assert len(held) == 1 and (held[0].x, held[0].y) == pytest.approx((0.0, -500.0), abs=1e-6)
    harness.execute(70)  # > 2 s later
    assert harness.blackboard[Obstacles].obstacles == []


def test_each_place_said_is_one_robot_seen_the_nearest_and_a_robot_beside_it_stays_apart() -> None:
    assert same_robots([], [(0.0, 0.0)], 400.0) == set()
    assert same_robots([(0.0, 0.0)], [], 400.0) == set()
    # a teammate in a duel: the opponent 250 mm beside it is not merged into it
    assert same_robots([(0.0, 0.0)], [(250.0, 0.0), (50.0, 0.0)], 400.0) == {1}
    # two teammates near one seen robot: it is only one of them
    assert same_robots([(0.0, 0.0), (100.0, 0.0)], [(60.0, 0.0)], 400.0) == {0}
    assert same_robots([(0.0, 0.0)], [(400.0, 0.0)], 400.0) == set()  # not nearer than within


def test_a_teammate_said_to_be_out_of_view_is_never_a_robot_seen_in_view() -> None:
    """5v5 (issue 32): a teammate 300 mm behind the robot, where it sees nothing, and an opponent beside it, seen, within
    ``same_robot`` of the teammate's place: the opponent was taken for the teammate, and no walk was kept from it. Now
    it stays a robot; a robot remembered out of view near the teammate's place is still the teammate."""
    mates = TeamMates(mates=[mate(2, -250.0, 200.0)])  # behind-left, beyond view_angle (100 degrees)
    harness = ModuleHarness(ObstacleModeler, RobotPose(valid=True), mates, RobotsPercept(robots=[SeenRobot(0.0, 420.0)]))
    found = harness.execute()[Obstacles].obstacles
    assert sorted(o.kind.name for o in found) == ["robot", "teammate"]
    # the same teammate said to be in view (ahead-left) is the robot seen there: counted once
    harness = ModuleHarness(ObstacleModeler, RobotPose(valid=True), TeamMates(mates=[mate(2, 250.0, 200.0)]),
                            RobotsPercept(robots=[SeenRobot(100.0, 420.0)]))
    assert [o.kind for o in harness.execute()[Obstacles].obstacles] == [ObstacleKind.teammate]
    # a robot seen ahead, then turned away from (remembered behind): the teammate said to be there is that robot
    harness = ModuleHarness(ObstacleModeler, RobotPose(valid=True), TeamMates(), RobotsPercept(robots=[SeenRobot(300.0, 0.0)]))
    harness.execute()
    harness.set(RobotPose(valid=True, rotation=math.pi), RobotsPercept(robots=[]), TeamMates(mates=[mate(2, 350.0, 0.0)]))
    assert [o.kind for o in harness.execute()[Obstacles].obstacles] == [ObstacleKind.teammate]
