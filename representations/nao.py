"""The NAO V6 in numbers: the one robot description that kinematics and every simulator use.

Figures from the published reference (``shared/reference/nao-v6.md``). Everything is in the robot's
torso frame with all joints at zero: x forward, y left, z up; lengths in mm, angles in rad, masses in kg.
Each joint rotates its child link about ``axis`` (right-hand rule); ``offset`` is the joint's position
in its parent link's frame. The legs' HipYawPitch joints are tilted 45 degrees and share one motor:
``RHipYawPitch`` exists in the simulated model but always follows ``LHipYawPitch``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from tafel.representations.motion import JOINT_NAMES

# ------------------------------------------------------------------------------ link offsets (mm)
NECK_OFFSET_Z = 126.5
SHOULDER_OFFSET_Y, SHOULDER_OFFSET_Z = 98.0, 100.0
ELBOW_OFFSET_Y = 15.0
UPPER_ARM_LENGTH = 105.0
LOWER_ARM_LENGTH = 55.95
HAND_OFFSET_X, HAND_OFFSET_Z = 57.75, 12.31
HIP_OFFSET_Z, HIP_OFFSET_Y = 85.0, 50.0
THIGH_LENGTH = 100.0
TIBIA_LENGTH = 102.9
FOOT_HEIGHT = 45.19

#: sole outline relative to the ankle (mm): forward, back, inside, outside
SOLE_FRONT, SOLE_BACK, SOLE_INSIDE, SOLE_OUTSIDE = 100.0, 50.0, 38.77, 50.02
#: the IMU in the torso frame (mm), as B-Human's NaoV6H25 scene has it (their 112 mm is from the hip)
ACCELEROMETER_POSITION = (-8.0, 6.06, 27.0)
GYROSCOPE_POSITION = (-8.0, 6.0, 29.0)


@dataclass(frozen=True)
class CameraMount:
    """A camera fixed to the head: position relative to the HeadPitch joint (mm), downward tilt (rad)."""

    name: str
    position: tuple[float, float, float]
    tilt: float


TOP_CAMERA = CameraMount("top", (58.71, 0.0, 63.64), math.radians(1.2))
BOTTOM_CAMERA = CameraMount("bottom", (50.71, 0.0, 17.74), math.radians(39.7))
CAMERAS = (TOP_CAMERA, BOTTOM_CAMERA)
#: vendor field of view (rad) for a 4:3 image
HORIZONTAL_FOV = math.radians(56.3)
VERTICAL_FOV = math.radians(43.7)


@dataclass(frozen=True)
class Joint:
    """One joint: it moves ``link`` (a child of ``parent``) about ``axis`` at ``offset`` in the parent."""

    name: str
    parent: str
    link: str
    offset: tuple[float, float, float]
    axis: tuple[float, float, float]
    limits: tuple[float, float]  # rad
    mass: float  # kg of the link it moves


_S = math.sqrt(0.5)


def _deg(low: float, high: float) -> tuple[float, float]:
    return math.radians(low), math.radians(high)


def _arm(side: str) -> list[Joint]:
    s = 1.0 if side == "L" else -1.0
    roll = _deg(-18, 76) if side == "L" else _deg(-76, 18)
    elbow_roll = _deg(-88.5, -2) if side == "L" else _deg(2, 88.5)
    return [
        Joint(f"{side}ShoulderPitch", "torso", f"{side}Shoulder", (0.0, s * SHOULDER_OFFSET_Y, SHOULDER_OFFSET_Z), (0, 1, 0), _deg(-119.5, 119.5), 0.09304),
        Joint(f"{side}ShoulderRoll", f"{side}Shoulder", f"{side}Biceps", (0.0, 0.0, 0.0), (0, 0, 1), roll, 0.15777),
        Joint(f"{side}ElbowYaw", f"{side}Biceps", f"{side}Elbow", (UPPER_ARM_LENGTH, s * ELBOW_OFFSET_Y, 0.0), (1, 0, 0), _deg(-119.5, 119.5), 0.06483),
        Joint(f"{side}ElbowRoll", f"{side}Elbow", f"{side}ForeArm", (0.0, 0.0, 0.0), (0, 0, 1), elbow_roll, 0.07761),
        Joint(f"{side}WristYaw", f"{side}ForeArm", f"{side}Wrist", (LOWER_ARM_LENGTH, 0.0, 0.0), (1, 0, 0), _deg(-104.5, 104.5), 0.17533),
        Joint(f"{side}Hand", f"{side}Wrist", f"{side}Fingers", (HAND_OFFSET_X, 0.0, -HAND_OFFSET_Z), (1, 0, 0), (0.0, 1.0), 0.01),
    ]


def _leg(side: str) -> list[Joint]:
    s = 1.0 if side == "L" else -1.0
    if side == "L":
        hip_roll, knee, ankle_pitch, ankle_roll = _deg(-21.74, 45.29), _deg(-5.29, 121.04), _deg(-68.15, 52.86), _deg(-22.79, 44.06)
    else:
        hip_roll, knee, ankle_pitch, ankle_roll = _deg(-45.29, 21.74), _deg(-5.90, 121.47), _deg(-67.97, 53.40), _deg(-44.06, 22.80)
    return [
        Joint(f"{side}HipYawPitch", "torso", f"{side}Pelvis", (0.0, s * HIP_OFFSET_Y, -HIP_OFFSET_Z), (0, _S, -s * _S), _deg(-65.62, 42.44), 0.06981),
        Joint(f"{side}HipRoll", f"{side}Pelvis", f"{side}Hip", (0.0, 0.0, 0.0), (1, 0, 0), hip_roll, 0.14053),
        Joint(f"{side}HipPitch", f"{side}Hip", f"{side}Thigh", (0.0, 0.0, 0.0), (0, 1, 0), _deg(-88, 27.73), 0.38968),
        Joint(f"{side}KneePitch", f"{side}Thigh", f"{side}Tibia", (0.0, 0.0, -THIGH_LENGTH), (0, 1, 0), knee, 0.30142),
        Joint(f"{side}AnklePitch", f"{side}Tibia", f"{side}Ankle", (0.0, 0.0, -TIBIA_LENGTH), (0, 1, 0), ankle_pitch, 0.13416),
        Joint(f"{side}AnkleRoll", f"{side}Ankle", f"{side}Foot", (0.0, 0.0, 0.0), (1, 0, 0), ankle_roll, 0.17184),
    ]


HEAD_JOINTS = [
    Joint("HeadYaw", "torso", "Neck", (0.0, 0.0, NECK_OFFSET_Z), (0, 0, 1), _deg(-119.5, 119.5), 0.07842),
    Joint("HeadPitch", "Neck", "Head", (0.0, 0.0, 0.0), (0, 1, 0), _deg(-38.5, 29.5), 0.65937),
]
#: every joint of the simulated model, parents before children
JOINTS: tuple[Joint, ...] = tuple(HEAD_JOINTS + _arm("L") + _arm("R") + _leg("L") + _leg("R"))
JOINTS_BY_NAME = {joint.name: joint for joint in JOINTS}
TORSO_MASS = 1.0496
#: the joint the real robot has no motor for: it follows LHipYawPitch
COUPLED_JOINTS = {"RHipYawPitch": "LHipYawPitch"}

assert set(JOINT_NAMES) <= set(JOINTS_BY_NAME), "every LoLA joint must be in the model"
assert set(JOINTS_BY_NAME) - set(JOINT_NAMES) == set(COUPLED_JOINTS)


def total_mass() -> float:
    return TORSO_MASS + sum(joint.mass for joint in JOINTS)
