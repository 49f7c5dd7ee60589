"""Foxglove's ``/tf`` carries the robot's links: each link's frame in its parent's, from the measured
joint angles, so that chaining them from the torso gives the program's own forward kinematics."""

from __future__ import annotations

from typing import Any

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from tafel.modules.motion.kinematics import angles_by_name, link_poses, transform
from tafel.representations.motion import JOINT_NAMES, JointSensorData, TorsoPose
from tafel.representations.motion_control import Odometry
from tafel.representations.nao import JOINTS
from tafel.tools.viewers.foxglove_channels import FoxgloveTranslator
from tests.test_foxglove import sdk_class

LIMITS = {joint.name: joint.limits for joint in JOINTS}
FRAME_TRANSFORMS = sdk_class("FrameTransforms")


def decoded(out: Any) -> Any:
    """The message as Foxglove reads it: its protobuf bytes decoded with the SDK's schema."""
    return FRAME_TRANSFORMS.FromString(out.encoded().data)


def as_matrix(frame: object) -> np.ndarray:
    """A FrameTransform (m, quaternion) as a 4x4 transform in mm."""
    q, t = frame.rotation, frame.translation  # type: ignore[attr-defined]
    x, y, z, w = q.x, q.y, q.z, q.w
    rotation = np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                         [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                         [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])
    return transform(rotation, (t.x * 1000, t.y * 1000, t.z * 1000))


@settings(max_examples=25, deadline=None)
@given(st.lists(st.floats(0.0, 1.0), min_size=len(JOINT_NAMES), max_size=len(JOINT_NAMES)))
def test_the_links_frames_on_tf_chain_to_the_kinematics_of_the_measured_angles(shares: list[float]) -> None:
    positions = np.array([LIMITS[name][0] + share * (LIMITS[name][1] - LIMITS[name][0]) if name in LIMITS else 0.0
                          for name, share in zip(JOINT_NAMES, shares)])
    translator = FoxgloveTranslator()
    translator.feed("motion", JointSensorData(position=positions), 0)
    translator.feed("motion", TorsoPose(translation=np.array([10.0, -5.0, 320.0])), 0)
    (out,) = [m for m in translator.feed("cognition", Odometry(), 0) if m.topic == "/tf"]
    by_child = {frame.child_frame_id: frame for frame in decoded(out).transforms}
    expected = link_poses(angles_by_name(positions))
    assert set(expected) - {"torso"} <= set(by_child)
    for link, pose in expected.items():
        chained, name = np.eye(4), link
        while name != "torso":  # up the tree to the torso
            frame = by_child[name]
            chained = as_matrix(frame) @ chained
            name = frame.parent_frame_id
        np.testing.assert_allclose(chained, pose, atol=1e-3, err_msg=link)
    assert by_child["torso"].parent_frame_id == "robot" and by_child["robot"].parent_frame_id == "field"


def test_without_measured_joints_tf_has_no_links() -> None:
    translator = FoxgloveTranslator()
    (out,) = [m for m in translator.feed("cognition", Odometry(), 0) if m.topic == "/tf"]
    assert {frame.child_frame_id for frame in decoded(out).transforms} == {"robot", "torso"}
