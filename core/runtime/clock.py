"""One time base for every context and every process of a program.

Frame times (``FrameInfo.time_ns``), image times (``CameraImage.time_ns``) and everything derived from
them count nanoseconds of the system's monotonic clock since one origin, taken once per program. The
concurrent runtime hands the origin to the processes it starts, so a motion frame and a cognition
frame taken at the same instant carry the same time, and a camera's own timestamps (V4L2 buffers are
stamped with the same monotonic clock) convert with ``from_monotonic_ns``. Simulated clocks start at
0 and do not use this module.
"""

from __future__ import annotations

import time

_origin_ns: int | None = None


def origin_ns() -> int:
    """The monotonic time (ns) of the program's time 0; taken at the first call unless set."""
    global _origin_ns
    if _origin_ns is None:
        _origin_ns = time.monotonic_ns()
    return _origin_ns


def set_origin(value_ns: int) -> None:
    """Adopt another process's origin (the concurrent runtime's context processes do this first)."""
    global _origin_ns
    _origin_ns = int(value_ns)


def now_ns() -> int:
    """The program's time now (ns since its origin)."""
    return time.monotonic_ns() - origin_ns()


def from_monotonic_ns(monotonic_ns: int) -> int:
    """A CLOCK_MONOTONIC timestamp (a V4L2 buffer's, say) on the program's time base."""
    return int(monotonic_ns) - origin_ns()
