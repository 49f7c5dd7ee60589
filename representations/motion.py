"""Representations of the motion context: joint and inertial sensors, joint targets and commands.

Every 25-element joint array is in ``JOINT_NAMES`` order (the order of the NAO's LoLA interface).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from tafel.core import array, representation

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

    position: np.ndarray = array((JOINT_COUNT,))
    stiffness: np.ndarray = array((JOINT_COUNT,))
    current: np.ndarray = array((JOINT_COUNT,))
    temperature: np.ndarray = array((JOINT_COUNT,))


@representation
class InertialSensorData:
    """The IMU in the robot frame: ``accelerometer`` (m/s^2, about +9.81 on z when upright),
    ``gyroscope`` (rad/s about x, y, z), ``angles`` (torso roll and pitch, rad)."""

    accelerometer: np.ndarray = array((3,))
    gyroscope: np.ndarray = array((3,))
    angles: np.ndarray = array((2,))


@representation
class FsrData:
    """Foot pressure (kg): left foot front-left, front-right, rear-left, rear-right, then the right foot."""

    pressure: np.ndarray = array((8,))


@representation
class HeadJointTargets:
    """Where the head motion wants the head joints now (rad), and the stiffness to hold them (0..1)."""

    yaw: float = 0.0
    pitch: float = 0.0
    stiffness: float = 0.0


@representation
class BodyJointTargets:
    """Targets of all joints but the head from the body motion (rad, ``JOINT_NAMES`` order; the head
    entries are ignored), with stiffness per joint (0..1)."""

    position: np.ndarray = array((JOINT_COUNT,))
    stiffness: np.ndarray = array((JOINT_COUNT,))


@representation
class JointCommand:
    """What the actuators get this motion frame: ``position`` (rad) and ``stiffness`` (0..1) per joint."""

    position: np.ndarray = array((JOINT_COUNT,))
    stiffness: np.ndarray = array((JOINT_COUNT,))


@representation
class InertialModel:
    """The filtered torso orientation: ``roll`` and ``pitch`` (rad) of the torso relative to the
    ground, ``gyroscope`` (rad/s) and ``accelerometer`` (m/s^2) low-pass filtered."""

    roll: float = 0.0
    pitch: float = 0.0
    gyroscope: np.ndarray = array((3,))
    accelerometer: np.ndarray = array((3,))


@dataclass
class CameraMatrix:
    """Where a camera is in the robot frame: ``rotation`` (3x3) and ``translation`` (mm) of the camera
    frame, whose x axis is the optical axis, y points left and z up in the image. ``valid`` once
    computed from measured joints."""

    rotation: np.ndarray = field(default_factory=lambda: np.eye(3))
    translation: np.ndarray = array((3,))
    valid: bool = False


@representation
class CameraMatrixTop(CameraMatrix):
    """The top camera's pose in the robot frame."""


@representation
class CameraMatrixBottom(CameraMatrix):
    """The bottom camera's pose in the robot frame."""


@representation
class TorsoPose:
    """The torso's pose in the robot frame: ``rotation`` (3x3) and ``translation`` (mm); the
    translation's z is the torso's height above the ground."""

    rotation: np.ndarray = field(default_factory=lambda: np.eye(3))
    translation: np.ndarray = array((3,))


@representation
class TouchSensorData:
    """Touch sensors and bumpers (1 pressed, 0 not): chest button, head front/middle/rear, left foot
    bumper left/right, left hand back/left/right, right foot bumper left/right, right hand back/left/right."""

    pressed: np.ndarray = array((14,))


@representation
class BatteryData:
    """``charge`` 0..1, ``current`` (A, negative while discharging), ``temperature`` (deg C), and the
    raw ``status`` flags of the battery board."""

    charge: float = 1.0
    status: float = 0.0
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
