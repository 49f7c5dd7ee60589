"""A cognition module for the web view's tests: on request, it writes each frame's number into the top
image (so a test can see which frame's drawings the page drew over which image), and it starts a plot
of a new name (so a test can see how soon a new name reaches the page).

Run it with ``tafel run --add-module cognition:tests.support.frame_stamp:FrameStamp``.
"""

from __future__ import annotations

from tafel.core import Module, provides, representation, requires
from tafel.debug import Canvas, DebugRequest, Plot
from tafel.representations.infrastructure import FrameInfo
from tafel.representations.perception import CameraImageTop


@representation
class FrameStampOutput:
    """The last frame stamped (a module provides something)."""

    frame: int = 0


@requires(FrameInfo, CameraImageTop)
@provides(FrameStampOutput)
class FrameStamp(Module):
    draw = DebugRequest("the frame's number in the top image")
    plot = DebugRequest("a plot named FrameStamp:frame")
    frame = Plot("the frame number, while FrameStamp:plot is on")

    def execute(self) -> None:
        frame = self.frame_info.frame_number
        self.frame_stamp_output.frame = frame
        if self.draw:
            self.draw.canvas(Canvas.IMAGE_TOP).text(12, 40, str(frame), color="yellow", size=24)
        if self.plot:
            self.frame.add(frame)
