"""LookAtBallBehavior: look at the ball while it is known; sweep the head to find it when it is not."""

from __future__ import annotations

import math
from dataclasses import dataclass

from core import Module, provides, requires
from representations.behavior import HeadMotionRequest
from representations.infrastructure import FrameInfo
from representations.modeling import BallModel


@requires(BallModel, FrameInfo)
@provides(HeadMotionRequest)
class LookAtBallBehavior(Module):
    """Points the head at the ball model's position; searches left and right when the model is invalid."""

    @dataclass
    class Parameters:
        camera_height: float = 480.0
        """mm, height of the top camera above the ground when standing"""
        camera_tilt: float = math.radians(1.2)
        """rad, downward tilt of the top camera relative to the head"""
        search_amplitude: float = 1.2
        """rad, largest head yaw while searching"""
        search_period: float = 6.0
        """s for one full left-right sweep"""
        search_pitch: float = 0.3
        """rad, head pitch while searching"""
        track_speed: float = 3.0
        """rad/s, head speed while tracking"""
        search_speed: float = 1.5
        """rad/s, head speed while searching"""

    def execute(self) -> None:
        p, ball, request = self.parameters, self.ball_model, self.head_motion_request
        if ball.valid:
            distance = max(math.hypot(ball.x, ball.y), 1.0)
            request.yaw = math.atan2(ball.y, ball.x)
            request.pitch = math.atan2(p.camera_height, distance) - p.camera_tilt
            request.max_speed = p.track_speed
            return
        phase = 2.0 * math.pi * self.frame_info.time_s / p.search_period
        request.yaw = p.search_amplitude * math.sin(phase)
        request.pitch = p.search_pitch
        request.max_speed = p.search_speed
