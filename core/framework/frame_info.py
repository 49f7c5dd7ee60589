"""``FrameInfo``, the frame clock every context has: the runtime writes it before a frame's modules run.

It lives in core because the runtime fills it and the module harness drives it; modules import it
from ``tafel.representations`` (``infrastructure.py``) as before.
"""

from __future__ import annotations

from tafel.core.framework.representation import representation


@representation
class FrameInfo:
    """The current frame of a context: its number and its time (platform clock, nanoseconds)."""

    frame_number: int = 0
    time_ns: int = 0

    @property
    def time_s(self) -> float:
        """``time_ns`` in seconds."""
        return self.time_ns * 1e-9


__all__ = ["FrameInfo"]
