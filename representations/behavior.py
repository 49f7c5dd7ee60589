"""Representations that behaviour decides and motion carries out."""

from __future__ import annotations

import math

from tafel.core import bounded, representation


@representation
class HeadMotionRequest:
    """Where the head should look: joint angles ``yaw``/``pitch`` (rad) reached with at most
    ``max_speed`` (rad/s)."""

    yaw: float = bounded(-math.pi, math.pi)
    pitch: float = bounded(-math.pi / 2, math.pi / 2)
    max_speed: float = bounded(0.0, 20.0, 2.0)
