"""Representations of the world model: what the robot believes beyond a single frame."""

from __future__ import annotations

import math

from tafel.core import bounded, representation
from tafel.representations.geometry import Pose2D


@representation
class BallModel:
    """The believed ball state in the robot frame.

    ``x``/``y`` in mm, ``vx``/``vy`` in mm/s, ``position_std`` the standard deviation of the position
    (mm). ``valid`` while the ball was seen recently enough to be trusted; ``seen`` when it was seen in
    this frame; ``time_since_seen`` in s.
    """

    valid: bool = False
    seen: bool = False
    x: float = bounded(-15000.0, 15000.0)
    y: float = bounded(-15000.0, 15000.0)
    vx: float = bounded(-20000.0, 20000.0)
    vy: float = bounded(-20000.0, 20000.0)
    position_std: float = bounded(0.0, 1e6)
    time_since_seen: float = bounded(0.0, 1e6)

    def status_text(self) -> str:
        """One phrase for the status line of ``tafel run`` (``[status] show`` in configuration)."""
        if not self.valid:
            return "ball not seen"
        return f"ball {'seen' if self.seen else 'remembered'} at x={self.x:.0f} y={self.y:.0f} mm"

    def field_position(self, pose: RobotPose) -> tuple[float, float]:
        """The ball on the field (mm), through the robot's pose; only as good as that pose."""
        return pose.to_field(self.x, self.y)


@representation
class RobotPose:
    """Where the robot is on the field (field frame of the README): ``x``, ``y`` in mm, ``rotation`` in
    rad (0: facing the opponent goal). ``valid`` once the localization trusts it; ``lost`` while it has
    lost track and relocalizes (``valid`` is then false). ``deviation`` is the position's standard
    deviation (mm), ``rotation_deviation`` the rotation's (rad), ``mirror_probability`` that of the
    mirrored twin."""

    valid: bool = False
    lost: bool = False
    x: float = bounded(-15000.0, 15000.0)
    y: float = bounded(-15000.0, 15000.0)
    rotation: float = bounded(-math.pi, math.pi)
    deviation: float = bounded(0.0, 1e6, 1e6)
    rotation_deviation: float = bounded(0.0, 10.0, math.pi)
    mirror_probability: float = bounded(0.0, 1.0, 0.5)
    """how likely the robot is at this pose's twin (turned by 180 degrees about the centre spot, which
    the field cannot tell apart) rather than here; ``valid`` only while it is low"""

    def as_pose2d(self) -> Pose2D:
        """The robot frame on the field, to compute with (the fields stay what logs hold)."""
        return Pose2D(self.x, self.y, self.rotation)

    def to_field(self, x: float, y: float) -> tuple[float, float]:
        """A point in the robot frame (mm) on the field (mm)."""
        return self.as_pose2d().to_global(x, y)

    def to_robot(self, x: float, y: float) -> tuple[float, float]:
        """A point on the field (mm) in the robot frame (mm)."""
        return self.as_pose2d().to_local(x, y)

    def status_text(self) -> str:
        if not self.valid:
            return "pose lost" if self.lost else "pose unknown"
        return f"pose x={self.x:.0f} y={self.y:.0f} mm {math.degrees(self.rotation):.0f} deg"


@representation
class KnownPose:
    """Where the robot is, told from outside its sensors: the simulator's ground truth after
    ``sim:move_robot ... -reset on``. ``serial`` counts the poses told (0: none yet); the localization
    starts anew at ``x``, ``y`` (mm) and ``rotation`` (rad) whenever it changes. Only simulated
    platforms provide it; elsewhere it stays at serial 0 and changes nothing."""

    serial: int = 0
    x: float = bounded(-15000.0, 15000.0)
    y: float = bounded(-15000.0, 15000.0)
    rotation: float = bounded(-math.pi, math.pi)

    def as_pose2d(self) -> Pose2D:
        return Pose2D(self.x, self.y, self.rotation)
