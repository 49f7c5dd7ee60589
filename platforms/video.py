"""The video platform: a video file or a webcam as the robot's top camera, and nothing else.

The way to develop vision on a laptop or on recorded video. Only cognition gets data (the image and
the frame time); every module that needs more (all of motion, ball modelling that needs a camera
matrix) is pruned by the runtime, which says so. A file plays at its own frame rate unless ``--fps``
says otherwise, and stops at its end (or starts over with ``--loop``).
"""

from __future__ import annotations

import argparse
import math
import os
import time
from collections.abc import Mapping
from typing import Any, ClassVar

import cv2
import numpy as np

from tafel.core import clock
from tafel.core.manager import Blackboard
from tafel.core.platform import EndOfData, Platform, PlatformError, PlatformOptionError
from tafel.platforms.v4l2 import image_time_ns
from tafel.representations.infrastructure import FrameInfo
from tafel.representations.perception import CameraImageBottom, CameraImageTop


class VideoPlatform(Platform):
    name = "video"
    description = "a video file or webcam as the top camera (--source FILE|DEVICE_INDEX)"
    clock = "own"
    provides: ClassVar[Mapping[str, tuple[type, ...]]] = {"cognition": (FrameInfo, CameraImageTop, CameraImageBottom)}
    consumes: ClassVar[Mapping[str, tuple[type, ...]]] = {}

    def __init__(self, options: Mapping[str, Any] | None = None) -> None:
        super().__init__(options)
        source = self.options.get("source")
        if source is None or str(source) == "":
            raise PlatformOptionError("the video platform needs --source FILE or --source DEVICE_INDEX (0 for the first webcam)")
        self.source = str(source)
        self.device = int(self.source) if self.source.isdigit() else None
        self.loop = bool(self.options.get("loop"))
        fps = self.options.get("fps")
        self.fps_override = float(fps) if fps else None
        if self.fps_override is not None and self.fps_override <= 0:
            raise PlatformOptionError(f"--fps must be positive, got {fps}")
        self.horizontal_fov = math.radians(float(self.options.get("fov") or 60.0))
        self.capture: Any = None
        self.frame_index = 0
        self.time_ns = 0
        self.started_ns = 0
        self.check()

    @classmethod
    def add_arguments(cls, parser: argparse.ArgumentParser) -> None:
        parser.add_argument("--source", help="video: a video file, or the index of a webcam (0, 1, ...)")
        parser.add_argument("--loop", action="store_true", help="video: start the file again at its end")
        parser.add_argument("--fps", type=float, help="video: play the file at this rate instead of its own")
        parser.add_argument("--fov", type=float, default=60.0, help="video: horizontal field of view of the camera (degrees)")

    def check(self) -> None:
        """Fail now, with a clear message, if the source cannot be opened (before processes start)."""
        if self.device is None and not os.path.isfile(self.source):
            raise PlatformError(f"video file {self.source} does not exist")
        capture = self._open()
        capture.release()

    def _open(self) -> Any:
        capture = cv2.VideoCapture(self.device if self.device is not None else self.source)
        if not capture.isOpened():
            capture.release()
            if self.device is not None:
                raise PlatformError(f"no camera at index {self.device} (is it connected, and free? /dev/video{self.device})")
            raise PlatformError(f"cannot read video file {self.source}: OpenCV cannot decode it")
        return capture

    def rates(self) -> Mapping[str, float] | None:
        return {"cognition": self.frame_rate()}

    def frame_rate(self) -> float:
        """Frames per second the source is played at."""
        if self.fps_override:
            return self.fps_override
        capture = self.capture or self._open()
        rate = capture.get(cv2.CAP_PROP_FPS)
        if capture is not self.capture:
            capture.release()
        return rate if rate and rate > 0 else 30.0

    def start(self, contexts: frozenset[str]) -> None:
        if "cognition" in contexts:
            self.capture = self._open()
            self.period_ns = int(1e9 / self.frame_rate())
            self.started_ns = time.monotonic_ns()

    def sense(self, context: str, blackboard: Blackboard, frame_number: int, time_ns: int) -> None:
        ok, frame = self.capture.read()
        if not ok and self.device is None and self.loop:
            self.capture.set(cv2.CAP_PROP_POS_FRAMES, 0)
            ok, frame = self.capture.read()
        if not ok:
            if self.device is not None:
                raise PlatformError(f"camera {self.device} stopped delivering images")
            raise EndOfData(f"end of {self.source}")
        if self.device is None:  # a file is paced to its frame rate; a camera paces itself
            due = self.started_ns + self.frame_index * self.period_ns
            delay = due - time.monotonic_ns()
            if delay > 0:
                time.sleep(delay * 1e-9)
            self.time_ns = self.frame_index * self.period_ns
            taken_ns = self.time_ns
        else:
            self.time_ns = clock.now_ns()
            taken_ns = image_time_ns(self.capture, str(self.device))
        self.frame_index += 1
        blackboard.set(FrameInfo(frame_number=frame_number, time_ns=self.time_ns))
        image = blackboard[CameraImageTop]
        image.time_ns = taken_ns
        image.image = cv2.cvtColor(frame, cv2.COLOR_BGR2RGB)
        height, width = image.image.shape[:2]
        image.horizontal_fov = self.horizontal_fov
        image.vertical_fov = 2 * math.atan(math.tan(self.horizontal_fov / 2) * height / width)
        # there is one camera: the bottom image stays empty, and perception skips it
        blackboard[CameraImageBottom].image = np.zeros((0, 0, 3), np.uint8)

    def frame_time_ns(self, context: str) -> int | None:
        return self.time_ns

    def stop(self) -> None:
        if self.capture is not None:
            self.capture.release()
            self.capture = None
