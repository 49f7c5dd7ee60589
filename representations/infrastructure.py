"""Representations every context has: the frame clock."""

from __future__ import annotations

from tafel.core import representation


@representation
class FrameInfo:
    """The current frame of a context: its number and its time (platform clock, nanoseconds)."""

    frame_number: int = 0
    time_ns: int = 0

    @property
    def time_s(self) -> float:
        """``time_ns`` in seconds."""
        return self.time_ns * 1e-9


# Provided by the runtime to motion; defined in core because the runtime fills it.
from tafel.core.runtime.status import CognitionStatus  # noqa: E402

__all__ = ["CognitionStatus", "FrameInfo"]
