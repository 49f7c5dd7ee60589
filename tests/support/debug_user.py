"""A cognition module that uses every debug concept, for the debug server tests."""

from __future__ import annotations

from tafel.core import Module, provides, representation, requires
from tafel.debug import drawing, modify, plot, request, stopwatch
from tafel.representations.infrastructure import FrameInfo

DRAW = request("DebugUser:draw", "a circle on the field every frame")


@representation
class DebugUserOutput:
    """gain * frame number, so a pinned modify value shows in the output."""

    value: float = 0.0


@requires(FrameInfo)
@provides(DebugUserOutput)
class DebugUser(Module):
    def execute(self) -> None:
        frame = self.frame_info.frame_number
        gain = modify("DebugUser:gain", 1.0)
        with stopwatch("DebugUser:work"):
            self.debug_user_output.value = gain * frame
        plot("DebugUser:frame", frame)
        if DRAW:
            drawing("field").circle(100.0, 200.0, 50.0, color="orange", width=2)
            drawing("image:top").text(10, 20, f"frame {frame}")
