"""A cognition module that asks for one motion, set by parameters: walking tests without behaviour.

Configuration names it as ``tests.support.motion_requests:ConstantMotionRequest``.
"""

from __future__ import annotations

from dataclasses import dataclass

from tafel.core import Module, provides
from tafel.representations.motion_control import Foot, MotionRequest, MotionType


@provides(MotionRequest)
class ConstantMotionRequest(Module):
    @dataclass
    class Parameters:
        motion: str = "stand"
        x: float = 0.0
        """mm/s (walk) or mm (walk_to)"""
        y: float = 0.0
        rotation: float = 0.0
        foot: str = "left"

    def execute(self) -> None:
        p, out = self.parameters, self.motion_request
        out.motion = MotionType[p.motion]
        out.walk_x, out.walk_y, out.walk_rotation = p.x, p.y, p.rotation
        out.target_x, out.target_y, out.target_rotation = p.x, p.y, p.rotation
        out.kick_foot = Foot[p.foot]
