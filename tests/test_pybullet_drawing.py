"""PyBullet's world drawn by MuJoCo's renderer (``--renderer``): the same scene where PyBullet's own renderer
draws it, whatever the robot's pose, joints and the ball; the option's errors and the fallback."""

from __future__ import annotations

import math
from collections.abc import Iterator

import numpy as np
import pytest

from tafel.core.runtime.platform import PlatformError, PlatformOptionError
from tafel.platforms import pybullet_sim
from tafel.platforms.pybullet_sim import PybulletPlatform
from tafel.platforms.robot_model import STANDING_HEIGHT
from tafel.representations.motion import JOINT_NAMES

CONTEXTS = frozenset({"motion", "cognition"})


@pytest.fixture(scope="module")
def both() -> Iterator[dict[str, PybulletPlatform]]:
    """Two PyBullet worlds with cameras: one drawn by MuJoCo, one by PyBullet's CPU renderer."""
    platforms = {name: PybulletPlatform({"renderer": name, "render_worker": "off", "resolution": "160x120"}) for name in ("mujoco", "pybullet")}
    for platform in platforms.values():
        platform.start(CONTEXTS)
    yield platforms
    for platform in platforms.values():
        platform.stop()


def quaternion(roll: float, pitch: float, yaw: float) -> np.ndarray:
    """wxyz of the turn yaw, then pitch, then roll (rad)."""
    cr, sr, cp, sp, cy, sy = (f(a / 2) for a in (roll, pitch, yaw) for f in (math.cos, math.sin))
    return np.array([cr * cp * cy + sr * sp * sy, sr * cp * cy - cr * sp * sy, cr * sp * cy + sr * cp * sy, cr * cp * sy - sr * sp * cy])


#: (torso x, y m, roll, pitch, yaw rad, head yaw, head pitch rad, ball x, y mm): standing, turned, leaning and
#: looking aside, so that a wrong frame, axis order or joint would move the ball in one image and not the other
SCENES = [
    (0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.3, 900.0, 0.0),
    (-1.5, 1.0, 0.0, 0.0, 0.6, -0.4, 0.1, -300.0, 1400.0),
    (2.0, -0.5, 0.1, 0.15, -2.5, 0.5, 0.25, 1500.0, -1590.0),
    (0.5, 0.5, -0.08, 0.0, 3.0, 0.0, 0.45, 100.0, 500.0),  # the ball near the feet: the bottom camera
]


@pytest.mark.parametrize("scene", SCENES, ids=[f"scene{i}" for i in range(len(SCENES))])
def test_mujoco_draws_the_ball_where_pybullets_own_renderer_does(both: dict[str, PybulletPlatform], scene: tuple[float, ...]) -> None:
    x, y, roll, pitch, yaw, head_yaw, head_pitch, ball_x, ball_y = scene
    masks = {}
    for name, platform in both.items():
        angles = np.zeros(len(JOINT_NAMES))
        angles[JOINT_NAMES.index("HeadYaw")], angles[JOINT_NAMES.index("HeadPitch")] = head_yaw, head_pitch
        platform.pose_joints(angles)
        platform.place_robot(np.array([x, y, STANDING_HEIGHT]), quaternion(roll, pitch, yaw))
        platform.move_ball(ball_x, ball_y)
        masks[name] = {camera: platform.ball_mask(camera) for camera in ("top", "bottom")}
        images = {camera: platform.render(camera) for camera in ("top", "bottom")}
        assert all(image.shape == (120, 160, 3) and image.dtype == np.uint8 for image in images.values())
    seen = 0
    for camera in ("top", "bottom"):
        drawn, own = masks["mujoco"][camera], masks["pybullet"][camera]
        if own.sum() < 30:  # a sliver at the image's edge: the renderers' rounding differs there
            continue
        seen += 1
        overlap = (drawn & own).sum() / (drawn | own).sum()
        assert overlap > 0.6, f"{camera}: the ball drawn by MuJoCo covers {overlap:.0%} of PyBullet's (both ways)"
    assert seen, "the scene must show the ball in one camera at least"


def test_the_cameras_follow_the_joints_as_pybullet_moves_them(both: dict[str, PybulletPlatform]) -> None:
    """Turning the head moves the image: MuJoCo is posed from PyBullet's state at every image, not once."""
    platform = both["mujoco"]
    platform.place_robot(np.array([0.0, 0.0, STANDING_HEIGHT]), quaternion(0.0, 0.0, 0.0))
    platform.move_ball(1000.0, 0.0)
    angles = np.zeros(len(JOINT_NAMES))
    columns = []
    for head_yaw in (-0.3, 0.0, 0.3):
        angles[JOINT_NAMES.index("HeadYaw")], angles[JOINT_NAMES.index("HeadPitch")] = head_yaw, 0.3
        platform.pose_joints(angles)
        columns.append(np.nonzero(platform.ball_mask("top"))[1].mean())
    assert columns[0] < columns[1] < columns[2], f"the ball's column as the head turns right to left: {columns}"


def test_the_renderer_option_says_what_it_takes() -> None:
    with pytest.raises(PlatformOptionError, match="--renderer takes auto, mujoco or pybullet, got 'opengl'"):
        PybulletPlatform({"renderer": "opengl"})
    assert PybulletPlatform({}).renderer == "auto"


def test_without_a_mujoco_renderer_auto_falls_back_and_mujoco_says_why(monkeypatch: pytest.MonkeyPatch, capfd: pytest.CaptureFixture[str]) -> None:
    def no_gl(*args: object) -> None:
        raise PlatformError("MuJoCo cannot render headless with MUJOCO_GL=egl (no EGL display)")

    monkeypatch.setattr(pybullet_sim, "MujocoDrawing", no_gl)
    fallback = PybulletPlatform({"renderer": "auto", "render_worker": "off", "resolution": "80x60"})
    fallback.start(CONTEXTS)
    try:
        assert fallback.drawing is None and fallback.render("top").shape == (60, 80, 3)
    finally:
        fallback.stop()
    assert "the cameras render with PyBullet's CPU renderer" in capfd.readouterr().err
    with pytest.raises(PlatformError, match="cannot render headless"):
        PybulletPlatform({"renderer": "mujoco", "render_worker": "off"}).start(CONTEXTS)


def test_with_the_cameras_off_nothing_is_drawn() -> None:
    platform = PybulletPlatform({"cameras": "off"})
    platform.start(CONTEXTS)
    try:
        assert platform.drawing is None
    finally:
        platform.stop()
