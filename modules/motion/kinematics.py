"""Forward kinematics of the NAO from the shared robot description (functions, not a module).

Poses are 4x4 homogeneous transforms in mm. ``link_poses`` gives every link in the torso frame;
``robot_frame_from_torso`` places the torso in the robot frame (origin on the ground between the feet,
x forward, z up) from the legs and the measured torso tilt.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from functools import lru_cache

import numpy as np

from tafel.representations.motion import JOINT_INDEX
from tafel.representations.nao import COUPLED_JOINTS, FOOT_HEIGHT, JOINTS, CameraMount, Joint


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


def _skew(axis: tuple[float, float, float]) -> np.ndarray:
    x, y, z = np.asarray(axis, dtype=float) / np.linalg.norm(axis)
    return np.array([[0.0, -z, y], [z, 0.0, -x], [-y, x, 0.0]])


def _terms(joint: Joint) -> np.ndarray:
    """(A, B, C) with the joint's local transform = A + sin(angle) B + (1 - cos(angle)) C (Rodrigues)."""
    k = _skew(joint.axis)
    a, b, c = np.eye(4), np.zeros((4, 4)), np.zeros((4, 4))
    a[:3, 3] = joint.offset
    b[:3, :3], c[:3, :3] = k, k @ k
    return np.stack([a, b, c]).reshape(3, 16)


#: per joint, computed once, so that a joint's transform is one small matrix product
_TERMS = {joint.name: _terms(joint) for joint in JOINTS}
_PARENT = {joint.link: joint for joint in JOINTS}


@lru_cache(maxsize=None)
def _chain(links: tuple[str, ...]) -> tuple:
    """The joints from the torso to ``links``, parents first."""
    needed: list = []
    for link in links:
        path = []
        while link in _PARENT:
            joint = _PARENT[link]
            path.append(joint)
            link = joint.parent
        needed += [j for j in reversed(path) if j not in needed]
    return tuple(needed)


_ALL_LINKS = tuple(joint.link for joint in JOINTS)


def link_poses(angles: Mapping[str, float], links: tuple[str, ...] = _ALL_LINKS) -> dict[str, np.ndarray]:
    """Link poses in the torso frame for the given joint angles (missing joints count as 0): of
    ``links`` and the links on their way from the torso (all links by default)."""
    chain, terms = _chain(links), _chain_terms(links)
    q = np.array([angles.get(joint.name, 0.0) for joint in chain])
    coefficients = np.stack([np.ones_like(q), np.sin(q), 1.0 - np.cos(q)], axis=1)
    local = np.einsum("jk,jkl->jl", coefficients, terms).reshape(-1, 4, 4)  # every joint's transform at once
    poses = {"torso": np.eye(4)}
    for joint, transform_ in zip(chain, local):
        poses[joint.link] = poses[joint.parent] @ transform_
    return poses


@lru_cache(maxsize=None)
def _chain_terms(links: tuple[str, ...]) -> np.ndarray:
    return np.stack([_TERMS[joint.name] for joint in _chain(links)])


#: the links the camera matrices need: the head, and both feet for the ground
CAMERA_LINKS = ("Head", "LFoot", "RFoot")


@lru_cache(maxsize=None)
def camera_mount(camera: CameraMount) -> np.ndarray:
    """The camera frame in the head frame (constant)."""
    return transform(rotation((0, 1, 0), camera.tilt), camera.position)


def camera_pose_in_torso(poses: Mapping[str, np.ndarray], camera: CameraMount) -> np.ndarray:
    """The camera frame (x along the optical axis, y left, z up in the image) in the torso frame."""
    return poses["Head"] @ camera_mount(camera)


def sole_in_torso(poses: Mapping[str, np.ndarray], side: str) -> np.ndarray:
    """The point of the sole below the ankle joint, in the torso frame."""
    return (poses[f"{side}Foot"] @ np.array([0.0, 0.0, -FOOT_HEIGHT, 1.0]))[:3]


def tilt(roll: float, pitch: float) -> np.ndarray:
    """The torso's rotation relative to the ground from its roll and pitch (rad): Rx(roll) Ry(pitch)."""
    cr, sr, cp, sp = math.cos(roll), math.sin(roll), math.cos(pitch), math.sin(pitch)
    return np.array([[cp, 0.0, sp], [sr * sp, cr, -sr * cp], [-cr * sp, sr, cr * cp]])


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
