"""LookAtBallBehavior: look at the ball while it is seen, glancing round now and then for the
localization; sweep the head to find it when it is not; hold the head still while penalized."""

from __future__ import annotations

import math
from dataclasses import dataclass

from tafel.core import Module, provides, requires, uses
from tafel.representations.behavior import HOLD_SPEED, HeadMotionRequest
from tafel.representations.game import GameState
from tafel.representations.infrastructure import FrameInfo
from tafel.representations.modeling import BallModel, RobotPose


def sweep(start: float, direction: float, distance: float, amplitude: float) -> float:
    """Where a point moving ``distance`` from ``start`` in ``direction`` (+1/-1) is, bouncing at ±amplitude."""
    if amplitude <= 0:
        return 0.0
    position = start + direction * distance + amplitude  # unfold into [0, 4A) and fold back
    period = 4 * amplitude
    phase = position % period
    return (phase if phase <= 2 * amplitude else period - phase) - amplitude


@requires(BallModel, FrameInfo)
@uses(RobotPose, GameState)
@provides(HeadMotionRequest)
class LookAtBallBehavior(Module):
    """Points the head at the ball model's position while the ball is being seen. Once it has not been
    seen for ``lost_after`` (it rolled away, or was moved), the head sweeps left and right, starting
    towards the other side, where the ball most likely went out of view.

    A ball alone shows little of the field, so every ``glance_interval`` s (more often while the pose is
    not valid) the head glances left and right for lines and goals, unless the ball is close: then the
    striker needs it in view, and the ball model follows the robot's steps meanwhile anyway.

    While penalized the head holds still where it is (``max_speed`` 0): the rules allow a penalized
    robot no motion at all until the GameController unpenalizes it. Then it looks for the ball anew."""

    ball_model: BallModel
    frame_info: FrameInfo
    robot_pose: RobotPose
    game_state: GameState
    head_motion_request: HeadMotionRequest

    @dataclass
    class Parameters:
        camera_height: float = 480.0
        """mm, height of the top camera above the ground when standing"""
        camera_tilt: float = math.radians(1.2)
        """rad, downward tilt of the top camera relative to the head"""
        lost_after: float = 0.5
        """s without seeing the ball before searching"""
        search_amplitude: float = 1.2
        """rad, largest head yaw while searching"""
        search_pitch: float = 0.3
        """rad, head pitch while searching"""
        track_speed: float = 3.0
        """rad/s, head speed while tracking"""
        search_speed: float = 1.5
        """rad/s, head speed while searching"""

        glance_interval: float = 5.0
        """s between glances while the pose is valid"""
        glance_interval_lost: float = 1.5
        """s between glances while it is not"""
        glance_duration: float = 1.6
        """s of one glance: left, right, back"""
        glance_amplitude: float = 1.0
        """rad of head yaw a glance reaches to either side"""
        glance_min_ball_distance: float = 900.0
        """mm: nearer balls are never looked away from"""

    parameters: Parameters

    def __init__(self) -> None:
        self.search_start: tuple[float, float, float] | None = None  # (time s, yaw rad, direction)
        self.last_glance = 0.0  # s when the last glance started

    def execute(self) -> None:
        p, ball, request = self.parameters, self.ball_model, self.head_motion_request
        now = self.frame_info.time_s
        if self.game_state.penalized:
            request.max_speed, self.search_start = HOLD_SPEED, None
            return
        if ball.valid and ball.time_since_seen <= p.lost_after:
            self.search_start = None
            if self.glance(now, math.hypot(ball.x, ball.y)):
                return
            distance = max(math.hypot(ball.x, ball.y), 1.0)
            request.yaw = math.atan2(ball.y, ball.x)
            request.pitch = math.atan2(p.camera_height, distance) - p.camera_tilt
            request.max_speed = p.track_speed
            return
        if self.search_start is None:
            yaw = max(-p.search_amplitude, min(p.search_amplitude, request.yaw))
            self.search_start = (now, yaw, -1.0 if yaw > 0 else 1.0)
        started, yaw, direction = self.search_start
        request.yaw = sweep(yaw, direction, (now - started) * p.search_speed, p.search_amplitude)
        request.pitch = p.search_pitch
        request.max_speed = p.search_speed * 1.5  # the request itself moves at search speed; keep up with it

    def glance(self, now: float, ball_distance: float) -> bool:
        """Glance round if it is time (or go on with a glance begun); whether the head is glancing."""
        p, request = self.parameters, self.head_motion_request
        interval = p.glance_interval if self.robot_pose.valid else p.glance_interval_lost
        if now - self.last_glance >= p.glance_duration + interval and ball_distance >= p.glance_min_ball_distance:
            self.last_glance = now
        elapsed = now - self.last_glance
        if elapsed >= p.glance_duration or self.last_glance == 0.0:
            return False
        request.yaw = p.glance_amplitude * math.sin(2 * math.pi * elapsed / p.glance_duration)
        request.pitch = p.search_pitch
        request.max_speed = p.search_speed * 2.0
        return True
