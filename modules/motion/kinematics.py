"""Forward kinematics of the NAO from the shared robot description (functions, not a module).

Poses are 4x4 homogeneous transforms in mm. ``link_poses`` gives every link in the torso frame;
``robot_frame_from_torso`` places the torso in the robot frame (origin on the ground between the feet,
x forward, z up) from the legs and the measured torso tilt.
"""

from __future__ import annotations

import math
from collections.abc import Mapping

import numpy as np

from representations.motion import JOINT_INDEX
from representations.nao import COUPLED_JOINTS, FOOT_HEIGHT, JOINTS, CameraMount


def rotation(axis: tuple[float, float, float] | np.ndarray, angle: float) -> np.ndarray:
    """Rotation matrix about a unit ``axis`` by ``angle`` rad (Rodrigues)."""
    x, y, z = np.asarray(axis, dtype=float) / np.linalg.norm(axis)
    c, s = math.cos(angle), math.sin(angle)
    t = 1.0 - c
    return np.array([
        [c + x * x * t, x * y * t - z * s, x * z * t + y * s],
        [y * x * t + z * s, c + y * y * t, y * z * t - x * s],
        [z * x * t - y * s, z * y * t + x * s, c + z * z * t],
    ])


def transform(rotation_: np.ndarray | None = None, translation: tuple[float, float, float] | np.ndarray = (0.0, 0.0, 0.0)) -> np.ndarray:
    result = np.eye(4)
    if rotation_ is not None:
        result[:3, :3] = rotation_
    result[:3, 3] = translation
    return result


def angles_by_name(positions: np.ndarray) -> dict[str, float]:
    """Joint angles of a ``JOINT_NAMES``-ordered array, plus the coupled RHipYawPitch."""
    angles = {name: float(positions[index]) for name, index in JOINT_INDEX.items()}
    for follower, leader in COUPLED_JOINTS.items():
        angles[follower] = angles[leader]
    return angles


def link_poses(angles: Mapping[str, float]) -> dict[str, np.ndarray]:
    """Every link's pose in the torso frame for the given joint angles (missing joints count as 0)."""
    poses = {"torso": np.eye(4)}
    for joint in JOINTS:
        local = transform(rotation(joint.axis, angles.get(joint.name, 0.0)), joint.offset)
        poses[joint.link] = poses[joint.parent] @ local
    return poses


def camera_pose_in_torso(poses: Mapping[str, np.ndarray], camera: CameraMount) -> np.ndarray:
    """The camera frame (x along the optical axis, y left, z up in the image) in the torso frame."""
    return poses["Head"] @ transform(rotation((0, 1, 0), camera.tilt), camera.position)


def sole_in_torso(poses: Mapping[str, np.ndarray], side: str) -> np.ndarray:
    """The point of the sole below the ankle joint, in the torso frame."""
    return (poses[f"{side}Foot"] @ np.array([0.0, 0.0, -FOOT_HEIGHT, 1.0]))[:3]


def tilt(roll: float, pitch: float) -> np.ndarray:
    """The torso's rotation relative to the ground from its roll and pitch (rad)."""
    return rotation((1, 0, 0), roll) @ rotation((0, 1, 0), pitch)


def robot_frame_from_torso(poses: Mapping[str, np.ndarray], roll: float, pitch: float) -> np.ndarray:
    """The torso's pose in the robot frame.

    The torso is tilted by (roll, pitch); the ground is at the lower sole, and the origin lies
    between the feet. The robot frame's yaw is the torso's.
    """
    tilted = tilt(roll, pitch)
    left = tilted @ sole_in_torso(poses, "L")
    right = tilted @ sole_in_torso(poses, "R")
    origin = (left + right) / 2.0
    origin[2] = min(left[2], right[2])
    return transform(tilted, -origin)
