"""Forward kinematics against poses computed by hand from the reference figures."""

from __future__ import annotations

import math

import numpy as np
import pytest

from tafel.core.testing import ModuleHarness
from tafel.modules.motion.camera_matrix_provider import CameraMatrixProvider
from tafel.modules.motion.kinematics import (
    angles_by_name,
    camera_pose_in_torso,
    link_poses,
    robot_frame_from_torso,
    rotation,
    sole_in_torso,
)
from tafel.platforms.robot_model import mjcf
from tafel.representations.motion import JOINT_INDEX, CameraMatrixBottom, CameraMatrixTop, InertialModel, JointSensorData, TorsoPose
from tafel.representations.nao import (
    ACCELEROMETER_POSITION,
    BOTTOM_CAMERA,
    GYROSCOPE_POSITION,
    JOINTS_BY_NAME,
    TOP_CAMERA,
    total_mass,
)

LEG = 85.0 + 100.0 + 102.9 + 45.19  # hip offset, thigh, tibia, foot height (mm)


def test_rotation_is_orthonormal_and_right_handed() -> None:
    r = rotation((0, 0, 1), math.pi / 2)
    assert np.allclose(r @ [1, 0, 0], [0, 1, 0])
    assert np.allclose(rotation((0, 1, 0), 0.3) @ rotation((0, 1, 0), -0.3), np.eye(3))
    assert np.isclose(np.linalg.det(rotation((1, 2, 3), 1.0)), 1.0)


def test_total_mass_matches_the_reference() -> None:
    assert total_mass() == pytest.approx(5.359, abs=0.002)


def test_cameras_with_all_joints_at_zero() -> None:
    poses = link_poses({})
    top = camera_pose_in_torso(poses, TOP_CAMERA)
    assert np.allclose(top[:3, 3], [58.71, 0.0, 126.5 + 63.64])
    # the optical axis points forward and 1.2 degrees down
    assert np.allclose(top[:3, 0], [math.cos(math.radians(1.2)), 0.0, -math.sin(math.radians(1.2))])
    bottom = camera_pose_in_torso(poses, BOTTOM_CAMERA)
    assert np.allclose(bottom[:3, 3], [50.71, 0.0, 126.5 + 17.74])
    assert np.allclose(bottom[:3, 0], [math.cos(math.radians(39.7)), 0.0, -math.sin(math.radians(39.7))])


def test_head_yaw_turns_the_cameras_left() -> None:
    top = camera_pose_in_torso(link_poses({"HeadYaw": math.pi / 2}), TOP_CAMERA)
    assert np.allclose(top[:3, 3], [0.0, 58.71, 190.14])
    assert top[1, 0] > 0.99  # looking along +y


def test_head_pitch_tilts_the_cameras_down() -> None:
    pitch = 0.5
    top = camera_pose_in_torso(link_poses({"HeadPitch": pitch}), TOP_CAMERA)
    c, s = math.cos(pitch), math.sin(pitch)
    expected = np.array([58.71 * c + 63.64 * s, 0.0, 126.5 - 58.71 * s + 63.64 * c])
    assert np.allclose(top[:3, 3], expected)
    tilt = pitch + math.radians(1.2)
    assert np.allclose(top[:3, 0], [math.cos(tilt), 0.0, -math.sin(tilt)])


def test_straight_legs_put_the_torso_a_leg_length_above_the_ground() -> None:
    poses = link_poses({})
    assert np.allclose(sole_in_torso(poses, "L"), [0.0, 50.0, -LEG])
    assert np.allclose(sole_in_torso(poses, "R"), [0.0, -50.0, -LEG])
    torso = robot_frame_from_torso(poses, 0.0, 0.0)
    assert np.allclose(torso[:3, 3], [0.0, 0.0, LEG])


def test_bent_knees_lower_the_torso_as_computed_by_hand() -> None:
    a = 0.4
    angles = {"LHipPitch": -a, "LKneePitch": 2 * a, "LAnklePitch": -a, "RHipPitch": -a, "RKneePitch": 2 * a, "RAnklePitch": -a}
    poses = link_poses(angles)
    sole = sole_in_torso(poses, "L")
    assert sole == pytest.approx([(100.0 - 102.9) * math.sin(a), 50.0, -85.0 - 202.9 * math.cos(a) - 45.19])
    torso = robot_frame_from_torso(poses, 0.0, 0.0)
    assert torso[2, 3] == pytest.approx(85.0 + 202.9 * math.cos(a) + 45.19)


def test_torso_tilt_moves_the_cameras() -> None:
    pitch = 0.1
    poses = link_poses({})
    torso = robot_frame_from_torso(poses, 0.0, pitch)
    camera = torso @ camera_pose_in_torso(poses, TOP_CAMERA)
    tilt = pitch + math.radians(1.2)
    assert np.allclose(camera[:3, 0], [math.cos(tilt), 0.0, -math.sin(tilt)])
    # the feet stay on the ground: the lower sole is at z = 0
    soles = [(torso @ np.append(sole_in_torso(poses, side), 1.0))[2] for side in "LR"]
    assert min(soles) == pytest.approx(0.0, abs=1e-9)


def test_hip_yaw_pitch_is_shared_by_both_legs() -> None:
    positions = np.zeros(25)
    positions[JOINT_INDEX["LHipYawPitch"]] = -0.3
    angles = angles_by_name(positions)
    assert angles["RHipYawPitch"] == -0.3
    poses = link_poses(angles)
    left, right = sole_in_torso(poses, "L"), sole_in_torso(poses, "R")
    assert left[0] == pytest.approx(right[0]) and left[1] == pytest.approx(-right[1])  # symmetric


def test_camera_matrix_provider_on_the_mocked_blackboard() -> None:
    position = np.zeros(25)
    position[JOINT_INDEX["HeadYaw"]] = 0.2
    bb = ModuleHarness(CameraMatrixProvider, JointSensorData(position=position), InertialModel()).execute()
    top, bottom = bb[CameraMatrixTop], bb[CameraMatrixBottom]
    assert top.valid and bottom.valid
    assert top.translation[2] == pytest.approx(LEG + 126.5 + 63.64)
    assert math.atan2(top.rotation[1, 0], top.rotation[0, 0]) == pytest.approx(0.2)
    assert bb[TorsoPose].translation[2] == pytest.approx(LEG)


@pytest.mark.parametrize(("angle", "left"), [(0.3, (-51.84, 55.54, -327.55)), (-0.5, (84.10, 65.19, -317.90))])
def test_hip_yaw_pitch_axes_are_the_real_robots(angle: float, left: tuple[float, float, float]) -> None:
    """Only HipYawPitch turned: the soles where B-Human's, NaoTH's and HULKs' models put them."""
    poses = link_poses({"LHipYawPitch": angle, "RHipYawPitch": angle})
    np.testing.assert_allclose(sole_in_torso(poses, "L"), left, atol=0.5)
    np.testing.assert_allclose(sole_in_torso(poses, "R"), (left[0], -left[1], left[2]), atol=0.5)


def test_hip_yaw_pitch_axes_in_the_torso_frame() -> None:
    s = math.sqrt(0.5)
    assert JOINTS_BY_NAME["LHipYawPitch"].axis == pytest.approx((0.0, s, -s))
    assert JOINTS_BY_NAME["RHipYawPitch"].axis == pytest.approx((0.0, s, s))


def test_imu_sits_where_the_real_one_does() -> None:
    assert ACCELEROMETER_POSITION == (-8.0, 6.06, 27.0) and GYROSCOPE_POSITION == (-8.0, 6.0, 29.0)
    xml = mjcf()
    assert '<site name="accelerometer" pos="-0.008 0.00606 0.027"' in xml
    assert '<site name="gyroscope" pos="-0.008 0.006 0.029"' in xml
