"""PyBullet's carpet with ``--realism``: MuJoCo's seeded carpet texture (``field_world.carpet_texture``) on
a mesh of one-metre squares, with darker strips; ``off`` keeps the flat box it always had."""

from __future__ import annotations

import math
from collections.abc import Iterator
from contextlib import contextmanager

import cv2
import numpy as np
import pybullet
import pytest

from tafel.modules.motion.kinematics import CAMERA_LINKS, angles_by_name, link_poses, robot_frame_from_torso
from tafel.modules.motion.stand_motion import stand_pose
from tafel.platforms.field_world import CARPET_RGBA, SceneLook
from tafel.platforms.pybullet_sim import PybulletPlatform, carpet_mesh, stripe_shade
from tafel.representations.geometry import Pose2D
from tafel.representations.motion import HEAD_PITCH, HEAD_YAW

#: the robot in its own half, turned to the halfway line: the top camera sees the centre circle, the bottom one a line
POSE, HEAD = (-500.0, 1500.0, -0.4), (0.0, 0.35)


@contextmanager
def platform(realism: str, seed: int) -> Iterator[PybulletPlatform]:
    """A PyBullet platform at ``realism`` with the robot posed at ``POSE`` (no render worker)."""
    p = PybulletPlatform({"realism": realism, "seed": seed, "renderer": "pybullet", "render_worker": "off", "resolution": "320x240"})
    p.start(frozenset({"motion", "cognition"}))
    try:
        angles = stand_pose()
        angles[HEAD_YAW], angles[HEAD_PITCH] = HEAD
        offset = robot_frame_from_torso(link_poses(angles_by_name(angles), CAMERA_LINKS), 0.0, 0.0)[:3, 3]
        x, y = Pose2D(*POSE).to_global(offset[0], offset[1])
        p.pose_joints(angles)
        p.place_robot(np.array([x, y, offset[2]]) * 0.001, np.array([math.cos(POSE[2] / 2), 0.0, 0.0, math.sin(POSE[2] / 2)]))
        p.move_ball(4000.0, -2500.0)  # out of sight
        yield p
    finally:
        p.stop()


def images(realism: str, seed: int) -> np.ndarray:
    """Both cameras' plain renders (the camera pipeline apart), top above bottom."""
    with platform(realism, seed) as p:
        return np.vstack([p.render("top"), p.render("bottom")])


def white(image: np.ndarray) -> np.ndarray:
    """Painted line pixels: bright and grey."""
    pixels = image.astype(int)
    return (pixels.min(axis=2) > 170) & (pixels.max(axis=2) - pixels.min(axis=2) < 50)


def away_from_lines(lines: np.ndarray) -> np.ndarray:
    """Pixels at least 3 px from every line pixel: carpet (or whatever else the image shows there)."""
    return ~np.asarray(cv2.dilate(lines.astype(np.uint8), np.ones((7, 7), np.uint8)), bool)


def test_the_carpet_mesh_covers_the_carpet_once_in_alternating_strips() -> None:
    half_x, half_y = 5.2, 3.7
    area = 0.0
    for strips in (0, 1):
        vertices, uvs, triangles = carpet_mesh(half_x, half_y, strips)
        corners = vertices[triangles]
        cross = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
        assert np.all(cross[:, 2] > 0), "every triangle faces up (counter-clockwise from above)"
        area += float(cross[:, 2].sum()) / 2
        assert uvs.min() >= 0.0 and uvs.max() <= 1.0 + 1e-9  # each square holds at most one copy of the texture
        assert np.all(np.abs(vertices[:, :2]) <= [half_x + 1e-9, half_y + 1e-9]) and np.all(vertices[:, 2] == 0.0)
        strip_of = np.floor((corners[:, :, 0].mean(axis=1) + half_x) / 1.0).astype(int)
        assert set(strip_of % 2) == {strips}
    assert area == pytest.approx(4 * half_x * half_y)
    everything = carpet_mesh(half_x, half_y)[2]
    assert len(everything) == len(carpet_mesh(half_x, half_y, 0)[2]) + len(carpet_mesh(half_x, half_y, 1)[2])


def test_the_stripes_are_seeded_and_as_strong_as_the_texture_says() -> None:
    phases = {stripe_shade(SceneLook(seed, (0.2, 0.5, 0.2), 0.1))[0] for seed in range(20)}
    assert phases == {0, 1}
    assert stripe_shade(SceneLook(3, (0.2, 0.5, 0.2), 0.1)) == stripe_shade(SceneLook(3, (0.2, 0.5, 0.2), 0.1))
    assert 0.9 < stripe_shade(SceneLook(3, (0.2, 0.5, 0.2), 0.12))[1] < stripe_shade(SceneLook(3, (0.2, 0.5, 0.2), 0.05))[1] < 1.0


def test_without_realism_the_carpet_is_the_flat_box_it_was() -> None:
    with platform("off", 0) as p:
        shape = pybullet.getVisualShapeData(p.bodies["carpet"], physicsClientId=p.client)[0]
        assert shape[2] == pybullet.GEOM_BOX and shape[7] == pytest.approx(CARPET_RGBA)
        assert "carpet_stripes" not in p.bodies
        image = p.render("bottom")  # the top camera sees the hall too
        carpet = away_from_lines(white(image))
        assert image[carpet].std(axis=0).max() == 0.0, "one flat green"


def test_the_realistic_carpet_is_textured_seeded_and_the_lines_stay_white_where_they_are() -> None:
    plain = images("off", 0)
    lines = white(plain)
    assert 0.01 < lines.mean() < 0.3, "the view must show lines and carpet"
    textured = {(level, seed): images(level, seed) for level, seed in (("mild", 1), ("mild", 2), ("full", 1))}
    # the carpet: what is green in the plain render, a few pixels away from the lines
    carpet = away_from_lines(lines) & (plain[:, :, 1].astype(int) - plain[:, :, [0, 2]].max(axis=2) > 40)
    carpet[: plain.shape[0] // 4] = False  # the far carpet of the top image: the realistic hall's clutter may stand there
    for (level, seed), image in textured.items():
        assert image.shape == plain.shape
        half = image.shape[0] // 2
        for camera, rows in (("top", slice(0, half)), ("bottom", slice(half, None))):
            green = image[rows, :, 1][carpet[rows]].astype(float)
            assert green.std() > 2.0, f"{level} seed {seed}, {camera} camera: the carpet has fibres and strips, not one flat green"
        assert carpet.mean() > 0.5
        assert np.all(image[carpet][:, 1] > image[carpet][:, 0]), f"{level} seed {seed}: the carpet stays green"
        found = white(image)
        assert (found & lines).sum() / (found | lines).sum() > 0.9, f"{level} seed {seed}: the lines are white where they were"
        assert (found & carpet).mean() < 0.001, f"{level} seed {seed}: no white in the carpet"
    assert not np.array_equal(textured["mild", 1], textured["mild", 2]), "another seed, another carpet"
    assert np.array_equal(textured["mild", 1], images("mild", 1)), "the same seed, the same carpet"


@pytest.mark.slow  # starts a render worker process
def test_the_render_worker_draws_the_same_realistic_carpet() -> None:
    """The worker builds its own copy of the world from the options: the same seeded carpet and strips."""
    p = PybulletPlatform({"realism": "mild", "seed": 4, "renderer": "pybullet", "render_worker": "on", "resolution": "160x120"})
    p.start(frozenset({"motion", "cognition"}))
    try:
        assert p.worker is not None, "the render worker did not start"
        p.worker.request(p.moving_state(), "top")
        np.testing.assert_array_equal(p.worker.image(), p.render("top"))
    finally:
        p.stop()
