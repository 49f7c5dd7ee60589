"""The striker's turn while it searches the ball (``ball_search.SearchTurn``): towards where the ball probably
is, through the mocked blackboard."""

from __future__ import annotations

import math

from tafel.core.testing import ModuleHarness
from tafel.modules.behavior.ball_search import turn_to_see
from tafel.modules.behavior.striker import Striker
from tafel.representations.modeling import BallModel, RobotPose
from tafel.representations.motion_control import MotionInfo, MotionRequest, MotionType, Odometry
from tafel.representations.team import TeamMate, TeamMates, TeamMessage


def team(ball: tuple[float, float] | None) -> TeamMates:
    """A teammate with a valid pose that reports ``ball`` (field, mm), or none."""
    if ball is None:
        return TeamMates(mates=[])
    said = TeamMessage(team=1, player=3, sent_ms=0, pose_valid=True, ball_seen=True, ball_x=ball[0], ball_y=ball[1], ball_age=0.2)
    return TeamMates(mates=[TeamMate(message=said, age=0.3)])


def turn(pose: RobotPose, team_ball: tuple[float, float] | None, ball: BallModel | None = None) -> float:
    """rad/s the striker turns in the first frame of a search."""
    harness = ModuleHarness(Striker, ball or BallModel(valid=False), pose, team(team_ball), Odometry(), MotionInfo())
    request = harness.execute()[MotionRequest]
    assert request.motion is MotionType.walk and request.walk_x == 0.0 and request.walk_y == 0.0
    return request.walk_rotation


def test_it_turns_towards_the_teams_ball_behind_it() -> None:
    """With a valid pose the striker turns towards the side where the teammate's ball lies behind it."""
    pose = RobotPose(valid=True, x=0.0, y=0.0, rotation=0.0, deviation=80.0, mirror_probability=0.0)
    assert turn(pose, (-2000.0, -800.0)) < 0.0  # behind, on the right
    assert turn(pose, (-2000.0, 800.0)) > 0.0  # behind, on the left


def test_an_unsure_robot_turns_by_both_places_of_the_teams_ball() -> None:
    """With the pose not valid but the particles gathered, the team's ball lies where it is seen from the
    estimate or from its twin, each as likely: the turn brings the one beyond the head's reach into reach the
    shorter way (the other, ahead, the head looks at meanwhile). Spread particles give no place; the last seen
    ball is no guide either for a robot that lost its pose (it may have been carried): it turns left, as the
    first search always does."""
    pose = RobotPose(valid=False, lost=True, x=0.0, y=0.0, rotation=0.0, deviation=150.0, mirror_probability=0.5)
    last_seen = BallModel(valid=False, x=-500.0, y=1000.0, time_since_seen=2.0)
    assert turn(pose, (-2000.0, -800.0), last_seen) < 0.0  # from the estimate behind on the right, from the twin ahead
    assert turn(pose, (2000.0, -800.0), last_seen) > 0.0  # from the twin behind on the left, from the estimate ahead
    spread = RobotPose(valid=False, lost=True, x=0.0, y=0.0, rotation=0.0, deviation=2000.0, mirror_probability=0.5)
    assert turn(spread, (-2000.0, -800.0), BallModel(valid=False, x=-500.0, y=-1000.0, time_since_seen=2.0)) > 0.0


def test_places_looked_at_from_a_pose_the_particles_left_count_again() -> None:
    """The estimate jumps (the particles found another place): a place that was within the head's reach from the
    old estimate lies elsewhere from the new one and counts again in the turn."""
    harness = ModuleHarness(Striker, BallModel(valid=False), team((2000.0, 300.0)), Odometry(), MotionInfo())
    harness.set(RobotPose(valid=False, lost=True, x=0.0, y=0.0, rotation=0.0, deviation=150.0, mirror_probability=0.5))
    assert harness.execute()[MotionRequest].walk_rotation < 0.0  # the estimate's place ahead, the twin's behind on the right
    harness.set(RobotPose(valid=False, lost=True, x=0.0, y=0.0, rotation=-2.54, deviation=150.0, mirror_probability=0.5))
    assert harness.execute()[MotionRequest].walk_rotation > 0.0  # now the estimate's place lies behind on the left


def test_without_a_teams_ball_it_turns_towards_the_last_seen_ball_or_the_way_it_turned_last() -> None:
    """No teammate's ball: towards the side the ball was last seen on; never seen, or lost since: the way of
    the last search (left at first)."""
    pose = RobotPose(valid=True, x=0.0, y=0.0, rotation=0.0, deviation=80.0)
    assert turn(pose, None, BallModel(valid=False, x=-300.0, y=-900.0, time_since_seen=2.0)) < 0.0
    assert turn(pose, None, BallModel(valid=False, x=-300.0, y=900.0, time_since_seen=2.0)) > 0.0
    harness = ModuleHarness(Striker, BallModel(valid=False), pose, team(None), Odometry(), MotionInfo())
    first = harness.execute()[MotionRequest].walk_rotation
    assert first > 0.0
    harness.set(BallModel(valid=True, seen=True, x=500.0, y=-2000.0))  # found on the right ...
    assert harness.execute()[MotionRequest].motion is MotionType.walk_to
    harness.set(BallModel(valid=False, x=500.0, y=-2000.0, time_since_seen=1.0))  # ... and lost there
    assert harness.execute()[MotionRequest].walk_rotation == -first
    harness.set(BallModel(valid=True, seen=True, x=500.0, y=2000.0), RobotPose(valid=False, lost=True, deviation=2000.0))
    harness.execute()
    harness.set(BallModel(valid=False, x=500.0, y=2000.0, time_since_seen=1.0))  # lost on the left, but the pose too
    assert harness.execute()[MotionRequest].walk_rotation == -first


def test_a_search_keeps_its_way_once_the_place_was_within_reach() -> None:
    """Turning towards the team's ball behind it, the robot keeps its way once the place has come within the
    head's reach without the ball being found there: it turns on, never back and forth."""
    harness = ModuleHarness(Striker, BallModel(valid=False), team((-2000.0, -800.0)), Odometry(), MotionInfo())
    rotation, sides = 0.0, []
    for _ in range(450):  # 15 s, the body turning as asked: more than a full turn
        harness.set(RobotPose(valid=True, x=0.0, y=0.0, rotation=rotation, deviation=80.0, mirror_probability=0.0))
        speed = harness.execute()[MotionRequest].walk_rotation
        sides.append(speed)
        rotation = math.remainder(rotation + speed / 30.0, math.tau)
    assert all(side < 0.0 for side in sides)


def test_the_turn_needed_to_bring_a_place_into_reach() -> None:
    assert turn_to_see(1.0, 1.0, 2.0) == 0.0 and turn_to_see(-1.9, 1.0, 2.0) == 0.0
    assert math.isclose(turn_to_see(3.0, 1.0, 2.0), 1.0) and math.isclose(turn_to_see(3.0, -1.0, 2.0), math.tau - 5.0)
    assert math.isclose(turn_to_see(-2.5, -1.0, 2.0), 0.5)
