"""Both simulators load the same robot: joints, limits, masses, cameras and their images agree."""

from __future__ import annotations

import math

import numpy as np
import pybullet
import pytest

from tafel.modules.perception.ball_detector import BallDetector
from tafel.platforms.mujoco_sim import MujocoPlatform
from tafel.platforms.pybullet_sim import PybulletPlatform
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
    images = [platform.render("top") for platform in engines]
    detector = BallDetector.__new__(BallDetector)
    object.__setattr__(detector, "parameters", BallDetector.Parameters())
    blobs = [detector.candidates("top", image) for image in images]
    assert all(blobs), "both engines render the orange ball"
    (mujoco_ball, *_), (bullet_ball, *_) = blobs
    assert math.hypot(mujoco_ball.x - bullet_ball.x, mujoco_ball.y - bullet_ball.y) < 3.0
    assert mujoco_ball.radius == pytest.approx(bullet_ball.radius, abs=1.5)
