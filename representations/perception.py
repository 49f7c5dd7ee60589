"""Representations computed by perception from sensor data."""

from __future__ import annotations

import enum
from dataclasses import dataclass

import numpy as np

from tafel.core import array, bounded, representation

#: rad: the widest field of view a pinhole camera can have, short of 180 degrees; 0 means not known (no image)
MAX_FOV = 3.0


@representation
class BallPercept:
    """The ball as seen in this frame's images.

    ``x``/``y`` is the ball's position on the ground in the robot frame (mm); ``image_x``/``image_y``
    its centre and ``radius`` its radius in the image (px) of ``camera`` ("top" or "bottom").
    """

    seen: bool = False
    x: float = bounded(-15000.0, 15000.0)
    y: float = bounded(-15000.0, 15000.0)
    image_x: float = 0.0
    image_y: float = 0.0
    radius: float = 0.0
    camera: str = ""


@dataclass
class CameraImage:
    """An RGB image (height x width x 3, uint8; top-left origin) of one camera, with its field of
    view (rad; 0: not known, and the image is not projected onto the ground). Both cameras have their
    own representation, so modules declare which they read."""

    image: np.ndarray = array((240, 320, 3), np.uint8)
    horizontal_fov: float = bounded(0.0, MAX_FOV)
    vertical_fov: float = bounded(0.0, MAX_FOV)
    #: when the image was taken, on the program's clock (ns); later than that it reaches cognition
    time_ns: int = 0


@representation
class CameraImageTop(CameraImage):
    """The top camera's image (upright: the NAO platform already rotated it)."""


@representation
class CameraImageBottom(CameraImage):
    """The bottom camera's image."""


@dataclass
class BallCandidate:
    """A round orange blob in one image: centre and radius (px), and the share of its enclosing circle
    that is orange; with the image's size (px), field of view (rad) and time to turn it into a ray."""

    camera: str = ""
    x: float = 0.0
    y: float = 0.0
    radius: float = 0.0
    fill: float = 0.0
    image_width: int = 0
    image_height: int = 0
    horizontal_fov: float = bounded(0.0, MAX_FOV)
    vertical_fov: float = bounded(0.0, MAX_FOV)
    #: when the image was taken (ns, program clock): the camera matrix of that instant places it
    time_ns: int = 0


@representation
class BallImagePercept:
    """Ball candidates found in this frame's images, largest first (image positions only)."""

    candidates: list[BallCandidate]


@representation
class FieldColor:
    """The field's green, estimated from the images each frame (OpenCV HSV: hue 0..180, saturation and
    value 0..255), so that a change of light moves it rather than breaking every detector.
    ``FieldColorProvider`` segments the images by it (``green_mask`` in its file)."""

    valid: bool = False
    hue: float = 60.0
    hue_tolerance: float = 12.0
    saturation_min: float = 60.0
    value_min: float = 40.0


class Camera(str, enum.Enum):
    """The NAO's two cameras. A ``str`` enum, so ``"top"`` works where ``Camera.top`` does; any other name
    is an error (``"Top"`` once silently meant the bottom camera)."""

    top = "top"
    bottom = "bottom"

    @classmethod
    def of(cls, name: Camera | str) -> Camera:
        try:
            return cls(name)
        except ValueError:
            raise ValueError(f"no camera {name!r}: the cameras are 'top' and 'bottom'") from None


@representation
class SegmentedImage:
    """Both images in HSV with their field-green masks, and the value (V, 0..255) of white in each (the
    brightest unsaturated pixels off the field), computed once per frame for every detector."""

    top_hsv: np.ndarray = array((None, None, 3), np.uint8)
    top_green: np.ndarray = array((None, None), np.bool_)
    top_white: float = 255.0
    bottom_hsv: np.ndarray = array((None, None, 3), np.uint8)
    bottom_green: np.ndarray = array((None, None), np.bool_)
    bottom_white: float = 255.0

    def white(self, camera: Camera | str) -> float:
        return self.top_white if Camera.of(camera) is Camera.top else self.bottom_white

    # plain arrays: numpy on a module's read-only view of them would pass through the access checks
    def hsv(self, camera: Camera | str) -> np.ndarray:
        return np.asarray(self.top_hsv if Camera.of(camera) is Camera.top else self.bottom_hsv)

    def green(self, camera: Camera | str) -> np.ndarray:
        return np.asarray(self.top_green if Camera.of(camera) is Camera.top else self.bottom_green)


@representation
class FieldBoundary:
    """Where the field ends in each image: for every pixel column the row (px) of the field's upper
    edge; the field is below it. A row of 0 means field up to the top, the image height no field."""

    top: np.ndarray = array((None,), np.float32)
    bottom: np.ndarray = array((None,), np.float32)

    def rows(self, camera: Camera | str) -> np.ndarray:
        return np.asarray(self.top if Camera.of(camera) is Camera.top else self.bottom)

    def inside(self, camera: Camera | str, x: float, y: float) -> bool:
        """Whether the pixel (x, y) lies on the field (below the boundary)."""
        rows = self.rows(camera)
        if rows.size == 0:
            return False
        return y >= float(rows[int(min(max(x, 0), rows.size - 1))])


@dataclass
class LineSegment:
    """A field line seen on the ground, as its centre line from (x1, y1) to (x2, y2) (mm, robot frame)."""

    x1: float = 0.0
    y1: float = 0.0
    x2: float = 0.0
    y2: float = 0.0

    @property
    def length(self) -> float:
        return float(np.hypot(self.x2 - self.x1, self.y2 - self.y1))


@representation
class LinePercept:
    """Field lines seen in this frame (robot frame, mm): straight segments, and the centre circle's
    centre if enough of it was seen. ``points`` are the line points found (N x 2, mm), what the
    localization weighs."""

    segments: list[LineSegment]
    circle_seen: bool = False
    circle_x: float = 0.0
    circle_y: float = 0.0
    points: np.ndarray = array((None, 2), np.float32)


@dataclass
class GoalPost:
    """One goal post's foot on the ground (mm, robot frame), with where it was found in the image (px):
    its centre column, its width and the row of its foot."""

    x: float = 0.0
    y: float = 0.0
    camera: str = ""
    image_x: float = 0.0
    image_width: float = 0.0
    image_foot: float = 0.0


@representation
class GoalPostPercept:
    """Goal posts seen in this frame, nearest first."""

    posts: list[GoalPost]
