"""Image times of V4L2 cameras on the program's clock."""

from __future__ import annotations

import logging
from typing import Any

import cv2

from tafel.core.runtime import clock

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


#: s an image may be old when it is read before it counts as stale (a camera at 30 Hz: 1.5 periods)
STALE_S = 0.05
#: stale images skipped at most per read: the queue of a V4L2 driver holds a few
MAX_SKIPPED = 8


def newest_image(capture: Any, device: str) -> tuple[bool, Any, int, int]:
    """The newest image a camera has: (ok, frame, its time on the program's clock, images dropped).

    After a slow cognition frame the driver's queue holds older images; reading them in turn would put
    cognition ever further behind the world. Stale ones are dropped (never queued) until one is fresh,
    and the count goes back to the caller, which reports it.
    """
    dropped = 0
    ok, frame = capture.read()
    taken_ns = image_time_ns(capture, device)
    while ok and dropped < MAX_SKIPPED and clock.now_ns() - taken_ns > STALE_S * 1e9:
        newer_ok, newer = capture.read()
        if not newer_ok:
            break
        newer_ns = image_time_ns(capture, device)
        if newer_ns <= taken_ns:  # no newer image in the queue: this one is the newest there is
            break
        ok, frame, taken_ns = newer_ok, newer, newer_ns
        dropped += 1
    return ok, frame, taken_ns, dropped
