"""``Pose2D``: a position and a heading on the ground, and the one way Tafel turns points between frames.

A pose is where a frame lies in another (the robot on the field, a step in the odometry, the kick's
frame at the ball): ``x``, ``y`` in mm and ``rotation`` in rad, counter-clockwise from the outer
frame's x axis (the convention of ``representations/__init__.py``). ``to_global`` takes a point from
the pose's own frame into the outer one, ``to_local`` back; ``a * b`` is ``b`` given in ``a``'s frame,
put into ``a``'s outer frame; ``b.relative_to(a)`` is the reverse, ``a.inverse() * b``.

It is a value, not a representation: representations with a pose (``RobotPose``, ``Odometry``) keep
their own fields, so logs stay as they are, and hand out a ``Pose2D`` to compute with.
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from dataclasses import dataclass


def normalize_angle(angle: float) -> float:
    """``angle`` (rad) turned by whole turns into (-pi, pi]."""
    wrapped = math.remainder(angle, math.tau)  # exact, within [-pi, pi]
    return math.pi if wrapped == -math.pi else wrapped


@dataclass(frozen=True)
class Pose2D:
    """A frame on the ground within an outer frame: its origin (mm) and heading (rad, kept in (-pi, pi])."""

    x: float = 0.0
    y: float = 0.0
    rotation: float = 0.0

    def __post_init__(self) -> None:
        object.__setattr__(self, "x", float(self.x))
        object.__setattr__(self, "y", float(self.y))
        object.__setattr__(self, "rotation", normalize_angle(float(self.rotation)))

    def __iter__(self) -> Iterator[float]:
        """``x, y, rotation = pose``, and ``np.array(tuple(pose))``."""
        return iter((self.x, self.y, self.rotation))

    def rotated(self, x: float, y: float) -> tuple[float, float]:
        """A vector of this frame (a velocity, a step) in the outer frame: turned, not moved."""
        c, s = math.cos(self.rotation), math.sin(self.rotation)
        return c * x - s * y, s * x + c * y

    def to_global(self, x: float, y: float) -> tuple[float, float]:
        """A point of this frame (mm) in the outer frame (mm)."""
        c, s = math.cos(self.rotation), math.sin(self.rotation)
        return self.x + c * x - s * y, self.y + s * x + c * y

    def to_local(self, x: float, y: float) -> tuple[float, float]:
        """A point of the outer frame (mm) in this frame (mm)."""
        dx, dy = x - self.x, y - self.y
        c, s = math.cos(self.rotation), math.sin(self.rotation)
        return c * dx + s * dy, -s * dx + c * dy

    def __mul__(self, other: Pose2D) -> Pose2D:
        """``other`` (a pose in this frame) in the outer frame: this pose, then ``other`` from there."""
        if not isinstance(other, Pose2D):
            return NotImplemented
        return Pose2D(*self.to_global(other.x, other.y), self.rotation + other.rotation)

    compose = __mul__

    def inverse(self) -> Pose2D:
        """The outer frame seen from this one: ``pose * pose.inverse()`` is the identity."""
        return Pose2D(*self.to_local(0.0, 0.0), -self.rotation)

    def relative_to(self, origin: Pose2D) -> Pose2D:
        """This pose seen from ``origin`` (both in the same outer frame): ``origin.inverse() * self``.
        Of two odometry readings, ``now.relative_to(before)`` is the step between them (forward, left, turn)."""
        return Pose2D(*origin.to_local(self.x, self.y), self.rotation - origin.rotation)
