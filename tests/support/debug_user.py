"""A cognition module that declares every kind of debug output, for the debug server tests."""

from __future__ import annotations

from tafel.core import Module, provides, representation, requires
from tafel.debug import Canvas, DebugRequest, ModifyValue, Plot, Stopwatch
from tafel.representations.infrastructure import FrameInfo


@representation
class DebugUserOutput:
    """gain * frame number, so a pinned modify value shows in the output."""

    value: float = 0.0


@requires(FrameInfo)
@provides(DebugUserOutput)
class DebugUser(Module):
    draw = DebugRequest("a circle on the field every frame")
    gain = ModifyValue(1.0, "the factor of the frame number in the output")
    work = Stopwatch("computing the output")
    frame = Plot("the frame number")

    def execute(self) -> None:
        frame = self.frame_info.frame_number
        gain = self.gain()
        with self.work:
            self.debug_user_output.value = gain * frame
        self.frame.add(frame)
        if self.draw:
            self.draw.canvas(Canvas.FIELD).circle(100.0, 200.0, 50.0, color="orange", width=2)
            self.draw.canvas(Canvas.IMAGE_TOP).text(10, 20, f"frame {frame}")
