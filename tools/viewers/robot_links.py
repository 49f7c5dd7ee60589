"""The robot's links and cameras in the robot frame, from measured joint angles and the torso's pose.

The web view's 3D panel and Foxglove's ``/tf`` show the robot as the program's own kinematic model
(``tafel.modules.motion.kinematics``) puts it: the page and Foxglove draw these poses, they do not
compute kinematics of their own.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from tafel.modules.motion.kinematics import angles_by_name, camera_pose_in_torso, link_poses, transform
from tafel.representations.nao import CAMERAS, HORIZONTAL_FOV, JOINTS, VERTICAL_FOV

#: each link's parent ("torso" is the root)
PARENTS: dict[str, str] = {joint.link: joint.parent for joint in JOINTS}
#: the link a joint moves, by joint name
LINK_OF: dict[str, str] = {joint.name: joint.link for joint in JOINTS}


def torso_in_robot(torso: Any | None) -> np.ndarray:
    """``TorsoPose`` as a 4x4 transform (mm); without one, upright 300 mm above the ground."""
    if torso is None:
        return transform(None, (0.0, 0.0, 300.0))
    return transform(np.asarray(torso.rotation, float), np.asarray(torso.translation, float))


def robot_links(positions: np.ndarray, torso: Any | None) -> tuple[dict[str, np.ndarray], dict[str, np.ndarray]]:
    """(links, cameras): every link's and each camera's 4x4 pose in the robot frame (mm), for the
    joint angles ``positions`` (``JOINT_NAMES`` order) and the ``TorsoPose`` ``torso``."""
    base = torso_in_robot(torso)
    in_torso = link_poses(angles_by_name(np.asarray(positions, float)))
    links = {name: base @ pose for name, pose in in_torso.items()}
    cameras = {camera.name: base @ camera_pose_in_torso(in_torso, camera) for camera in CAMERAS}
    return links, cameras


def links_message(positions: np.ndarray, torso: Any | None) -> dict[str, Any]:
    """What the web view's 3D panel draws: links and cameras (``rotation`` 3x3 and ``translation`` mm,
    robot frame), each link's parent, the cameras' fields of view (rad), and the angles they come from."""
    links, cameras = robot_links(positions, torso)

    def pose(matrix: np.ndarray) -> dict[str, Any]:
        return {"rotation": matrix[:3, :3].round(6).tolist(), "translation": matrix[:3, 3].round(3).tolist()}

    return {"links": {name: {**pose(matrix), "parent": PARENTS.get(name, "")} for name, matrix in links.items()},
            "cameras": {name: pose(matrix) for name, matrix in cameras.items()},
            "fov": {"horizontal": HORIZONTAL_FOV, "vertical": VERTICAL_FOV},
            "angles": {name: float(value) for name, value in angles_by_name(np.asarray(positions, float)).items()}}
