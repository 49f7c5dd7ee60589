"""Both simulators load the same robot: joints, limits, masses, cameras and their images agree."""

from __future__ import annotations

import math

import cv2
import numpy as np
import pybullet
import pytest
from hypothesis import given
from hypothesis import strategies as st

from tafel.platforms.mujoco_sim import MujocoPlatform
from tafel.platforms.pybullet_sim import PybulletPlatform
from tafel.platforms.robot_model import joint_motor, torque_range
from tafel.platforms.simulated import TIMESTEP
from tafel.representations.motion import JOINT_NAMES
from tafel.representations.nao import CAMERAS, JOINTS, TORSO_MASS, VERTICAL_FOV


@pytest.fixture(scope="module")
def engines():
    mujoco_platform, bullet_platform = MujocoPlatform({"ball": "1500,200"}), PybulletPlatform({"ball": "1500,200"})
    for platform in (mujoco_platform, bullet_platform):
        platform.start(frozenset({"cognition", "motion"}))
    yield mujoco_platform, bullet_platform
    for platform in (mujoco_platform, bullet_platform):
        platform.stop()


def bullet_joints(platform: PybulletPlatform) -> dict[str, tuple]:
    infos = [pybullet.getJointInfo(platform.robot, i, physicsClientId=platform.client)
             for i in range(pybullet.getNumJoints(platform.robot, physicsClientId=platform.client))]
    return {info[1].decode(): info for info in infos}


@pytest.mark.slow
def test_joint_names_and_limits_agree(engines) -> None:
    mujoco_platform, bullet_platform = engines
    model = mujoco_platform.model
    mujoco_joints = {model.joint(i).name: tuple(model.jnt_range[i]) for i in range(model.njnt) if model.jnt_type[i] == 3}
    bullet = {name: (info[8], info[9]) for name, info in bullet_joints(bullet_platform).items()}
    assert set(mujoco_joints) == set(bullet) == {joint.name for joint in JOINTS}
    for name, (low, high) in mujoco_joints.items():
        assert bullet[name] == pytest.approx((low, high), abs=1e-5), name


@pytest.mark.slow
def test_link_masses_agree(engines) -> None:
    mujoco_platform, bullet_platform = engines
    joints = bullet_joints(bullet_platform)
    for joint in JOINTS:
        mujoco_mass = mujoco_platform.model.body(joint.link).mass[0]
        bullet_mass = pybullet.getDynamicsInfo(bullet_platform.robot, joints[joint.name][0], physicsClientId=bullet_platform.client)[0]
        assert mujoco_mass == pytest.approx(joint.mass) and bullet_mass == pytest.approx(joint.mass), joint.link
    assert pybullet.getDynamicsInfo(bullet_platform.robot, -1, physicsClientId=bullet_platform.client)[0] == pytest.approx(TORSO_MASS)
    assert mujoco_platform.model.body("torso").mass[0] == pytest.approx(TORSO_MASS)


@pytest.mark.slow
def test_camera_poses_and_field_of_view_agree(engines) -> None:
    mujoco_platform, bullet_platform = engines
    import mujoco

    mujoco.mj_forward(mujoco_platform.model, mujoco_platform.data)
    state = pybullet.getLinkState(bullet_platform.robot, bullet_platform.head_link, computeForwardKinematics=True,
                                  physicsClientId=bullet_platform.client)
    head_position, head_rotation = np.array(state[4]), np.array(pybullet.getMatrixFromQuaternion(state[5])).reshape(3, 3)
    for mount in CAMERAS:
        camera = mujoco_platform.model.camera(f"{mount.name}_camera")
        mujoco_position = mujoco_platform.data.cam_xpos[camera.id]
        mujoco_axis = -mujoco_platform.data.cam_xmat[camera.id].reshape(3, 3)[:, 2]  # MuJoCo cameras look along -z
        bullet_position = head_position + head_rotation @ (np.array(mount.position) / 1000.0)
        c, s = math.cos(mount.tilt), math.sin(mount.tilt)
        bullet_axis = head_rotation @ np.array([c, 0.0, -s])
        assert np.allclose(mujoco_position, bullet_position, atol=1e-6), mount.name
        assert np.allclose(mujoco_axis, bullet_axis, atol=1e-6), mount.name
        assert math.radians(camera.fovy[0]) == pytest.approx(VERTICAL_FOV)
    assert mujoco_platform.fov() == bullet_platform.fov()


@pytest.mark.slow
def test_both_renderings_show_the_ball_at_the_same_pixel(engines) -> None:
    masks = [platform.ball_mask("top") for platform in engines]  # the engines' own segmentation: ground truth
    assert all(mask.sum() > 20 for mask in masks), "both engines render the ball"
    (mujoco_y, mujoco_x), (bullet_y, bullet_x) = (np.argwhere(mask).mean(axis=0) for mask in masks)
    assert math.hypot(mujoco_x - bullet_x, mujoco_y - bullet_y) < 2.0
    assert masks[0].sum() == pytest.approx(masks[1].sum(), rel=0.15)


@pytest.mark.slow
def test_both_renderings_look_alike_to_the_detectors(engines) -> None:
    """The same share of field green, of white lines and of black ball patches in the same places."""
    shares = []
    for platform in engines:
        image = platform.render("top")
        hsv = cv2.cvtColor(image, cv2.COLOR_RGB2HSV)
        green = (hsv[..., 0] > 35) & (hsv[..., 0] < 85) & (hsv[..., 1] > 80)
        white = (hsv[..., 1] < 40) & (hsv[..., 2] > 200)
        dark_ball = platform.ball_mask("top") & (hsv[..., 2] < 90)
        shares.append((green.mean(), white.mean(), dark_ball.sum() / max(1, platform.ball_mask("top").sum())))
    (mujoco_green, mujoco_white, mujoco_dark), (bullet_green, bullet_white, bullet_dark) = shares
    assert mujoco_green == pytest.approx(bullet_green, abs=0.03)
    assert mujoco_white == pytest.approx(bullet_white, abs=0.01)
    assert 0.1 < mujoco_dark < 0.45 and 0.1 < bullet_dark < 0.45


@given(velocity=st.floats(-30.0, 30.0), stall=st.floats(0.1, 20.0), no_load=st.floats(0.5, 20.0))
def test_the_motor_gives_its_stall_torque_at_rest_and_nothing_forwards_at_its_no_load_speed(
        velocity: float, stall: float, no_load: float) -> None:
    low, high = (float(v[0]) for v in torque_range(np.array([velocity]), np.array([stall]), np.array([no_load])))
    assert -stall <= low <= 0.0 <= high <= stall
    if velocity >= no_load:
        assert high == 0.0  # cannot drive it any faster
    if velocity <= -no_load:
        assert low == 0.0
    if velocity == 0.0:
        assert (low, high) == (-stall, stall)
    if velocity > 0:
        assert low == -stall  # braking is always possible
    faster_high = float(torque_range(np.array([velocity + 1.0]), np.array([stall]), np.array([no_load]))[1][0])
    assert faster_high <= high


@pytest.mark.slow
def test_no_joint_moves_faster_than_its_motor(engines) -> None:
    """A 3 rad step in both shoulders: each engine moves them at most at the motor's no-load speed."""
    names = ["LShoulderPitch", "RShoulderPitch", "HeadYaw"]
    indices = [JOINT_NAMES.index(name) for name in names]
    no_load = np.array([joint_motor(name)[1] for name in names])
    for platform in engines:
        start = platform.joint_angles()
        target = start.copy()
        target[indices] = [-1.5, -1.5, 1.5]
        previous, fastest = start[indices], np.zeros(len(names))
        for _ in range(300):  # 0.6 s in 2 ms steps
            platform.drive(target, np.ones(len(JOINT_NAMES)))
            platform.step_physics(1)
            now = platform.joint_angles()[indices]
            fastest = np.maximum(fastest, np.abs(now - previous) / TIMESTEP)
            previous = now
        assert np.all(fastest <= no_load * 1.05), (platform.name, fastest, no_load)
        assert np.all(fastest >= no_load * 0.25), (platform.name, fastest)  # and the motors do drive
        platform.drive(start, np.ones(len(JOINT_NAMES)))
        platform.step_physics(300)
