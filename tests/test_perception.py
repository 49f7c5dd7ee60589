"""The perception pipeline against rendered images with known positions (``tools.simulation.scene_frames``), and its
parts alone: field colour, field boundary, image geometry, the SPL ball's texture.

Rendered scenes are posed kinematically (no physics), so each takes a few milliseconds; opening a
renderer takes seconds, so the rendered checks are marked slow and the parts alone run in the fast tier.
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from pathlib import Path
from types import SimpleNamespace

import cv2
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tafel.core.testing import ModuleHarness
from tafel.modules.modeling.field_model import FIELD_MODEL
from tafel.modules.perception.field_boundary_detector import FieldBoundaryDetector, lower_hull
from tafel.modules.perception.field_color_provider import FieldColorProvider, green_mask
from tafel.modules.perception.image_geometry import ImageProjection
from tafel.modules.perception.line_detector import longest_arc, white_runs
from tafel.platforms.field_world import ball_is_black, ball_texture, paint_ball_texture
from tafel.representations import field
from tafel.representations.motion import CameraMatrix, CameraMatrixBottom, CameraMatrixBuffer, CameraMatrixTop
from tafel.representations.perception import (
    BallImagePercept,
    BallPercept,
    CameraImageBottom,
    CameraImageTop,
    FieldBoundary,
    FieldColor,
    GoalPostPercept,
    LinePercept,
    SegmentedImage,
)
from tafel.tools.simulation.scene_frames import Perception, SceneRenderer

ENGINES = [pytest.param("mujoco", marks=pytest.mark.slow), pytest.param("pybullet", marks=pytest.mark.slow)]


@pytest.fixture(scope="module", params=ENGINES)
def renderer(request: pytest.FixtureRequest) -> Iterator[SceneRenderer]:
    with SceneRenderer(request.param) as scene:
        yield scene


def percepts(renderer: SceneRenderer, pose: tuple[float, float, float], head: tuple[float, float], ball: tuple[float, float]):
    frames = renderer.frames(pose, head, ball)
    perception = Perception()
    for _ in range(3):  # the field colour settles over a few frames, as in the program
        board = perception(frames)
    return frames, board


# ------------------------------------------------------------------------------------------ ball
@pytest.mark.parametrize("distance", [500.0, 1000.0, 2000.0, 3000.0, 4000.0])
def test_the_spl_ball_is_found_where_it_is(renderer: SceneRenderer, distance: float) -> None:
    pose = (-2500.0, -500.0, 0.3)
    bearing = pose[2] + 0.15
    ball = (pose[0] + distance * math.cos(bearing), pose[1] + distance * math.sin(bearing))
    head = (0.15, 0.45 if distance < 700 else 0.25 if distance < 1500 else 0.05)
    frames, board = percepts(renderer, pose, head, ball)
    truth = frames["top"].ball
    percept = board[BallPercept]
    assert max(f.ball_visible for f in frames.values()) > 0.9, "the scene must show the ball"
    assert percept.seen
    assert math.hypot(percept.x - truth[0], percept.y - truth[1]) < max(60.0, 0.08 * distance)


@pytest.mark.slow
@pytest.mark.parametrize("side", [1.0, -1.0])
def test_a_ball_half_out_of_the_image_is_still_found(renderer: SceneRenderer, side: float, request: pytest.FixtureRequest) -> None:
    if "pybullet" in request.node.name and side < 0:
        # known, and not hidden: since the candidates need the carpet's full green (real images, issue 31), no
        # candidate is proposed for PyBullet's ball cut by the image's right edge; MuJoCo's is found
        request.applymarker(pytest.mark.xfail(reason="PyBullet's ball cut by the right edge gets no candidate", strict=False))
    pose, ball = (-2000.0, 0.0, 0.0), (-500.0, 0.0)
    # turn the head until the ball sits on the image's edge, between half and nine tenths in view
    for yaw in np.arange(0.45, 0.6, 0.005):
        frames = renderer.frames(pose, (side * yaw, 0.1), ball)
        if 0.55 <= frames["top"].ball_visible <= 0.9:
            break
    else:
        pytest.fail("no head yaw puts the ball on the image's edge")
    perception = Perception()
    for _ in range(3):
        board = perception(frames)
    assert board[BallPercept].seen
    assert math.hypot(board[BallPercept].x - 1500.0, board[BallPercept].y) < 150.0


def test_a_ball_partly_behind_a_goal_post_is_still_found(renderer: SceneRenderer) -> None:
    post = field.goal_post_positions()[0]
    pose = (post[0] - 1200.0, post[1], 0.0)
    ball = (post[0] + 120.0, post[1] - 60.0)  # inside the goal, its left part hidden by the post
    frames, board = percepts(renderer, pose, (0.0, 0.3), ball)
    assert 0.5 <= frames["top"].ball_visible <= 0.9, frames["top"].ball_visible
    assert board[BallPercept].seen
    truth = frames["top"].ball
    assert math.hypot(board[BallPercept].x - truth[0], board[BallPercept].y - truth[1]) < 200.0


@pytest.mark.parametrize(("pose", "head"), [
    ((3000.0, 0.0, 0.0), (0.0, 0.25)),  # the penalty mark, the penalty area and the goal ahead
    ((-600.0, 0.0, 0.0), (0.0, 0.3)),  # the centre circle, the centre mark and the halfway line
    ((-4000.0, -2000.0, 0.8), (0.3, 0.3)),  # the penalty area's corner, the goal area, a post
    ((-1500.0, 0.0, 0.0), (0.0, 0.5)),  # looking down at the own feet
])
def test_no_ball_where_there_is_none(renderer: SceneRenderer, pose: tuple[float, float, float], head: tuple[float, float]) -> None:
    frames, board = percepts(renderer, pose, head, (pose[0] - 2000.0 * math.cos(pose[2]), pose[1] - 2000.0 * math.sin(pose[2])))
    assert max(f.ball_pixels for f in frames.values()) == 0
    assert not board[BallPercept].seen


@pytest.mark.slow
def test_the_orange_ball_needs_the_orange_detector() -> None:
    with SceneRenderer("mujoco", ball_color="orange") as scene:
        frames = scene.frames((-1500.0, 0.0, 0.0), (0.0, 0.25), (0.0, 100.0))
        assert not Perception("SPLBallDetector")(frames)[BallPercept].seen
        board = Perception("BallDetector")(frames)
        assert board[BallPercept].seen and math.hypot(board[BallPercept].x - 1500.0, board[BallPercept].y - 100.0) < 120.0


# ----------------------------------------------------------------------------- lines and posts
def to_field(pose: tuple[float, float, float], points: np.ndarray) -> np.ndarray:
    c, s = math.cos(pose[2]), math.sin(pose[2])
    return np.column_stack([pose[0] + c * points[:, 0] - s * points[:, 1], pose[1] + s * points[:, 0] + c * points[:, 1]])


@pytest.mark.parametrize(("pose", "head"), [((-2000.0, 300.0, 0.1), (0.0, 0.2)), ((-3300.0, -1800.0, 2.0), (-0.4, 0.3)),
                                            ((1200.0, 1000.0, -2.6), (0.3, 0.1))])
def test_line_points_lie_on_the_field_lines(renderer: SceneRenderer, pose: tuple[float, float, float], head: tuple[float, float]) -> None:
    _, board = percepts(renderer, pose, head, (5000.0, 3500.0))
    lines = board[LinePercept]
    points = np.asarray(lines.points, float)
    assert len(points) >= 30
    distance = FIELD_MODEL.line_distance(to_field(pose, points))
    assert np.median(distance) < 40.0 and np.mean(distance < 150.0) > 0.9
    assert lines.segments
    for segment in lines.segments:
        ends = to_field(pose, np.array([[segment.x1, segment.y1], [segment.x2, segment.y2]]))
        assert np.all(FIELD_MODEL.line_distance(ends) < 300.0)


def test_the_centre_circle_is_found_where_it_is(renderer: SceneRenderer) -> None:
    pose = (-1700.0, 200.0, 0.05)
    _, board = percepts(renderer, pose, (0.0, 0.2), (4000.0, 3000.0))
    lines = board[LinePercept]
    assert lines.circle_seen
    centre = to_field(pose, np.array([[lines.circle_x, lines.circle_y]]))[0]
    assert math.hypot(*centre) < 150.0


def test_both_posts_of_the_goal_ahead_are_found(renderer: SceneRenderer) -> None:
    pose = (2000.0, 300.0, 0.05)
    _, board = percepts(renderer, pose, (0.0, 0.0), (-4000.0, 0.0))
    posts = board[GoalPostPercept].posts
    assert len(posts) == 2
    true = np.array(field.goal_post_positions()[:2])
    for post in posts:
        where = to_field(pose, np.array([[post.x, post.y]]))[0]
        assert np.min(np.linalg.norm(true - where, axis=1)) < 0.06 * math.hypot(post.x, post.y)


def test_no_posts_where_there_are_none(renderer: SceneRenderer) -> None:
    _, board = percepts(renderer, (0.0, 0.0, math.pi / 2), (0.0, 0.1), (0.0, -1000.0))  # looking at the sideline
    assert board[GoalPostPercept].posts == []


# ---------------------------------------------------------------------------- the parts alone
def field_image(green: tuple[int, int, int], boundary_row: int = 80) -> np.ndarray:
    image = np.zeros((240, 320, 3), np.uint8)
    image[:] = (120, 118, 115)  # a grey wall
    image[boundary_row:] = green
    image[150:155, :] = 255  # a line
    return image


@pytest.mark.parametrize("green", [(45, 140, 50), (20, 80, 25), (90, 200, 70), (60, 150, 110)])
def test_the_field_colour_follows_the_light(green: tuple[int, int, int]) -> None:
    image = field_image(green)
    board = ModuleHarness(FieldColorProvider, CameraImageTop(image=image), CameraImageBottom(image=image)).execute()
    color, segmented = board[FieldColor], board[SegmentedImage]
    assert color.valid
    assert segmented.top_green[200:].mean() > 0.95  # the field
    assert segmented.top_green[:70].mean() == 0.0 and segmented.top_green[150:155].mean() == 0.0  # wall and line


def test_no_green_no_field_colour_and_no_crash() -> None:
    grey = np.full((240, 320, 3), 128, np.uint8)
    board = ModuleHarness(FieldColorProvider, CameraImageTop(image=grey), CameraImageBottom(image=np.zeros((0, 0, 3), np.uint8))).execute()
    assert not board[FieldColor].valid
    assert board[SegmentedImage].bottom_hsv.size == 0


@settings(max_examples=60, deadline=None)
@given(hue=st.integers(0, 179), tolerance=st.integers(1, 40), saturation_min=st.integers(0, 255), value_min=st.integers(0, 255))
def test_the_green_mask_is_a_hue_band_round_the_circle_above_saturation_and_value(hue: int, tolerance: int, saturation_min: int,
                                                                                 value_min: int) -> None:
    """Every hue within ``tolerance`` of the field's, counted round the circle (0 and 179 are neighbours), with
    saturation and value at least their minimums, and nothing else."""
    h, s, v = np.meshgrid(np.arange(180), [0, 1, 64, 127, 128, 254, 255], [0, 1, 64, 127, 128, 254, 255], indexing="ij")
    hsv = np.stack([h, s, v], axis=-1).reshape(180, -1, 3).astype(np.uint8)
    color = FieldColor(valid=True, hue=hue, hue_tolerance=tolerance, saturation_min=saturation_min, value_min=value_min)
    distance = np.minimum(np.abs(hsv[..., 0].astype(int) - hue), 180 - np.abs(hsv[..., 0].astype(int) - hue))
    expected = (distance <= tolerance) & (hsv[..., 1] >= saturation_min) & (hsv[..., 2] >= value_min)
    np.testing.assert_array_equal(green_mask(color, hsv), expected)


def test_the_boundary_ignores_what_stands_on_the_field() -> None:
    image = field_image((45, 140, 50), boundary_row=80)
    image[40:180, 150:165] = 255  # a post standing on the field, rising over the boundary
    board = ModuleHarness(FieldColorProvider, CameraImageTop(image=image), CameraImageBottom(image=image)).execute()
    rows = ModuleHarness(FieldBoundaryDetector, board[SegmentedImage], board[FieldColor]).execute()[FieldBoundary].top
    assert len(rows) == 320
    assert np.all(np.abs(rows - 80) <= 4)  # also behind the post


def test_green_in_the_hall_does_not_lift_the_boundary() -> None:
    """A green door or board beyond the carpet, with the hall's floor between (as in HULKs' lab), and a wide
    white line near the camera: the boundary stays on the carpet's edge."""
    image = field_image((45, 140, 50), boundary_row=120)
    image[30:100, 20:70] = (45, 140, 50)  # a green board on the wall, 20 px above the field's edge
    image[180:215, :] = 255  # a line close to the camera, taller than any gap the scan crosses
    board = ModuleHarness(FieldColorProvider, CameraImageTop(image=image), CameraImageBottom(image=image)).execute()
    rows = ModuleHarness(FieldBoundaryDetector, board[SegmentedImage], board[FieldColor]).execute()[FieldBoundary].top
    assert np.all(np.abs(rows - 120) <= 4)


def test_nothing_above_the_horizon_is_field() -> None:
    """With the camera's pose known, green above the horizon (a green wall) is no field."""
    image = field_image((45, 140, 50), boundary_row=0)  # green everywhere: the wall is green too
    matrix = CameraMatrix(np.array([[math.cos(0.2), 0, math.sin(0.2)], [0, 1, 0], [-math.sin(0.2), 0, math.cos(0.2)]]),
                          np.array([0.0, 0.0, 500.0]), True)
    fov = (math.radians(56.3), math.radians(43.7))
    top = CameraImageTop(image=image, horizontal_fov=fov[0], vertical_fov=fov[1])
    board = ModuleHarness(FieldColorProvider, top, CameraImageBottom(image=image)).execute()
    buffer = CameraMatrixBuffer.of(CameraMatrixTop(matrix.rotation, matrix.translation, True), CameraMatrixBottom(), 0)
    rows = ModuleHarness(FieldBoundaryDetector, board[SegmentedImage], board[FieldColor], top, buffer).execute()[FieldBoundary].top
    horizon = ImageProjection(matrix, 320, 240, *fov).horizon(160.0)
    assert 40 < horizon < 100  # the camera looks down by 0.2 rad: the horizon is in the upper half
    assert np.all(rows >= horizon - 0.03 * 240 - 4)


@pytest.fixture(scope="module")
def htwk_images() -> list[tuple[np.ndarray, tuple[float, float, float]]]:
    """Nao-Team HTWK's real images (tests/data/real_images, with their licence) at 320x240, with the labelled ball."""
    import csv
    from pathlib import Path

    folder = Path(__file__).parent / "data" / "real_images"
    found = []
    for row in csv.DictReader((folder / "labels.csv").open()):
        image = cv2.cvtColor(cv2.imread(str(folder / row["image"])), cv2.COLOR_BGR2RGB)
        found.append((cv2.resize(image, (320, 240), interpolation=cv2.INTER_AREA),
                      tuple(float(row[k]) / 2 for k in ("ball_x", "ball_y", "ball_r"))))
    return found


@pytest.mark.parametrize("index", [0, 1])
def test_real_balls_in_a_colour_cast_and_in_shadow_are_found(htwk_images, index: int) -> None:
    """A real ball among feet and lines, and a far one in the image's dark, teal-cast corner: the carpet's
    green shows faintly on the ball, and its white is darker than the carpet elsewhere."""
    image, (x, y, r) = htwk_images[index]
    fov = (math.radians(56.3), math.radians(43.7))
    board = None
    for pitch in (0.2, 0.27, 0.35):  # the pose is not known: the check must hold for a range of head pitches
        matrix = CameraMatrix(np.array([[math.cos(pitch), 0, math.sin(pitch)], [0, 1, 0], [-math.sin(pitch), 0, math.cos(pitch)]]),
                              np.array([0.0, 0.0, 503.0]), True)
        perception = Perception()
        view = SimpleNamespace(image=image, horizontal_fov=fov[0], vertical_fov=fov[1], matrix=matrix)
        empty = SimpleNamespace(image=np.zeros((0, 0, 3), np.uint8), horizontal_fov=0.0, vertical_fov=0.0, matrix=CameraMatrix())
        for _ in range(2):
            board = perception({"top": view, "bottom": empty})
        candidates = board[BallImagePercept].candidates
        assert any(math.hypot(c.x - x, c.y - y) <= r for c in candidates), (pitch, candidates)
        assert all(math.hypot(c.x - x, c.y - y) <= r for c in candidates), "nothing else is a ball"


@given(st.lists(st.tuples(st.floats(0, 300), st.floats(0, 200)), min_size=2, max_size=40, unique_by=lambda p: p[0]))
def test_lower_hull_is_convex_and_below_every_point(points: list[tuple[float, float]]) -> None:
    points.sort()
    xs, ys = np.array([p[0] for p in points]), np.array([p[1] for p in points])
    hx, hy = lower_hull(xs, ys)
    assert np.all(np.interp(xs, hx, hy) <= ys + 1e-6)
    apart = np.diff(hx) > 1e-3  # slopes between points that are not on top of each other
    slopes = np.diff(hy)[apart] / np.diff(hx)[apart]
    assert np.all(np.diff(slopes) >= -1e-6 * (1 + np.abs(slopes[1:])))


@given(yaw=st.floats(-1.0, 1.0), pitch=st.floats(0.1, 0.8), height=st.floats(300.0, 600.0),
       x=st.floats(0.0, 319.0), y=st.floats(0.0, 239.0))
@settings(max_examples=80)
def test_pixels_to_the_ground_and_back(yaw: float, pitch: float, height: float, x: float, y: float) -> None:
    cy, sy, cp, sp = math.cos(yaw), math.sin(yaw), math.cos(pitch), math.sin(pitch)
    rotation = np.array([[cy, -sy, 0], [sy, cy, 0], [0, 0, 1]]) @ np.array([[cp, 0, sp], [0, 1, 0], [-sp, 0, cp]])
    projection = ImageProjection(CameraMatrix(rotation, np.array([0.0, 0.0, height]), True), 320, 240, math.radians(60.97), math.radians(47.64))
    ground, hit = projection.to_ground(np.array([x]), np.array([y]))
    if not hit[0] or np.linalg.norm(ground[0]) > 50_000:
        return
    pixel, front = projection.to_image(np.array([[ground[0, 0], ground[0, 1], 0.0]]))
    assert front[0] and pixel[0] == pytest.approx([x, y], abs=1e-6)
    assert y > projection.horizon(x) - 1e-6  # what reaches the ground lies below the horizon


def test_white_runs_and_arcs() -> None:
    mask = np.zeros((10, 4), bool)
    mask[2:5, 0] = True
    mask[7:9, 0] = True
    mask[0:10, 2] = True
    x, first, last = white_runs(mask, step=2)
    assert sorted(zip(x.tolist(), first.tolist(), last.tolist())) == [(0, 2, 4), (0, 7, 8), (2, 0, 9)]
    assert longest_arc(np.radians(np.arange(0, 100, 5)), math.radians(15)) == pytest.approx(math.radians(95))
    assert longest_arc(np.radians([0, 60, 120, 180]), math.radians(15)) == 0.0
    assert longest_arc(np.array([]), 0.3) == 0.0


def test_the_spl_ball_is_white_with_black_pentagons() -> None:
    directions = np.random.default_rng(0).normal(size=(200_000, 3))
    directions /= np.linalg.norm(directions, axis=1, keepdims=True)
    share = ball_is_black(directions).mean()
    assert 0.25 < share < 0.31  # twelve pentagons of a truncated icosahedron: 28 % of the surface
    texture = ball_texture()
    assert texture.shape == (256, 512, 3) and texture.dtype == np.uint8
    grey = cv2.cvtColor(texture, cv2.COLOR_RGB2GRAY)
    assert (grey < 60).mean() > 0.15 and (grey > 200).mean() > 0.55


@pytest.mark.slow  # painting takes a second
def test_the_shipped_ball_texture_is_what_the_code_paints() -> None:
    """The simulators load platforms/assets/ball_texture.png; after a change to the painting, write it
    anew with python -m tafel.platforms.field_world."""
    np.testing.assert_array_equal(ball_texture(), paint_ball_texture())


# ------------------------------------------------------------------- real images at full resolution
def level_camera(pitch: float, height: float = 503.0) -> CameraMatrix:
    """A level camera ``height`` mm above the ground, pitched down by ``pitch`` rad (a standing NAO's top camera)."""
    return CameraMatrix(np.array([[math.cos(pitch), 0, math.sin(pitch)], [0, 1, 0], [-math.sin(pitch), 0, math.cos(pitch)]]),
                        np.array([0.0, 0.0, height]), True)


def perceive(image: np.ndarray, matrix: CameraMatrix, settle: int = 2, **parameters: object):
    """The perception modules on one top-camera image (the bottom one empty); ``parameters`` set on SPLBallDetector."""
    fov = (math.radians(56.3), math.radians(43.7))
    perception = Perception()
    for name, value in parameters.items():
        setattr(perception.manager.module("SPLBallDetector").parameters, name, value)
    view = SimpleNamespace(image=image, horizontal_fov=fov[0], vertical_fov=fov[1], matrix=matrix)
    empty = SimpleNamespace(image=np.zeros((0, 0, 3), np.uint8), horizontal_fov=0.0, vertical_fov=0.0, matrix=CameraMatrix())
    for _ in range(settle):
        board = perception({"top": view, "bottom": empty})
    return board


@pytest.mark.parametrize("pitch", [0.37, 0.4, 0.45])  # the ball's size implies 0.4; the pose is not known exactly
def test_a_real_ball_at_the_image_edge_is_found_at_full_resolution(pitch: float) -> None:
    """HTWK's ball at the image's left edge, 640x480, passes the checks once, as one candidate: dark corners at
    the image's bottom and copies of spots moved to the image's edge used up the candidate slots before it.
    (The checks alone: the classifier's verdict on this ball is measured by benchmarks/real_images.py.)"""
    from pathlib import Path

    path = Path(__file__).parent / "data" / "real_images" / "images" / "htwk" / "ChinaTest2015GAB03B_AnyBallTest3_00049806_U.png"
    image = cv2.cvtColor(cv2.imread(str(path)), cv2.COLOR_BGR2RGB)
    candidates = perceive(image, level_camera(pitch), classifier=False)[BallImagePercept].candidates
    assert any(math.hypot(c.x - 23, c.y - 215) <= 1.25 * 21 for c in candidates), candidates  # its centre is out of sight: estimated
    assert len(candidates) == 1, "one ball, reported once"


# ------------------------------------------------------------------------------ the ball classifier
def painted_candidates(rng: np.random.Generator, count: int) -> tuple[np.ndarray, np.ndarray]:
    """Rows of classifier features from painted 160x120 scenes: half an SPL-like ball (white, black
    patches round its centre) on the carpet, half a thing of the same size that is none (a joint, a foot)."""
    from tafel.modules.perception.ball_classifier import features
    from tafel.modules.perception.ball_spots import carpet
    from tafel.tools.simulation.train_ball_classifier import camera_like, distractors

    rows, labels = [], []
    for i in range(count):
        image = np.zeros((120, 160, 3), np.uint8)
        image[:] = (45, 140, 50)
        r = float(rng.uniform(5, 14))
        x, y = float(rng.uniform(30, 130)), float(rng.uniform(30, 90))
        if i % 2 == 0:
            cv2.circle(image, (int(x), int(y)), int(r), (235, 235, 235), -1)
            for angle in rng.uniform(0, 2 * math.pi, 4):
                cv2.circle(image, (int(x + 0.55 * r * math.cos(angle)), int(y + 0.55 * r * math.sin(angle))), max(1, int(0.25 * r)), (20, 20, 20), -1)
            cv2.circle(image, (int(x), int(y)), max(1, int(0.25 * r)), (20, 20, 20), -1)
        else:
            image = distractors(image, rng, None)
            # the candidate sits on whatever was painted: the first non-green pixel's neighbourhood
            ys, xs = np.nonzero(np.abs(image.astype(int) - (45, 140, 50)).sum(axis=2) > 60)
            if len(xs):
                pick = int(rng.integers(len(xs)))
                x, y = float(xs[pick]), float(ys[pick])
        image = camera_like(image, rng)
        hsv = cv2.cvtColor(image, cv2.COLOR_RGB2HSV)
        green = (hsv[..., 0] > 30) & (hsv[..., 0] < 90) & (hsv[..., 1] > 60)
        rows.append(features(hsv, green, x, y, r, *carpet(hsv, green)))
        labels.append(1 - i % 2)
    return np.array(rows), np.array(labels)


def test_the_classifier_learns_balls_from_a_tiny_data_set_and_saves_what_it_learned(tmp_path) -> None:
    from tafel.modules.perception.ball_classifier import BallClassifier, train

    rows, labels = painted_candidates(np.random.default_rng(0), 160)
    model = train(rows[:120], labels[:120], epochs=300)
    said = model.scores(rows[120:]) >= 0.0
    assert (said == (labels[120:] == 1)).mean() >= 0.85
    model.save(tmp_path / "model.npz")
    loaded = BallClassifier(tmp_path / "model.npz")
    assert np.allclose(loaded.scores(rows[120:]), model.scores(rows[120:]), atol=0.05 * (1 + np.abs(model.scores(rows[120:]))).max())
    again = train(rows[:120], labels[:120], epochs=300)
    assert np.array_equal(again.scores(rows[:5]), model.scores(rows[:5]))  # seeded: the same data, the same model


def test_the_classifier_says_what_is_wrong_with_its_input(tmp_path) -> None:
    from tafel.modules.perception.ball_classifier import FEATURES, BallClassifier, train

    with pytest.raises(FileNotFoundError, match="train_ball_classifier"):
        BallClassifier(tmp_path / "missing.npz")
    with pytest.raises(ValueError, match="both balls"):
        train(np.zeros((4, FEATURES)), np.zeros(4))
    with pytest.raises(ValueError, match=f"N x {FEATURES}"):
        train(np.zeros((4, 3)), np.array([0, 1, 0, 1]))


def test_the_shipped_classifier_is_small_and_shipped() -> None:
    import tomllib
    from pathlib import Path

    from tafel.modules.perception.ball_classifier import MODEL_PATH, BallClassifier

    assert MODEL_PATH.stat().st_size < 1_000_000
    BallClassifier()  # loads, with as many features as the code makes
    pyproject = tomllib.loads((Path(__file__).parent.parent / "pyproject.toml").read_text())
    assert MODEL_PATH.name in pyproject["tool"]["setuptools"]["package-data"]["tafel.modules.perception"]


@pytest.mark.slow
def test_the_training_script_trains_on_renders_and_real_images(tmp_path) -> None:
    from tafel.modules.perception.ball_classifier import BallClassifier
    from tafel.tools.simulation.train_ball_classifier import main

    out = tmp_path / "model.npz"
    main(["--scenes", "3", "--real", str(Path(__file__).parent / "data" / "real_images"), "--real-variants", "1", "--epochs", "50",
          "--out", str(out)])
    assert BallClassifier(out).scores(np.zeros((2, BallClassifier(out).w1.shape[0]))).shape == (2,)


# ------------------------------------------------------------------------------------ goal posts
def test_the_goals_rear_frame_is_no_post() -> None:
    """A post of the width a 100 mm post has at its foot's distance, and behind it the goal's rear frame: a
    pipe half as wide, whose foot the scan finds too near (where the carpet ends in front of it)."""
    matrix = level_camera(0.3)
    fov = (math.radians(56.3), math.radians(43.7))
    projection = ImageProjection(matrix, 640, 480, *fov)
    image = np.zeros((480, 640, 3), np.uint8)
    image[:] = (120, 118, 115)
    image[150:] = (45, 140, 50)
    posts = {}
    for name, x, foot in (("post", 200, 230), ("rear", 420, 225)):
        ground, _ = projection.to_ground(np.array([x + 0.5]), np.array([foot + 0.5]))
        distance = float(np.linalg.norm(np.append(ground[0], 0.0) - projection.translation))
        width = projection.fx * field.GOAL_POST_DIAMETER / distance * (1.0 if name == "post" else 0.5)
        posts[name] = (x, width)
        image[20 : foot + 1, int(x - width / 2) : int(x + width / 2) + 1] = 235
    found = perceive(image, matrix)[GoalPostPercept].posts
    assert [round(p.image_x) for p in found] == [pytest.approx(200, abs=3)], found


SHARED_IMAGES = Path(__file__).resolve().parent.parent.parent / "shared" / "real-images"


def test_a_real_goals_rear_frame_is_not_taken_for_its_post() -> None:
    """HULKs' image of a goal seen from beside it, with the camera matrix the robot recorded: the hall's pale
    floor is as unsaturated as the post, and the goal's rear frame stands behind the post. Reported were the
    rear frame's pipe (column 237, its foot on the carpet's far edge at row 221) and not the post (columns
    258 to 285, its foot on the goal line at row 252). (HULKs' images are GPL-3.0: read from
    ../shared/real-images, not copied here.)"""
    from tafel.platforms.images import posed_image

    path = SHARED_IMAGES / "images" / "hulks" / "1687084038.jpg"
    if not path.is_file():
        pytest.skip(f"the labelled real images are not at {SHARED_IMAGES} (see its README)")
    posed = posed_image(path, camera="top")
    perception = Perception()
    view = SimpleNamespace(image=posed.image, horizontal_fov=posed.horizontal_fov, vertical_fov=posed.vertical_fov, matrix=posed.matrix)
    empty = SimpleNamespace(image=np.zeros((0, 0, 3), np.uint8), horizontal_fov=0.0, vertical_fov=0.0, matrix=CameraMatrix())
    for _ in range(2):
        board = perception({"top": view, "bottom": empty})
    posts = board[GoalPostPercept].posts
    assert [(round(p.image_x), round(p.image_foot)) for p in posts] == [(pytest.approx(271, abs=8), pytest.approx(253, abs=6))], posts


def test_a_ball_cut_by_the_image_edge_is_centred_on_what_is_seen() -> None:
    """A ball cut by the image's left edge, its dark shadow beside it: the distance transform's peak lies
    between the ball and the shadow; the circle fitted to the ball's visible outline is the ball."""
    from tafel.modules.perception.ball_checks import fit_visible, near_edge
    from tafel.modules.perception.ball_spots import Spot

    image = np.zeros((120, 160, 3), np.uint8)
    image[:] = (45, 140, 50)
    cv2.circle(image, (10, 60), 30, (30, 40, 30), -1)  # the shadow, below and right of the ball
    cv2.circle(image, (4, 50), 20, (230, 230, 230), -1)  # the ball: its centre 4 px in, a fifth of it out of sight
    for angle in (0.5, 2.0, 3.5, 5.0):
        cv2.circle(image, (int(4 + 11 * math.cos(angle)), int(50 + 11 * math.sin(angle))), 4, (20, 20, 20), -1)
    hsv = cv2.cvtColor(image, cv2.COLOR_RGB2HSV)
    green = (hsv[..., 0] > 30) & (hsv[..., 0] < 90) & (hsv[..., 1] > 60)
    spot = Spot(12.0, 58.0, 24.0, 20.0)  # where the peak of ball and shadow together is
    assert near_edge(spot, green.shape)
    fitted = fit_visible(hsv, green, spot)
    assert fitted is not None and math.hypot(fitted.x - 4, fitted.y - 50) < 2.0, fitted
    assert not near_edge(Spot(80.0, 60.0, 10.0, 10.0), green.shape)


@pytest.mark.parametrize("pitch", [0.4, 0.42, 0.45])  # the ball's size implies 0.4; the pose is not known exactly
def test_a_real_ball_cut_by_the_image_edge_passes_the_classifier_too(pitch: float) -> None:
    """HTWK's ball at the left edge at 640x480, with the classifier: its shadow pulled the candidate 18 px
    off the ball, and the classifier turned the off-centre square down; centred on the ball's visible
    outline, it is reported where it is."""
    path = Path(__file__).parent / "data" / "real_images" / "images" / "htwk" / "ChinaTest2015GAB03B_AnyBallTest3_00049806_U.png"
    image = cv2.cvtColor(cv2.imread(str(path)), cv2.COLOR_BGR2RGB)
    candidates = perceive(image, level_camera(pitch))[BallImagePercept].candidates
    assert len(candidates) == 1 and math.hypot(candidates[0].x - 23, candidates[0].y - 215) <= 0.5 * 21, candidates

def test_the_field_colour_comes_from_below_the_horizon() -> None:
    """A robot looking up: the top image's lower half is mostly a teal door in the hall, the carpet only
    below the horizon. The field colour is the carpet's."""
    matrix = level_camera(-0.25)  # looking up: the horizon low in the image
    fov = (math.radians(56.3), math.radians(43.7))
    horizon = ImageProjection(matrix, 320, 240, *fov).horizon(160.0)
    assert 170 < horizon < 220
    image = np.zeros((240, 320, 3), np.uint8)
    image[:] = (120, 118, 115)
    image[100 : int(horizon) + 6] = (30, 150, 140)  # the door, down to the carpet's far edge
    image[int(horizon) + 6 :] = (45, 140, 50)
    top = CameraImageTop(image=image, horizontal_fov=fov[0], vertical_fov=fov[1])
    buffer = CameraMatrixBuffer.of(CameraMatrixTop(matrix.rotation, matrix.translation, True), CameraMatrixBottom(), 0)
    board = ModuleHarness(FieldColorProvider, top, CameraImageBottom(image=np.zeros((0, 0, 3), np.uint8)), buffer).execute()
    green = board[SegmentedImage].top_green
    assert green[int(horizon) + 10 :].mean() > 0.95  # the carpet
    assert green[100 : int(horizon)].mean() < 0.05  # not the door
