"""Representations that behaviour decides and motion carries out."""

from __future__ import annotations

import math

from tafel.core import bounded, representation

HOLD_SPEED = 0.0  # rad/s: a request at this speed keeps the head where it is (a penalized robot moves nothing)


@representation
class HeadMotionRequest:
    """Where the head should look: joint angles ``yaw``/``pitch`` (rad) reached with at most
    ``max_speed`` (rad/s); ``max_speed`` 0 (``HOLD_SPEED``) holds the head where it is."""

    yaw: float = bounded(-math.pi, math.pi)
    pitch: float = bounded(-math.pi / 2, math.pi / 2)
    max_speed: float = bounded(0.0, 20.0, 2.0)
