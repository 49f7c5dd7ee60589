"""Representations computed by perception from sensor data."""

from __future__ import annotations

from core import representation


@representation
class BallPercept:
    """The ball as seen in this frame's images.

    ``x``/``y`` is the ball's position on the ground in the robot frame (mm); ``image_x``/``image_y``
    its centre and ``radius`` its radius in the image (px) of ``camera`` ("top" or "bottom").
    """

    seen: bool = False
    x: float = 0.0
    y: float = 0.0
    image_x: float = 0.0
    image_y: float = 0.0
    radius: float = 0.0
    camera: str = ""
