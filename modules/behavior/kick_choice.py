"""What SoccerBehavior's kick plan goes by beside the pass rule (``passing.py``): the way an own free kick goes,
never straight at the goal (``indirect_direction``), and which robots seen are opponents (``seen_opponents``)."""

from __future__ import annotations

import math
from typing import Protocol

from tafel.modules.behavior.kicking import goal_direction
from tafel.representations import field as pitch
from tafel.representations.modeling import BallModel, RobotPose
from tafel.representations.motion_control import Odometry
from tafel.representations.obstacles import ObstacleKind, Obstacles, same_robots
from tafel.representations.team import TeamMates


class SightParameters(Protocol):
    """What ``seen_opponents`` reads of SoccerBehavior.Parameters."""

    pass_mate_age: float
    pass_mate_seen: float


class Sighted(Protocol):
    """What ``seen_opponents`` reads of SoccerBehavior."""

    robot_pose: RobotPose
    obstacles: Obstacles
    team_mates: TeamMates

    @property
    def parameters(self) -> SightParameters: ...


def seen_opponents(b: Sighted) -> list[tuple[float, float]]:
    """The robots seen (field mm; needs a valid pose) but those that are teammates: the robot seen nearest where a
    teammate said it was (within ``pass_mate_seen``) is that teammate, walked on since."""
    pose, p = b.robot_pose, b.parameters
    seen = [pose.to_field(o.x, o.y) for o in b.obstacles.obstacles if o.kind is ObstacleKind.robot]
    mates_seen = same_robots([(m.message.x, m.message.y) for m in b.team_mates.fresh(p.pass_mate_age)], seen, p.pass_mate_seen)
    return [robot for k, robot in enumerate(seen) if k not in mates_seen]


def indirect_direction(ball: BallModel, pose: RobotPose, odometry: Odometry, indirect_target: list[float]) -> float:
    """rad in the robot frame for an own free kick: ahead and towards the middle, not at the goal."""
    if not pose.valid:
        return goal_direction(ball, pose, odometry) + 0.6  # beside the goal rather than at it
    bx, by = ball.field_position(pose)
    ahead, inward = indirect_target
    tx = min(bx + ahead, pitch.LENGTH / 2 - pitch.PENALTY_AREA_LENGTH)  # near the goal line: back into the field
    tx = bx - 300.0 if abs(tx - bx) < 300.0 else tx
    ty = by * (1.0 - inward)
    beside, to_line = pitch.GOAL_INNER_WIDTH / 2 + 500.0, max(pitch.LENGTH / 2 - bx, 1.0)
    if tx > bx and abs(by + (ty - by) * to_line / (tx - bx)) < beside:  # it would cross the goal line in the goal
        ty = by + (math.copysign(beside, by if by else 1.0) - by) * (tx - bx) / to_line  # aim beside it instead
    rx, ry = pose.to_robot(tx, ty)
    return math.atan2(ry - ball.y, rx - ball.x)
