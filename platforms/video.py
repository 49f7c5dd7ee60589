"""The video platform: a video file, a webcam, or recorded NAO images as the robot's camera, and nothing else.

The way to develop vision on a laptop, on recorded video and on what a real robot's cameras saw. Only
cognition gets data (the image and the frame time); every module that needs more (all of motion) is
pruned by the runtime, which says so. A file plays at its own frame rate unless ``--fps`` says
otherwise, and stops at its end (or starts over with ``--loop``).

A folder of images (PNG, JPEG, NAO raw YUV422 frames; or one such file) plays in file-name order, one
image per frame at ``--fps`` (default 2), with each camera's pose (``tafel.platforms.images``: a JSON
beside the image, PNG text chunks, ``--camera-pose``, or a standing robot looking ahead), so the camera
matrices are known and every perception module runs; the SPL ball detector is chosen. ``video:pause``,
``video:step`` and ``video:resume`` hold an image and step through them.
"""

from __future__ import annotations

import argparse
import math
import multiprocessing
import os
import sys
import time
from collections.abc import Mapping
from pathlib import Path
from typing import Any, ClassVar

import cv2
import numpy as np

from tafel.core.framework.manager import Blackboard
from tafel.core.framework.values import Range, convert, refusal
from tafel.core.runtime import clock
from tafel.core.runtime.platform import EndOfData, Platform, PlatformError, PlatformOptionError
from tafel.platforms.images import IMAGE_SUFFIXES, RAW_SUFFIXES, ImageSourceError, PosedImage, image_files, options_pose, posed_image
from tafel.platforms.v4l2 import image_time_ns
from tafel.representations.motion import CameraMatrixBottom, CameraMatrixBuffer, CameraMatrixTop
from tafel.representations.motion_control import Odometry
from tafel.representations.perception import Camera, CameraImageBottom, CameraImageTop

#: images per second a folder of images plays at without --fps
IMAGES_FPS = 2.0


#: what ``--fov`` takes
FOV = "a finite number of degrees above 0 and below 180 (the horizontal field of view)"


#: what ``check`` has said in this process
TOLD: set[str] = set()


class VideoPlatform(Platform):
    name = "video"
    description = "a video file, webcam or folder of NAO images as the camera (--source FILE|DEVICE_INDEX|FOLDER)"
    clock = "own"
    provides: ClassVar[Mapping[str, tuple[type, ...]]] = {"cognition": (CameraImageTop, CameraImageBottom)}
    consumes: ClassVar[Mapping[str, tuple[type, ...]]] = {}

    def __init__(self, options: Mapping[str, Any] | None = None) -> None:
        super().__init__(options)
        source = self.options.get("source")
        if source is None or str(source) == "":
            raise PlatformOptionError("the video platform needs --source FILE or --source DEVICE_INDEX (0 for the first webcam)")
        self.source = str(source)
        self.device = int(self.source) if self.source.isdigit() else None
        path = Path(self.source)
        self.images: list[Path] | None = None  # the image files, when the source is a folder or an image
        if path.is_dir():
            self.images = image_files(path)
            if not self.images:
                raise PlatformError(f"folder {self.source} holds no images: expected PNG, JPEG or BMP files or NAO raw frames "
                                    f"({', '.join(IMAGE_SUFFIXES + RAW_SUFFIXES)})")
        elif path.suffix.lower() in IMAGE_SUFFIXES + RAW_SUFFIXES and path.is_file():
            self.images = [path]
        camera = self.options.get("camera") or None
        self.camera: str | None = None if camera is None else convert(camera, Camera, where="--camera", text=False,
                                                                       error=PlatformOptionError).value
        try:
            self.pose = options_pose(self.options)
        except ImageSourceError as error:
            raise PlatformOptionError(str(error)) from error
        ball_color = self.options.get("ball_color") or ("spl" if self.images is not None or self.pose is not None else "orange")
        self.ball_color: str = convert(ball_color, str, where="--ball-color", choices=("spl", "orange"), error=PlatformOptionError)
        if self.images is not None or self.pose is not None:  # the camera's pose is known: matrices for every detector
            # the robot stands where the images were taken: no odometry, so the localization runs as well
            self.provides = {"cognition": (CameraImageTop, CameraImageBottom, CameraMatrixBuffer, Odometry)}
        self.paused = False
        self.steps = 0
        self.current: PosedImage | None = None
        self.loop = bool(self.options.get("loop"))
        self.fps_override: float | None = convert(self.options.get("fps"), float | None, where="--fps", bounds=Range(0.0, low_open=True),
                                                  unit="frames per second", error=PlatformOptionError)
        fov = self.options.get("fov")
        self.fov_given = fov is not None
        degrees = convert(60.0 if fov is None else fov, float, where="--fov", bounds=Range(0.0, 180.0, low_open=True),
                          expected=FOV, error=PlatformOptionError)
        if degrees >= 180.0:  # a pinhole camera sees less than half the world
            raise refusal("--fov", FOV, fov, PlatformOptionError)
        self.horizontal_fov = math.radians(degrees)
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
        parser.add_argument("--fov", type=float, default=None,
                            help="video: horizontal field of view of the camera (degrees; 60 for videos, the NAO's 56.3 for images)")
        parser.add_argument("--camera", choices=["top", "bottom"],
                            help="video: the camera the images come from (default: what a pose file or the file name says, else top)")
        parser.add_argument("--camera-pose", metavar="HEIGHT,PITCH,ROLL,YAW",
                            help="video: the camera's pose (mm above the ground; rad, pitch down positive) where no pose file "
                                 "or PNG text gives one; also [video] camera_pose in the configuration")
        parser.add_argument("--ball-color", choices=["spl", "orange"],
                            help="video: which ball to look for (default: spl for images and posed cameras, orange otherwise)")

    def config_layers(self) -> list[str]:
        """``video``, then ``video_spl`` (it picks the SPL ball detector) when the SPL ball is looked for."""
        return [self.name, *(["video_spl"] if self.ball_color == "spl" else [])]

    config_sections = ("video",)  # [video] camera_pose

    def configure(self, config: Mapping[str, Any]) -> None:
        """``[video] camera_pose`` from the configuration, where the command line gives none."""
        pose = (config.get("video") or {}).get("camera_pose")
        if pose and not self.options.get("camera_pose"):
            self.options["camera_pose"] = str(pose)
            try:
                self.pose = options_pose(self.options)
            except ImageSourceError as error:
                raise PlatformOptionError(f"[video] camera_pose: {error}") from error

    def check(self) -> None:
        """Fail now, with a clear message, if the source cannot be opened (before processes start)."""
        if self.images is not None:
            try:  # the first image and its pose: a wrong pose file is reported before anything runs
                first = self.posed(0)
            except ImageSourceError as error:
                raise PlatformError(str(error)) from error
            line = f"video: {len(self.images)} image(s) from {self.source}; camera pose of the first: {first.pose_source}"
            # start-up makes the platform more than once, and each context's process again: say it once
            if line not in TOLD and multiprocessing.parent_process() is None:
                TOLD.add(line)
                print(line, file=sys.stderr)
            return
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
        if self.images is not None:
            return IMAGES_FPS
        capture = self.capture or self._open()
        rate = capture.get(cv2.CAP_PROP_FPS)
        if capture is not self.capture:
            capture.release()
        return rate if rate and rate > 0 else 30.0

    def start(self, contexts: frozenset[str]) -> None:
        if "cognition" in contexts:
            if self.images is None:
                self.capture = self._open()
            self.period_ns = int(1e9 / self.frame_rate())
            self.started_ns = time.monotonic_ns()

    def posed(self, index: int) -> PosedImage:
        """Image ``index`` of the folder with its camera's pose."""
        posed = posed_image(self.images[index], self.pose, self.camera)  # type: ignore[index]
        if self.fov_given and not posed.pose_source.startswith("json"):  # --fov for images whose pose file gives none
            height, width = posed.image.shape[:2]
            posed.horizontal_fov = self.horizontal_fov
            posed.vertical_fov = 2 * math.atan(math.tan(self.horizontal_fov / 2) * height / width)
        return posed

    def sense_image(self, blackboard: Blackboard, frame_number: int) -> None:
        """The next image of the folder (the same one while paused) with its camera matrix."""
        assert self.images is not None
        advance = not self.paused or self.steps > 0 or self.current is None
        if advance:
            if self.frame_index >= len(self.images):
                if not self.loop:
                    raise EndOfData(f"end of {self.source} ({len(self.images)} images)")
                self.frame_index = 0
            try:
                posed = self.posed(self.frame_index)
            except ImageSourceError as error:
                raise PlatformError(str(error)) from error
            if self.current is None or posed.pose_source != self.current.pose_source:
                print(f"video: {posed.path.name}: {posed.camera} camera, pose {posed.pose_source}", file=sys.stderr)
            self.current = posed
            self.frame_index += 1
            self.steps = max(0, self.steps - 1)
        due = self.started_ns + (frame_number - 1) * self.period_ns
        delay = due - time.monotonic_ns()
        if delay > 0:
            time.sleep(delay * 1e-9)
        self.time_ns = (frame_number - 1) * self.period_ns
        posed = self.current
        assert posed is not None
        for camera, rep in (("top", CameraImageTop), ("bottom", CameraImageBottom)):
            image = blackboard[rep]
            image.time_ns = self.time_ns
            if camera == posed.camera:
                image.image, image.horizontal_fov, image.vertical_fov = posed.image, posed.horizontal_fov, posed.vertical_fov
            else:  # one camera per image: the other stays empty, and perception skips it
                image.image, image.horizontal_fov, image.vertical_fov = np.zeros((0, 0, 3), np.uint8), 0.0, 0.0
        matrix = posed.matrix
        blackboard.set(CameraMatrixBuffer.of(CameraMatrixTop(matrix.rotation, matrix.translation, True),
                                             CameraMatrixBottom(matrix.rotation, matrix.translation, True), self.time_ns))

    def sense(self, context: str, blackboard: Blackboard, frame_number: int, time_ns: int) -> None:
        if self.images is not None:
            self.sense_image(blackboard, frame_number)
            return
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
        image = blackboard[CameraImageTop]
        image.time_ns = taken_ns
        image.image = cv2.cvtColor(frame, cv2.COLOR_BGR2RGB)
        height, width = image.image.shape[:2]
        image.horizontal_fov = self.horizontal_fov
        image.vertical_fov = 2 * math.atan(math.tan(self.horizontal_fov / 2) * height / width)
        # there is one camera: the bottom image stays empty, and perception skips it
        blackboard[CameraImageBottom].image = np.zeros((0, 0, 3), np.uint8)
        if self.pose is not None:  # a camera whose pose was given: the same matrix every frame
            matrix = self.pose.matrix()
            blackboard.set(CameraMatrixBuffer.of(CameraMatrixTop(matrix.rotation, matrix.translation, True),
                                                 CameraMatrixBottom(matrix.rotation, matrix.translation, True), taken_ns))

    def frame_time_ns(self, context: str) -> int | None:
        return self.time_ns

    def commands(self) -> Mapping[str, tuple[str, Any]]:
        def pause(args: Mapping[str, Any]) -> str:
            self.paused = True
            return "holding the current image (video:step shows the next, video:resume plays on)"

        def step(args: Mapping[str, Any]) -> str:
            self.paused, self.steps = True, self.steps + 1
            return "the next image"

        def resume(args: Mapping[str, Any]) -> str:
            self.paused = False
            return "playing"

        if self.images is None:
            return {}
        return {"video:pause": ("hold the current image (perception runs on it every frame)", pause),
                "video:step": ("show the next image and hold it", step),
                "video:resume": ("play the images on", resume)}

    def stop(self) -> None:
        if self.capture is not None:
            self.capture.release()
            self.capture = None
