"""Representations computed by perception from sensor data."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from tafel.core import array, bounded, representation


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
    view (rad). Both cameras have their own representation, so modules declare which they read."""

    image: np.ndarray = array((240, 320, 3), np.uint8)
    horizontal_fov: float = 0.0
    vertical_fov: float = 0.0
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
    horizontal_fov: float = 0.0
    vertical_fov: float = 0.0
    #: when the image was taken (ns, program clock): the camera matrix of that instant places it
    time_ns: int = 0


@representation
class BallImagePercept:
    """Ball candidates found in this frame's images, largest first (image positions only)."""

    candidates: list[BallCandidate]
