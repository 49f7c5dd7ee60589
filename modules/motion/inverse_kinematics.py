"""Analytic inverse kinematics of the NAO's legs (functions, not a module).

Each leg is HipYawPitch (an axis tilted 45 degrees, shared by both legs), HipRoll, HipPitch, KneePitch,
AnklePitch, AnkleRoll. Turning the hip frame by 45 degrees about x makes the HipYawPitch axis the z
axis (-z on the left, +z on the right), and the leg becomes a yaw-roll-pitch hip, a knee and a pitch-roll ankle, which has a closed-form
solution (as in B-Human's and NaoTH's kinematics): the knee from the hip-ankle distance, the ankle
from where the hip lies seen from the foot, and the hip from what rotation remains.

Both legs share one HipYawPitch motor: ``leg_angles`` solves each leg alone, takes the mean of the two
HipYawPitch angles, and solves both legs again with it fixed, so positions are reached exactly and
only the feet's yaw may differ from the request where the requests disagree.

Poses are 4x4 transforms of the sole point below the ankle (mm) in the torso frame. An unreachable
target gets the closest reachable pose (the leg stretched towards it) within the joint limits, never NaN.
"""

from __future__ import annotations

import math

import numpy as np

from tafel.representations.motion import JOINT_INDEX
from tafel.representations.nao import FOOT_HEIGHT, HIP_OFFSET_Y, HIP_OFFSET_Z, JOINTS_BY_NAME, THIGH_LENGTH, TIBIA_LENGTH

LEG_JOINTS = ("HipYawPitch", "HipRoll", "HipPitch", "KneePitch", "AnklePitch", "AnkleRoll")
_QUARTER = math.pi / 4


def rot_x(angle: float) -> np.ndarray:
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])


def rot_y(angle: float) -> np.ndarray:
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def rot_z(angle: float) -> np.ndarray:
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def pose(x: float, y: float, z: float, roll: float = 0.0, pitch: float = 0.0, yaw: float = 0.0) -> np.ndarray:
    """A 4x4 transform from a position (mm) and roll, pitch, yaw (rad, applied as Rz Ry Rx)."""
    result = np.eye(4)
    result[:3, :3] = rot_z(yaw) @ rot_y(pitch) @ rot_x(roll)
    result[:3, 3] = (x, y, z)
    return result


def _limit(side: str, joint: str, angle: float) -> float:
    name = f"{side}{joint}" if f"{side}{joint}" in JOINTS_BY_NAME else f"L{joint}"
    low, high = JOINTS_BY_NAME[name].limits
    return min(max(angle, low), high)


def _sign(side: str) -> float:
    return 1.0 if side == "L" else -1.0


def _rotated_ankle(side: str, sole: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(rotation, position) of the ankle relative to the hip, in the hip frame turned so that the
    HipYawPitch axis is -z (left leg) or +z (right leg)."""
    s = _sign(side)
    rotation = sole[:3, :3]
    ankle = sole[:3, 3] + rotation @ np.array([0.0, 0.0, FOOT_HEIGHT])
    relative = ankle - np.array([0.0, s * HIP_OFFSET_Y, -HIP_OFFSET_Z])
    turn = rot_x(-s * _QUARTER)
    return turn @ rotation, turn @ relative


def _wrap(angle: float) -> float:
    """The angle in (-pi, pi]: a difference of two atan2 may come out a full turn off."""
    return math.remainder(angle, math.tau)


def _knee(distance: float) -> float:
    """Knee flexion (rad, >= 0) for a hip-ankle distance; stretched as far as the leg goes."""
    l1, l2 = THIGH_LENGTH, TIBIA_LENGTH
    cosine = (distance * distance - l1 * l1 - l2 * l2) / (2 * l1 * l2)
    return math.acos(min(1.0, max(-1.0, cosine)))


def _solve(side: str, sole: np.ndarray, yaw_pitch: float | None) -> list[float]:
    """The six angles of one leg; with ``yaw_pitch`` given, HipYawPitch is fixed to it."""
    s = _sign(side)
    rotation, position = _rotated_ankle(side, sole)
    l1, l2 = THIGH_LENGTH, TIBIA_LENGTH
    knee = _knee(float(np.linalg.norm(position)))
    if yaw_pitch is None:
        # the hip as seen from the ankle gives both ankle angles, then the hip rotation is what remains
        hip = rotation.T @ -position
        ankle_roll = math.atan2(hip[1], hip[2])
        reach = math.hypot(hip[1], hip[2])
        w = np.array([-l1 * math.sin(knee), l1 * math.cos(knee) + l2])  # (x, z) of the hip in the tibia frame
        ankle_pitch = _wrap(math.atan2(w[0], w[1]) - math.atan2(hip[0], reach))
        upper = rotation @ rot_x(-ankle_roll) @ rot_y(-(ankle_pitch + knee))
        yaw = math.atan2(-upper[0, 1], upper[1, 1])
        roll = math.asin(min(1.0, max(-1.0, upper[2, 1])))
        pitch = math.atan2(-upper[2, 0], upper[2, 2])
        return [-s * yaw, roll + s * _QUARTER, pitch, knee, ankle_pitch, ankle_roll]
    # HipYawPitch fixed: the hip's roll and pitch place the ankle, the ankle angles level the foot
    undo = rot_z(-s * yaw_pitch).T  # the HipYawPitch rotation (about -z on the left, +z on the right) undone
    target, rotation = undo @ position, undo @ rotation
    roll = math.atan2(target[1], -target[2])
    leg = np.array([-l2 * math.sin(knee), -l1 - l2 * math.cos(knee)])  # (x, z) of the ankle in the thigh frame
    radial = math.hypot(target[1], target[2])
    pitch = _wrap(math.atan2(target[0], -radial) - math.atan2(leg[0], leg[1]))
    rest = rot_y(-(pitch + knee)) @ rot_x(-roll) @ rotation
    ankle_pitch = math.atan2(-rest[2, 0], rest[0, 0])
    ankle_roll = math.atan2(-rest[1, 2], rest[1, 1])
    return [yaw_pitch, roll + s * _QUARTER, pitch, knee, ankle_pitch, ankle_roll]


def leg_angles(left_sole: np.ndarray, right_sole: np.ndarray) -> dict[str, float]:
    """Joint angles of both legs (by joint name, LHipYawPitch for the shared motor) for two sole poses."""
    shared = (_solve("L", left_sole, None)[0] + _solve("R", right_sole, None)[0]) / 2
    shared = _limit("L", "HipYawPitch", shared)
    angles: dict[str, float] = {}
    for side, sole in (("L", left_sole), ("R", right_sole)):
        for joint, angle in zip(LEG_JOINTS, _solve(side, sole, shared)):
            angles[f"{side}{joint}"] = _limit(side, joint, angle) if math.isfinite(angle) else 0.0
    angles.pop("RHipYawPitch")
    return angles


def apply_leg_angles(positions: np.ndarray, angles: dict[str, float]) -> np.ndarray:
    """``positions`` (``JOINT_NAMES`` order) with the legs set to ``angles``."""
    result = np.array(positions, dtype=float)
    for name, angle in angles.items():
        result[JOINT_INDEX[name]] = angle
    return result
