"""Representations that behaviour decides and motion carries out."""

from __future__ import annotations

from tafel.core import representation


@representation
class HeadMotionRequest:
    """Where the head should look: joint angles ``yaw``/``pitch`` (rad) reached with at most
    ``max_speed`` (rad/s)."""

    yaw: float = 0.0
    pitch: float = 0.0
    max_speed: float = 2.0
