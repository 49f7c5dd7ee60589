"""Cognition works on the newest camera image: after a slow frame the stale images queued in the
driver are dropped, never worked through in turn, and the drop is counted."""

from __future__ import annotations

import time

import cv2
import numpy as np

from tafel.platforms.v4l2 import MAX_SKIPPED, newest_image


class QueuedCamera:
    """A V4L2 capture whose driver queue holds images taken at ``ages_s`` before now (oldest first)."""

    def __init__(self, ages_s: list[float]) -> None:
        base = time.monotonic_ns()  # V4L2 stamps buffers with CLOCK_MONOTONIC
        self.queue = [(i, base - int(age * 1e9)) for i, age in enumerate(ages_s)]
        self.current = (None, 0)

    def read(self) -> tuple[bool, np.ndarray | None]:
        if not self.queue:
            return False, None
        self.current = self.queue.pop(0)
        return True, np.full((2, 2, 3), self.current[0], np.uint8)

    def get(self, prop: int) -> float:
        assert prop == cv2.CAP_PROP_POS_MSEC
        return self.current[1] / 1e6


def test_stale_images_are_dropped_until_the_newest() -> None:
    camera = QueuedCamera([0.20, 0.167, 0.133, 0.10, 0.01])  # a cognition frame of 200 ms: five queued
    ok, frame, _, dropped = newest_image(camera, "/dev/video-test")
    assert ok and frame[0, 0, 0] == 4 and dropped == 4


def test_a_fresh_image_is_taken_as_it_is() -> None:
    camera = QueuedCamera([0.01, 0.0])
    ok, frame, _, dropped = newest_image(camera, "/dev/video-test")
    assert ok and frame[0, 0, 0] == 0 and dropped == 0


def test_an_old_image_with_nothing_newer_is_kept_and_at_most_a_few_are_skipped() -> None:
    ok, frame, _, dropped = newest_image(QueuedCamera([0.5]), "/dev/video-test")
    assert ok and dropped == 0  # the camera is late, but it is the newest there is
    ok, frame, _, dropped = newest_image(QueuedCamera([0.9 - i * 0.01 for i in range(30)]), "/dev/video-test")
    assert ok and dropped == MAX_SKIPPED
