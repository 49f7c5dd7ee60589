"""Representations of the motion context: joint and inertial sensors, joint targets and commands.

Every 25-element joint array is in ``JOINT_NAMES`` order (the order of the NAO's LoLA interface).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from tafel.core import array, bounded, representation
from tafel.core.framework.representation import counter

#: what the elements of a rotation matrix take: -1 to 1, with room for rounding (1 + 2e-16 after a product)
ROTATION_ELEMENT = (-1.0 - 1e-9, 1.0 + 1e-9)

JOINT_NAMES: tuple[str, ...] = (
    "HeadYaw", "HeadPitch",
    "LShoulderPitch", "LShoulderRoll", "LElbowYaw", "LElbowRoll", "LWristYaw",
    "LHipYawPitch", "LHipRoll", "LHipPitch", "LKneePitch", "LAnklePitch", "LAnkleRoll",
    "RHipRoll", "RHipPitch", "RKneePitch", "RAnklePitch", "RAnkleRoll",
    "RShoulderPitch", "RShoulderRoll", "RElbowYaw", "RElbowRoll", "RWristYaw",
    "LHand", "RHand",
)
JOINT_COUNT = len(JOINT_NAMES)
JOINT_INDEX: dict[str, int] = {name: i for i, name in enumerate(JOINT_NAMES)}
HEAD_YAW, HEAD_PITCH = JOINT_INDEX["HeadYaw"], JOINT_INDEX["HeadPitch"]


@representation
class JointSensorData:
    """Measured joint state: ``position`` (rad; hands 0..1 open), ``stiffness`` (0..1), ``current`` (A),
    ``temperature`` (deg C), in ``JOINT_NAMES`` order."""

    position: np.ndarray = bounded(-math.pi, math.pi, array_shape=(JOINT_COUNT,))
    stiffness: np.ndarray = bounded(0.0, 1.0, array_shape=(JOINT_COUNT,))
    current: np.ndarray = bounded(0.0, 10.0, array_shape=(JOINT_COUNT,))
    temperature: np.ndarray = bounded(-20.0, 150.0, array_shape=(JOINT_COUNT,))


@representation
class InertialSensorData:
    """The IMU in the robot frame: ``accelerometer`` (m/s^2, about +9.81 on z when upright),
    ``gyroscope`` (rad/s about x, y, z), ``angles`` (torso roll and pitch, rad)."""

    accelerometer: np.ndarray = bounded(-160.0, 160.0, array_shape=(3,))
    gyroscope: np.ndarray = bounded(-35.0, 35.0, array_shape=(3,))
    angles: np.ndarray = bounded(-math.pi, math.pi, array_shape=(2,))


@representation
class FsrData:
    """Foot pressure (kg): left foot front-left, front-right, rear-left, rear-right, then the right foot."""

    pressure: np.ndarray = bounded(0.0, 25.0, array_shape=(8,))


@representation
class HeadJointTargets:
    """Where the head motion wants the head joints now (rad), and the stiffness to hold them (0..1)."""

    yaw: float = 0.0
    pitch: float = 0.0
    stiffness: float = bounded(0.0, 1.0)


@representation
class BodyJointTargets:
    """Targets of all joints but the head from the body motion (rad, ``JOINT_NAMES`` order; the head
    entries are ignored), with stiffness per joint (0..1)."""

    position: np.ndarray = array((JOINT_COUNT,))
    stiffness: np.ndarray = bounded(0.0, 1.0, array_shape=(JOINT_COUNT,))


@representation
class JointCommand:
    """What the actuators get this motion frame: ``position`` (rad) and ``stiffness`` (0..1) per joint."""

    position: np.ndarray = array((JOINT_COUNT,))
    stiffness: np.ndarray = bounded(0.0, 1.0, array_shape=(JOINT_COUNT,))


@representation
class InertialModel:
    """The filtered torso orientation: ``roll`` and ``pitch`` (rad) of the torso relative to the
    ground, ``gyroscope`` (rad/s) and ``accelerometer`` (m/s^2) low-pass filtered."""

    roll: float = bounded(-math.pi, math.pi)
    pitch: float = bounded(-math.pi, math.pi)
    gyroscope: np.ndarray = array((3,))
    accelerometer: np.ndarray = array((3,))


@dataclass
class CameraMatrix:
    """Where a camera is in the robot frame: ``rotation`` (3x3) and ``translation`` (mm) of the camera
    frame, whose x axis is the optical axis, y points left and z up in the image. ``valid`` once
    computed from measured joints."""

    rotation: np.ndarray = field(default_factory=lambda: np.eye(3), metadata={"range": ROTATION_ELEMENT})
    translation: np.ndarray = array((3,))
    valid: bool = False


@representation
class CameraMatrixTop(CameraMatrix):
    """The top camera's pose in the robot frame."""


@representation
class CameraMatrixBottom(CameraMatrix):
    """The bottom camera's pose in the robot frame."""


#: camera matrices the buffer holds: 400 ms at 100 Hz (NaoTH's CameraMatrixBuffer holds about 300 ms)
CAMERA_MATRIX_HISTORY = 40


@representation
class CameraMatrixBuffer:
    """The camera matrices of the last motion frames with their times, oldest first, so that cognition
    can use the pose a camera had when an image was taken (images arrive 30 to 40 ms after that on
    the NAO). ``count`` entries are filled; ``time_ns`` is on the program's clock, like ``FrameInfo``.
    """

    count: int = bounded(0, CAMERA_MATRIX_HISTORY, 0)
    time_ns: np.ndarray = array((CAMERA_MATRIX_HISTORY,), np.int64)
    top_rotation: np.ndarray = bounded(*ROTATION_ELEMENT, array_shape=(CAMERA_MATRIX_HISTORY, 3, 3))
    top_translation: np.ndarray = array((CAMERA_MATRIX_HISTORY, 3))
    bottom_rotation: np.ndarray = bounded(*ROTATION_ELEMENT, array_shape=(CAMERA_MATRIX_HISTORY, 3, 3))
    bottom_translation: np.ndarray = array((CAMERA_MATRIX_HISTORY, 3))

    @classmethod
    def of(cls, top: CameraMatrix, bottom: CameraMatrix, time_ns: int = 0) -> CameraMatrixBuffer:
        """A buffer holding one pair of matrices (tests, and programs without a history)."""
        buffer = cls(count=1)
        buffer.time_ns[0] = time_ns
        buffer.top_rotation[0], buffer.top_translation[0] = top.rotation, top.translation
        buffer.bottom_rotation[0], buffer.bottom_translation[0] = bottom.rotation, bottom.translation
        return buffer

    def newest(self, camera: str) -> CameraMatrix:
        """The latest matrix of ``camera`` ("top" or "bottom"); invalid while the buffer is empty."""
        if self.count == 0:
            return CameraMatrix()
        rotation, translation = self._arrays(camera)
        return CameraMatrix(rotation[self.count - 1].copy(), translation[self.count - 1].copy(), True)

    def at(self, camera: str, time_ns: int) -> CameraMatrix:
        """The matrix of ``camera`` at ``time_ns``, interpolated between the two nearest entries.

        Rotation is interpolated on the shortest arc between the two, translation linearly. Before
        the oldest or after the newest entry the nearest one is used. Invalid while empty.
        """
        n = self.count
        if n == 0:
            return CameraMatrix()
        rotation, translation = self._arrays(camera)
        times = self.time_ns[:n]
        after = int(np.searchsorted(times, time_ns, side="left"))
        if after == 0 or after >= n:
            index = 0 if after == 0 else n - 1
            return CameraMatrix(rotation[index].copy(), translation[index].copy(), True)
        before = after - 1
        span = float(times[after] - times[before])
        share = (time_ns - float(times[before])) / span if span > 0 else 1.0
        relative = rotation[before].T @ rotation[after]
        blended = rotation[before] @ _rotation_power(relative, share)
        return CameraMatrix(blended, translation[before] + share * (translation[after] - translation[before]), True)

    def _arrays(self, camera: str) -> tuple[np.ndarray, np.ndarray]:
        if camera == "top":
            return self.top_rotation, self.top_translation
        if camera == "bottom":
            return self.bottom_rotation, self.bottom_translation
        raise ValueError(f"camera is 'top' or 'bottom', not {camera!r}")


def _rotation_power(rotation: np.ndarray, share: float) -> np.ndarray:
    """``rotation`` raised to ``share`` (0: identity, 1: itself), through its axis and angle."""
    cosine = max(-1.0, min(1.0, (float(np.trace(rotation)) - 1.0) / 2.0))
    angle = float(np.arccos(cosine))
    if angle < 1e-9:
        return np.eye(3)
    axis = np.array([rotation[2, 1] - rotation[1, 2], rotation[0, 2] - rotation[2, 0], rotation[1, 0] - rotation[0, 1]])
    axis /= 2.0 * np.sin(angle)
    x, y, z = axis
    k = np.array([[0.0, -z, y], [z, 0.0, -x], [-y, x, 0.0]])
    theta = share * angle
    return np.eye(3) + np.sin(theta) * k + (1.0 - np.cos(theta)) * (k @ k)


@representation
class TorsoPose:
    """The torso's pose in the robot frame: ``rotation`` (3x3) and ``translation`` (mm); the
    translation's z is the torso's height above the ground."""

    rotation: np.ndarray = field(default_factory=lambda: np.eye(3), metadata={"range": ROTATION_ELEMENT})
    translation: np.ndarray = array((3,))


CHEST_BUTTON = 0  # index of the chest button in TouchSensorData.pressed


@representation
class TouchSensorData:
    """Touch sensors and bumpers (1 pressed, 0 not): chest button, head front/middle/rear, left foot
    bumper left/right, left hand back/left/right, right foot bumper left/right, right hand back/left/right."""

    pressed: np.ndarray = array((14,))


@representation
class ChestButton:
    """The chest button, debounced: ``pressed`` now, and ``presses`` counted since the start (a press
    ends when the button is let go), so that a reader at any rate misses none."""

    pressed: bool = False
    presses: int = counter()


@representation
class BatteryData:
    """The battery as LoLA reports it (its ``Battery`` array: charge, status, current, temperature, the
    order B-Human, HULKs and NaoTH read; Softbank's documentation lists another, which is wrong).

    ``charge`` 0..1; ``status`` the battery board's raw flags (a 16-bit signed value, for example
    -32552 = 0x80D8 while charging); ``charging`` its bit 0x80, as B-Human reads it; ``current`` (A,
    negative while discharging); ``temperature`` LoLA's raw battery temperature reading: about 3 on real
    robots whatever the battery does (NaoTH notes the same), so it is no temperature in deg C."""

    charge: float = 1.0
    status: int = 0
    charging: bool = False
    current: float = 0.0
    temperature: float = 0.0


@representation
class LedRequest:
    """LED colours and brightness, 0..1: ``chest``, ``left_foot``, ``right_foot`` (R, G, B);
    ``left_eye``, ``right_eye`` (8 red, 8 green, 8 blue); ``left_ear``, ``right_ear`` (10 segments);
    ``skull`` (12)."""

    chest: np.ndarray = array((3,))
    left_foot: np.ndarray = array((3,))
    right_foot: np.ndarray = array((3,))
    left_eye: np.ndarray = array((24,))
    right_eye: np.ndarray = array((24,))
    left_ear: np.ndarray = array((10,))
    right_ear: np.ndarray = array((10,))
    skull: np.ndarray = array((12,))
