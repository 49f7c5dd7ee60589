"""How a field player gets the ball to where it wants it: walk behind it on the kick's line, then kick.

Shared by the behaviours that kick (``Striker``, ``SoccerBehavior``); not a module.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields

from tafel.core import bounded
from tafel.debug import ModifyParameters
from tafel.representations import field
from tafel.representations.geometry import Pose2D
from tafel.representations.modeling import BallModel, RobotPose
from tafel.representations.motion_control import Foot, MotionRequest, MotionType, Odometry


@dataclass
class KickParameters:
    behind: float = bounded(100.0, 500.0, 190.0)
    """mm from the ball to the robot's centre when kicking"""
    foot_offset: float = bounded(0.0, 120.0, 50.0)
    """mm sideways from the robot's centre to the kicking foot's centre"""
    kick_tolerance_x: float = bounded(10.0, 200.0, 45.0)
    """mm the ball may lie nearer or farther than ``behind`` for a kick"""
    kick_tolerance_y: float = bounded(5.0, 100.0, 30.0)
    """mm the ball may lie beside the kicking foot for a kick"""
    kick_tolerance_angle: float = bounded(0.02, 1.0, 0.2)
    """rad the robot may face away from the kick direction for a kick"""


#: the kick's parameters tried live: modify values Kick:NAME, declared by the modules that kick
KICK_TUNED = tuple(item.name for item in fields(KickParameters))


def kick_tuning() -> ModifyParameters:
    """The declaration of the kick's modify values, for a module that kicks: ``kick_tuning = kick_tuning()``."""
    return ModifyParameters(KICK_TUNED, "the kick, tried live: modify:set Kick:NAME", prefix="Kick")


def goal_direction(ball: BallModel, pose: RobotPose, odometry: Odometry) -> float:
    """rad in the robot frame from the ball to the opponent goal's centre; without a valid pose, the way
    the robot faced at the start (by odometry), which in the default scene is that goal as well."""
    if not pose.valid:
        return math.remainder(-odometry.rotation, math.tau)
    goal_x, goal_y = pose.to_robot(field.LENGTH / 2 + field.GOAL_DEPTH / 2, 0.0)
    return math.atan2(goal_y - ball.y, goal_x - ball.x)


def approach_and_kick(ball: BallModel, kick_direction: float, p: KickParameters, out: MotionRequest) -> tuple[float, float, float]:
    """Fill ``out``: kick towards ``kick_direction`` (rad, robot frame) when the ball lies right in front
    of the kicking foot, else walk to the point ``behind`` mm behind the ball on the kick's line, the
    kicking foot in line with the ball. Returns that point and direction (mm, mm, rad; robot frame).

    The caller passes ``p`` with its modify values ``Kick:NAME`` applied (``kick_tuning``), so a value pinned
    by a debug client is tried live."""
    foot = Foot.left if ball.y >= 0 else Foot.right
    side = p.foot_offset if foot is Foot.left else -p.foot_offset
    # behind the ball on the kick's line, shifted so that the kicking foot (not the centre) meets it
    target_x, target_y = Pose2D(ball.x, ball.y, kick_direction).to_global(-p.behind, -side)
    # the ball as the kicking foot sees it, in the kick's frame
    along, across = Pose2D(0.0, 0.0, kick_direction).to_local(ball.x, ball.y)
    across -= side
    if abs(along - p.behind) < p.kick_tolerance_x and abs(across) < p.kick_tolerance_y and abs(kick_direction) < p.kick_tolerance_angle:
        out.motion, out.kick_foot, out.kick_direction = MotionType.kick, foot, kick_direction
    else:
        out.motion = MotionType.walk_to
        out.target_x, out.target_y, out.target_rotation = target_x, target_y, kick_direction
    return target_x, target_y, kick_direction
