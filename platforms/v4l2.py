"""Image times of V4L2 cameras on the program's clock."""

from __future__ import annotations

import logging
from typing import Any

import cv2

from tafel.core import clock

log = logging.getLogger("tafel.platform.camera")
#: a buffer timestamp further than this from the time of the read is not on the monotonic clock
PLAUSIBLE_NS = 2_000_000_000
_warned: set[str] = set()


def image_time_ns(capture: Any, device: str) -> int:
    """When the image just read was taken, on the program's clock.

    V4L2 stamps each buffer with CLOCK_MONOTONIC at capture (OpenCV reports it as
    ``CAP_PROP_POS_MSEC``), so it converts directly. A driver that stamps with another clock, or none,
    gives an implausible value: then the time of the read is used, and that is said once per device.
    """
    read_ns = clock.now_ns()
    try:
        stamp_ms = float(capture.get(cv2.CAP_PROP_POS_MSEC))
    except Exception:  # noqa: BLE001 - a backend without the property: fall back below
        stamp_ms = 0.0
    if stamp_ms > 0:
        taken_ns = clock.from_monotonic_ns(int(stamp_ms * 1e6))
        if 0 <= read_ns - taken_ns <= PLAUSIBLE_NS:
            return taken_ns
    if device not in _warned:
        _warned.add(device)
        log.warning("camera %s gives no monotonic buffer timestamps; image times are the times of reading", device)
    return read_ns
