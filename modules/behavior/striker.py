"""Striker: find the ball, walk behind it, kick it towards the opponent goal, follow it, repeat."""

from __future__ import annotations

import math
from dataclasses import dataclass

from tafel.core import Module, bounded, provides, requires, uses
from tafel.debug import drawing, request
from tafel.representations import field
from tafel.representations.infrastructure import FrameInfo
from tafel.representations.modeling import BallModel, RobotPose
from tafel.representations.motion_control import Foot, MotionInfo, MotionRequest, MotionType, Odometry

DRAW = request("Striker:draw_target", "where the striker wants to stand, on the robot canvas")


@requires(BallModel, Odometry, MotionInfo, FrameInfo)
@uses(RobotPose)
@provides(MotionRequest)
class Striker(Module):
    """The kick goes from the ball to the opponent goal's centre, through ``RobotPose``, from anywhere
    on the field. While the pose is not valid (before the first fix, or lost) it goes the way the robot
    faced at the start, by odometry: in the default scene, the opponent goal as well.

    - No ball: turn on the spot (the head searches meanwhile).
    - Ball: walk to the point ``behind`` mm behind it on the line of the kick, the kicking foot in line
      with the ball, facing the kick direction.
    - There, with the ball in front of the foot: kick, and wait for the kick to end.
    """

    @dataclass
    class Parameters:
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
        search_turn: float = bounded(0.0, 2.0, 0.6)
        """rad/s while the ball is lost"""

    def execute(self) -> None:
        p, ball, out = self.parameters, self.ball_model, self.motion_request
        if self.motion_info.busy:  # a kick or get-up plays to its end
            return
        if not ball.valid:
            out.motion, out.walk_x, out.walk_y = MotionType.walk, 0.0, 0.0
            out.walk_rotation = p.search_turn
            return
        kick_direction = self.kick_direction(ball.x, ball.y)
        foot = Foot.left if ball.y >= 0 else Foot.right
        side = p.foot_offset if foot is Foot.left else -p.foot_offset
        c, s = math.cos(kick_direction), math.sin(kick_direction)
        # behind the ball on the kick's line, shifted so that the kicking foot (not the centre) meets it
        target_x = ball.x - c * p.behind + s * side
        target_y = ball.y - s * p.behind - c * side
        if DRAW:
            drawing("robot").robot_pose(target_x, target_y, kick_direction, color="orange")
        # the ball as the kicking foot sees it, in the kick's frame
        along = c * ball.x + s * ball.y
        across = -s * ball.x + c * ball.y - side
        if abs(along - p.behind) < p.kick_tolerance_x and abs(across) < p.kick_tolerance_y and abs(kick_direction) < p.kick_tolerance_angle:
            out.motion, out.kick_foot, out.kick_direction = MotionType.kick, foot, kick_direction
            return
        out.motion = MotionType.walk_to
        out.target_x, out.target_y, out.target_rotation = target_x, target_y, kick_direction

    def kick_direction(self, ball_x: float, ball_y: float) -> float:
        """rad in the robot frame: from the ball to the goal's centre, or the start heading without a pose."""
        pose = self.robot_pose
        if not pose.valid:
            return math.remainder(-self.odometry.rotation, math.tau)
        goal_x, goal_y = pose.to_robot(field.LENGTH / 2 + field.GOAL_DEPTH / 2, 0.0)
        return math.atan2(goal_y - ball_y, goal_x - ball_x)
