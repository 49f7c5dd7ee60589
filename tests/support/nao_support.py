"""A cognition module that needs no camera, so the nao platform can be tested without one."""

from __future__ import annotations

from tafel.core import Module, provides, requires
from tafel.representations.behavior import HeadMotionRequest
from tafel.representations.infrastructure import FrameInfo


@requires(FrameInfo)
@provides(HeadMotionRequest)
class LookLeft(Module):
    """Asks the head to turn to 0.5 rad, slowly enough to watch it move."""

    def execute(self) -> None:
        self.head_motion_request.yaw = 0.5
        self.head_motion_request.pitch = 0.0
        self.head_motion_request.max_speed = 1.0
