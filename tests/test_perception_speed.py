"""The perception modules' vectorized steps (issue 34) against the loops they replaced, kept here as the
reference: the same output on painted scenes drawn by hypothesis (balls with black patches, lines,
posts over the field's edge, dark corners), and for the goal posts on every real image of
../shared/real-images (MuJoCo renders where it is absent). The real-image figures are benchmarks/real_images.py's."""

from __future__ import annotations

import csv
import math
from collections.abc import Iterator
from pathlib import Path
from types import SimpleNamespace
from typing import Any

import cv2
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tafel.core.framework.manager import make_module
from tafel.modules.modeling.field_model import FIELD_MODEL
from tafel.modules.modeling.particle_filter import seen_from
from tafel.modules.modeling.pose_measurements import robust
from tafel.modules.perception import ball_checks, ball_spots
from tafel.modules.perception.ball_checks import (
    LOOSER_TESTS,
    alone_on_dark_carpet,
    beside_post,
    carpet_below_post,
    check,
    post_columns,
    under_post,
    verdict,
)
from tafel.modules.perception.ball_spots import (
    Spot,
    ball_ranges,
    carpet,
    carpet_light,
    carpet_sample,
    dark_pixels,
    dark_share,
    inside_image,
    spots,
    strict_green,
)
from tafel.modules.perception.far_ball_spots import centroids, edge_spots, green_below, white_halves
from tafel.modules.perception.field_boundary_detector import cell_shares, chain, lower_hull
from tafel.modules.perception.goal_post_band import band_checks, band_passes, edge_peaks
from tafel.modules.perception.goal_post_detector import GoalPostDetector
from tafel.modules.perception.goal_post_shapes import exact_norms, rising_rows, runs_of_rows, segment_medians, strip_means, strip_sums
from tafel.modules.perception.image_geometry import BODY_POINTS, BODY_POINTS_ALL, ImageProjection, camera_views, own_body_mask, rows_times
from tafel.modules.perception.line_detector import CIRCLE_RADIUS, LineDetector, green_on_both_sides, longest_arc, white_runs
from tafel.modules.perception.pixel_statistics import (
    below,
    byte_median,
    byte_percentile,
    channel_histogram,
    every,
    histogram_median,
    histogram_percentile,
    white_pixels,
)
from tafel.modules.perception.spl_ball_detector import SPLBallDetector
from tafel.platforms.images import posed_image
from tafel.representations.field import BALL_RADIUS, GOAL_HEIGHT, GOAL_POST_DIAMETER
from tafel.representations.motion import CameraMatrix, CameraMatrixBuffer
from tafel.representations.perception import (
    BallCandidate,
    BallImagePercept,
    CameraImageBottom,
    CameraImageTop,
    FieldBoundary,
    GoalPost,
    GoalPostPercept,
    LinePercept,
    LineSegment,
    SegmentedImage,
)
from tafel.tools.simulation.scene_frames import Perception


def level_projection(width: int, height: int, pitch: float) -> ImageProjection:
    """A standing NAO's top camera (503 mm up, pitched down by ``pitch``) seeing ``width`` x ``height`` px."""
    rotation = np.array([[math.cos(pitch), 0, math.sin(pitch)], [0, 1, 0], [-math.sin(pitch), 0, math.cos(pitch)]])
    return ImageProjection(CameraMatrix(rotation, np.array([0.0, 0.0, 503.0]), True), width, height, math.radians(56.3), math.radians(43.7))


def scene(seed: int, width: int, height: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, float]:
    """(hsv, green, boundary rows, white) of a painted field: carpet below a wavy edge, the hall above,
    balls with black patches (some cut by the image's edge), lines, posts rising over the edge, dark blobs."""
    rng = np.random.default_rng(seed)
    image = np.empty((height, width, 3), np.uint8)
    image[:] = (40 + rng.integers(-15, 15), 140 + rng.integers(-30, 30), 50 + rng.integers(-15, 15))
    edge = int(rng.integers(0, height // 2))
    image[:edge] = rng.integers(60, 200, 3)
    for _ in range(int(rng.integers(0, 4))):  # lines
        a = (int(rng.integers(0, width)), int(rng.integers(edge, height)))
        b = (int(rng.integers(0, width)), int(rng.integers(edge, height)))
        cv2.line(image, a, b, (235, 235, 235), int(rng.integers(1, 6)))
    for _ in range(int(rng.integers(0, 3))):  # posts over the field's edge
        x, w = int(rng.integers(0, width)), int(rng.integers(2, 10))
        cv2.rectangle(image, (x, 0), (x + w, edge + int(rng.integers(0, height // 3))), (225, 225, 225), -1)
    for _ in range(int(rng.integers(0, 4))):  # balls
        x, y, r = int(rng.integers(-5, width + 5)), int(rng.integers(edge - 5, height + 5)), int(rng.integers(2, 18))
        cv2.circle(image, (x, y), r, (240, 240, 240), -1)
        for angle in rng.uniform(0, 2 * math.pi, 3):
            cv2.circle(image, (int(x + 0.5 * r * math.cos(angle)), int(y + 0.5 * r * math.sin(angle))), max(1, r // 4), (25, 25, 25), -1)
    for _ in range(int(rng.integers(0, 3))):  # dark blobs and shadows
        cv2.circle(image, (int(rng.integers(0, width)), int(rng.integers(0, height))), int(rng.integers(2, 20)), (30, 50, 30), -1)
    image = np.clip(image.astype(int) + rng.integers(-12, 13, image.shape), 0, 255).astype(np.uint8)
    hsv = cv2.cvtColor(image, cv2.COLOR_RGB2HSV)
    green = (hsv[..., 0] > 35) & (hsv[..., 0] < 85) & (hsv[..., 1] > 60) & (hsv[..., 2] > 40)
    boundary = np.clip(edge + rng.normal(0, 3, width), 0, height).astype(np.float32)
    return hsv, green, boundary, float(hsv[..., 2].max())


scenes = st.builds(scene, st.integers(0, 2**32 - 1), st.integers(24, 120), st.integers(24, 100))


# ------------------------------------------------------------ SPLBallDetector: the loops as they were
def reference_dark_pixels(self: SPLBallDetector, hsv: np.ndarray, green: np.ndarray) -> np.ndarray | None:
    sampled = hsv[::4, ::4, 2][green[::4, ::4]]
    if sampled.size < 10:
        return None
    return hsv[..., 2] < self.parameters.black_contrast * float(np.median(sampled))


def reference_carpet(hsv: np.ndarray, green: np.ndarray) -> tuple[float, float]:
    sampled = carpet_sample(hsv, green)
    if len(sampled) < 10:
        return 128.0, 128.0
    return float(np.median(sampled[:, 2])), float(np.median(sampled[:, 1]))


def reference_strict_green(self: SPLBallDetector, hsv: np.ndarray, green: np.ndarray) -> np.ndarray:
    if not green.any():
        return green
    saturation = hsv[..., 1]
    sampled = saturation[::4, ::4][green[::4, ::4]]
    median = float(np.median(sampled)) if sampled.size else float(np.median(saturation[green]))
    return green & (saturation >= self.parameters.strict_saturation * median)


def reference_dark_share(dark: np.ndarray, xs: np.ndarray, ys: np.ndarray, radii: np.ndarray) -> np.ndarray:
    height, width = dark.shape
    integral = cv2.integral(dark.astype(np.uint8))
    x0, x1 = np.clip((xs - radii).astype(int), 0, width), np.clip((xs + radii).astype(int) + 1, 0, width)
    y0, y1 = np.clip((ys - radii).astype(int), 0, height), np.clip((ys + radii).astype(int) + 1, 0, height)
    area = np.maximum((x1 - x0) * (y1 - y0), 1)
    return (integral[y1, x1] - integral[y0, x1] - integral[y1, x0] + integral[y0, x0]) / area


def reference_spots(self: SPLBallDetector, green: np.ndarray, boundary: np.ndarray, projection: ImageProjection,
                    dark: np.ndarray | None = None) -> list[Spot]:
    p = self.parameters
    height, width = green.shape
    known = boundary.size == width
    top = max(0, int(boundary.min() - p.above_boundary)) if known else 0
    field = np.arange(top, height)[:, None] >= boundary[None, :] - p.above_boundary if known else np.ones((height - top, width), bool)
    solid = (~green[top:] & field).astype(np.uint8)
    if not solid.any():
        return []
    thickness = cv2.distanceTransform(solid, cv2.DIST_L2, 3)
    peaks = (thickness >= p.min_radius) & (thickness >= cv2.dilate(thickness, np.ones((3, 3), np.uint8)))
    ys, xs = np.nonzero(peaks)
    if len(xs) == 0:
        return []
    radii = thickness[ys, xs]
    ys = ys + top
    centres, hits = projection.to_ground(xs, ys, BALL_RADIUS)
    points = np.column_stack([centres, np.full(len(xs), BALL_RADIUS)])
    distance = np.linalg.norm(points - projection.translation, axis=1)
    expected = np.where(hits, projection.fx * BALL_RADIUS / np.maximum(distance, 1.0), 0.0)
    fits = hits & (radii >= p.size_low * expected) & (radii <= p.size_high * expected + 1.0)
    if known:
        fits &= ys >= boundary[xs]
    if dark is not None:
        fits &= reference_dark_share(dark, xs, ys, np.clip(radii, 1.0, max(height, width))) >= p.dark_spot_min
    order = np.argsort(np.abs(np.log(np.maximum(radii[fits], 0.5) / np.maximum(expected[fits], 0.5))))
    chosen: list[Spot] = []
    for x, y, r, e in zip(xs[fits][order], ys[fits][order], radii[fits][order], expected[fits][order]):
        if all((x - s.x) ** 2 + (y - s.y) ** 2 > (s.expected * 1.5) ** 2 for s in chosen):
            spot = Spot(float(x), float(y), float(max(r, 0.5 * (r + e))), float(e))
            if spot.x < e or spot.x > width - 1 - e or spot.y > height - 1 - e:
                spot = inside_image(spot, ~green)
                if any((spot.x - s.x) ** 2 + (spot.y - s.y) ** 2 <= (s.expected * 1.5) ** 2 for s in chosen):
                    continue
            chosen.append(spot)
            if len(chosen) >= p.max_spots:
                break
    return chosen


def reference_green_below(green: np.ndarray, x: float, y: float, radius: float) -> float:
    height, width = green.shape
    reach = int(math.ceil(1.7 * radius)) + 1
    x0, x1 = max(0, int(x) - reach), min(width, int(x) + reach + 1)
    y0, y1 = max(0, int(y)), min(height, int(y) + reach + 1)
    if x1 <= x0 or y1 <= y0:
        return 0.0
    yy, xx = np.mgrid[y0:y1, x0:x1]
    d = np.hypot(xx - x, yy - y)
    ring = (d >= 1.2 * radius) & (d <= 1.7 * radius) & (yy > y)
    return float(green[y0:y1, x0:x1][ring].mean()) if ring.any() else 0.0


def reference_white_halves(value: np.ndarray, x: float, y: float, radius: float) -> float:
    height, width = value.shape
    reach = int(math.ceil(radius))
    x0, x1 = max(0, int(round(x)) - reach), min(width, int(round(x)) + reach + 1)
    y0, y1 = max(0, int(round(y)) - reach), min(height, int(round(y)) + reach + 1)
    yy, xx = np.mgrid[y0:y1, x0:x1]
    disc = (xx - x) ** 2 + (yy - y) ** 2 <= radius**2
    patch = value[y0:y1, x0:x1]
    if not disc.any():
        return 0.0
    white = patch >= 0.6 * float(patch[disc].max())
    shares = [float(white[disc & side].mean()) for side in (xx < x, xx > x) if (disc & side).any()]
    return min(shares) if len(shares) == 2 else 0.0


def reference_centroid(mask: np.ndarray, x: float, y: float, radius: float) -> tuple[float, float]:
    height, width = mask.shape
    reach = int(math.ceil(radius))
    x0, x1 = max(0, int(round(x)) - reach), min(width, int(round(x)) + reach + 1)
    y0, y1 = max(0, int(round(y)) - reach), min(height, int(round(y)) + reach + 1)
    yy, xx = np.mgrid[y0:y1, x0:x1]
    near = (mask[y0:y1, x0:x1] > 0) & ((xx - x) ** 2 + (yy - y) ** 2 <= radius**2)
    if not near.any():
        return x, y
    return float(xx[near].mean()), float(yy[near].mean())


def reference_edge_spots(self: SPLBallDetector, hsv: np.ndarray, green: np.ndarray, boundary: np.ndarray, projection: ImageProjection,
                         carpet_value: float, taken: list[Spot]) -> list[Spot]:
    """The band search over the whole band (every column, down to its lowest row), one candidate after the other."""
    p = self.parameters
    height, width = green.shape
    if boundary.size != width:
        return []
    columns = np.linspace(0, width - 1, 9).astype(int)
    centres, hits = projection.to_ground(columns, np.minimum(boundary[columns], height - 1), BALL_RADIUS)
    ranges = np.linalg.norm(np.column_stack([centres, np.full(len(columns), BALL_RADIUS)]) - projection.translation, axis=1)
    if not (hits & (projection.fx * BALL_RADIUS / np.maximum(ranges, 1.0) <= p.edge_max_radius)).any():
        return []
    top = max(0, int(boundary.min()) - p.edge_above)
    bottom = min(height, int(boundary.max()) + p.edge_below + 1)
    if bottom - top < 3:
        return []
    rows = np.arange(top, bottom)[:, None]
    band = (rows >= boundary[None, :] - p.edge_above) & (rows <= boundary[None, :] + p.edge_below)
    value, saturation = hsv[top:bottom, :, 2], hsv[top:bottom, :, 1]
    black = value <= p.edge_black * carpet_value
    white = (value >= p.edge_white * carpet_value) & (saturation <= p.saturation_max)
    ballish = (cv2.morphologyEx(((white | black) & ~green[top:bottom]).astype(np.uint8), cv2.MORPH_CLOSE, np.ones((3, 3), np.uint8))
               & band.astype(np.uint8))
    if not ballish.any():
        return []
    thickness = cv2.distanceTransform(ballish, cv2.DIST_L2, 3)
    peaks = (thickness >= p.min_radius) & (thickness >= cv2.dilate(thickness, np.ones((3, 3), np.uint8)))
    ys, xs = np.nonzero(peaks)
    if len(xs) == 0:
        return []
    radii = thickness[ys, xs]
    centres, hits = projection.to_ground(xs, ys + top, BALL_RADIUS)
    points = np.column_stack([centres, np.full(len(xs), BALL_RADIUS)])
    distance = np.linalg.norm(points - projection.translation, axis=1)
    expected = np.where(hits, projection.fx * BALL_RADIUS / np.maximum(distance, 1.0), 0.0)
    fits = hits & (expected <= p.edge_max_radius) & (radii >= p.size_low * expected) & (radii <= p.size_high * expected + 1.0)
    if not fits.any():
        return []
    xs, ys, radii, expected = xs[fits], ys[fits], radii[fits], expected[fits]
    patched = reference_dark_share(black, xs, ys, np.maximum(radii, 1.0)) >= p.dark_spot_min
    xs, ys, radii, expected = xs[patched], ys[patched] + top, radii[patched], expected[patched]
    order = np.argsort(np.abs(np.log(np.maximum(radii, 0.5) / np.maximum(expected, 0.5))))
    chosen: list[Spot] = []
    for i in order[: 10 * p.edge_max_spots]:
        x, y, r, e = float(xs[i]), float(ys[i]), float(radii[i]), float(expected[i])
        if any((x - s.x) ** 2 + (y - s.y) ** 2 <= (max(s.expected, e) * 1.5) ** 2 for s in (*taken, *chosen)):
            continue
        for _ in range(2):
            x, y = reference_centroid(ballish, x, y - top, e)
            y += top
        if reference_green_below(green, x, y, e) < p.edge_green_below:
            continue
        if reference_white_halves(value, x, y - top, e) < p.edge_white_halves:
            continue
        chosen.append(Spot(x, y, max(r, e), e, edge=True))
        if len(chosen) >= p.edge_max_spots:
            break
    return chosen


def reference_check(self: SPLBallDetector, hsv: np.ndarray, green: np.ndarray, spot: Spot, white: float,
                    beside_post: bool = False) -> tuple[float, bool]:
    p = self.parameters
    height, width = green.shape
    r = spot.radius
    reach = int(math.ceil(r * 1.7)) + 1
    x0, x1 = max(0, int(spot.x) - reach), min(width, int(spot.x) + reach + 1)
    y0, y1 = max(0, int(spot.y) - reach), min(height, int(spot.y) + reach + 1)
    yy, xx = np.mgrid[y0:y1, x0:x1]
    d = np.hypot(xx - spot.x, yy - spot.y)
    inside, around = d <= 0.9 * r, (d >= 1.2 * r) & (d <= 1.7 * r)
    if inside.sum() < 3 or around.sum() < 3:
        return 0.0, False
    patch_green, patch = green[y0:y1, x0:x1], hsv[y0:y1, x0:x1]
    green_inside, green_around = patch_green[inside].mean(), patch_green[around].mean()
    solid = inside & ~patch_green
    if solid.sum() < 3:
        return 0.0, False
    value = patch[..., 2][solid].astype(float)
    bright = np.percentile(value, 90)
    dark = float((value < p.dark_ratio * bright).mean())
    saturation = float(patch[..., 1][inside].mean())
    carpet = patch[..., 2][around & patch_green]
    field_value = float(np.median(carpet if carpet.size >= 3 else patch[..., 2][around]))
    black = value[value < p.dark_ratio * bright]
    darkest = float(black.mean()) if black.size else math.inf
    first, posts = post_columns(hsv, green, spot, white, self.parameters)
    if (not beside_post and 0 <= int(spot.x) - first < len(posts) and posts[int(spot.x) - first]
            and not carpet_below_post(green, spot)):
        return 0.0, True
    if (green_inside > p.green_inside_max or green_around < p.green_around_min or not p.dark_share_min <= dark <= p.dark_share_max
            or saturation > p.saturation_max
            or (darkest > p.black_contrast * field_value and not alone_on_dark_carpet(green, spot, bright, field_value, green_around, p))):
        return 0.0, False
    return float(min(1.0, 0.5 + dark + 0.3 * green_around - green_inside)), False


def reference_beside_post(self: SPLBallDetector, hsv: np.ndarray, green: np.ndarray, spot: Spot, white: float) -> Spot | None:
    first, posts = post_columns(hsv, green, spot, white, self.parameters)
    height, width = green.shape
    post = np.nonzero(posts)[0]
    if len(post) == 0:
        return None
    best: tuple[int, float, int] | None = None
    for row in range(max(0, int(spot.y - 2 * spot.radius)), min(height, int(spot.y + 2 * spot.radius) + 1)):
        solid = ~green[row]
        solid[first : first + len(posts)] &= ~posts
        for edge, step in ((first + int(post.max()) + 1, 1), (first + int(post.min()) - 1, -1)):
            if not (0 <= edge < width and solid[edge]):
                continue
            far = edge
            while 0 <= far + step < width and solid[far + step]:
                far += step
            extent = abs(far - edge) + 1
            if extent <= 2 * spot.expected + 2 and (best is None or extent > best[0]):
                best = (extent, far - step * spot.expected, row)
    if best is None or best[0] < 0.5 * spot.expected:
        return None
    return Spot(float(best[1]), float(best[2]), spot.expected, spot.expected)


def detector() -> SPLBallDetector:
    return make_module(SPLBallDetector, parameters=SPLBallDetector.Parameters())  # type: ignore[return-value]


def same_spots(a: list[Spot], b: list[Spot]) -> None:
    assert [(s.x, s.y, s.radius, s.expected) for s in a] == [(s.x, s.y, s.radius, s.expected) for s in b]


@settings(max_examples=300)
@given(st.integers(0, 2**32 - 1), st.sampled_from([0, 1, 2]),
       st.one_of(st.floats(-300.0, 600.0), st.integers(-2, 258).map(float), st.sampled_from([math.inf, -math.inf, math.nan])))
def test_below_is_numpys_comparison(seed: int, channel: int, threshold: float) -> None:
    hsv = np.random.default_rng(seed).integers(0, 256, (7, 9, 3)).astype(np.uint8)
    mask = below(hsv, channel, threshold)
    assert mask.dtype == np.bool_
    np.testing.assert_array_equal(mask, hsv[..., channel] < threshold)


@settings(max_examples=150)
@given(scenes, st.floats(0.05, 0.6))
def test_spl_candidates_are_the_loops(painted: tuple[np.ndarray, np.ndarray, np.ndarray, float], pitch: float) -> None:
    """The light measures, the spots and the check of each (beside posts too) as the loops found them."""
    hsv, green, boundary, white = painted
    height, width = green.shape
    self = detector()
    projection = level_projection(width, height, pitch)
    sampled = carpet_light(hsv, green)
    strict = strict_green(hsv, green, self.parameters, sampled)
    np.testing.assert_array_equal(strict, reference_strict_green(self, hsv, green))
    dark, old_dark = dark_pixels(hsv, green, self.parameters, sampled), reference_dark_pixels(self, hsv, green)
    assert (dark is None) == (old_dark is None)
    if dark is not None:
        np.testing.assert_array_equal(dark, old_dark)
    assert carpet(hsv, green, sampled) == carpet(hsv, green) == reference_carpet(hsv, green)
    for rows in (boundary, np.zeros(0, np.float32)):
        found = spots(strict, rows, projection, self.parameters, dark)
        same_spots(found, reference_spots(self, strict, rows, projection, old_dark))
        few = ball_spots.FEW_PEAKS
        try:  # the greedy choice over many peaks (numpy's) as over few (a Python loop)
            ball_spots.FEW_PEAKS = -1
            same_spots(spots(strict, rows, projection, self.parameters, dark), found)
        finally:
            ball_spots.FEW_PEAKS = few
    for spot in found:
        for beside in (False, True):
            assert check(hsv, green, spot, white, self.parameters, beside) == reference_check(self, hsv, green, spot, white, beside)
        moved, old = beside_post(hsv, green, spot, white, self.parameters), reference_beside_post(self, hsv, green, spot, white)
        same_spots([moved] if moved else [], [old] if old else [])


@settings(max_examples=200)
@given(scenes, st.data())
def test_spl_checks_anywhere_are_the_loops(painted: tuple[np.ndarray, np.ndarray, np.ndarray, float], data: st.DataObject) -> None:
    """The check and the look beside a post for spots anywhere, of any size, at the image's edges too."""
    hsv, green, _, white = painted
    height, width = green.shape
    self = detector()
    for _ in range(5):
        x, y = data.draw(st.floats(-3.0, width + 2.0)), data.draw(st.floats(-3.0, height + 2.0))
        spot = Spot(x, y, data.draw(st.floats(0.5, 25.0)), data.draw(st.floats(0.5, 25.0)))
        for beside in (False, True):
            assert check(hsv, green, spot, white, self.parameters, beside) == reference_check(self, hsv, green, spot, white, beside)
        moved, old = beside_post(hsv, green, spot, white, self.parameters), reference_beside_post(self, hsv, green, spot, white)
        same_spots([moved] if moved else [], [old] if old else [])
        score, _, failed = verdict(hsv, green, spot, white, self.parameters)
        if score == 0.0 and failed not in LOOSER_TESTS:  # the second look, left out for such spots, would turn them down
            assert check(hsv, green, spot, white, self.parameters, parameters=self.looser())[0] == 0.0


#: the band search's parameters that let the most candidates through to its last checks (where the loops ran)
LOOSE_BAND = {"dark_spot_min": 0.0, "edge_green_below": 0.0, "edge_white_halves": 0.0, "edge_max_spots": 20}


def same_band_spots(self: SPLBallDetector, hsv: np.ndarray, green: np.ndarray, boundary: np.ndarray, projection: ImageProjection,
                    taken: list[Spot]) -> int:
    """The band search's spots, asserted those of the loops over the whole band, with the module's parameters and with
    ``LOOSE_BAND``; how many the loose search found."""
    sampled = carpet_light(hsv, green)
    if sampled.count < 10:
        return 0
    strict, value = strict_green(hsv, green, self.parameters, sampled), byte_median(carpet_sample(hsv, green)[:, 2])
    found = 0
    for loose in (False, True):
        if loose:
            self.parameters = SPLBallDetector.Parameters(**LOOSE_BAND)
        band = edge_spots(hsv, strict, boundary, projection, value, list(taken), self.parameters)
        same_spots(band, reference_edge_spots(self, hsv, strict, boundary, projection, value, list(taken)))
        assert all(spot.edge for spot in band)
        found = len(band)
    self.parameters = SPLBallDetector.Parameters()
    return found


@settings(max_examples=60, deadline=None)
@given(st.integers(0, 2**32 - 1), st.sampled_from([(640, 480), (320, 240), (120, 90)]), st.floats(-0.05, 0.35))
def test_the_band_search_is_the_loops_over_the_whole_band(seed: int, size: tuple[int, int], pitch: float) -> None:
    """Painted scenes seen level to pitched down: the band search narrowed to where a ball is small finds the spots that
    the search of the whole band, one candidate after the other, found."""
    hsv, green, boundary, _ = scene(seed, *size)
    self = detector()
    projection = level_projection(*size, pitch)
    taken = spots(green, boundary, projection, self.parameters)[:3]
    same_band_spots(self, hsv, green, boundary, projection, taken)


@settings(max_examples=200)
@given(st.integers(0, 2**32 - 1), st.integers(1, 40), st.integers(1, 40), st.integers(0, 12), st.integers(1, 12))
def test_the_band_candidates_measures_at_once_are_each_ones(seed: int, height: int, width: int, left: int, count: int) -> None:
    """Centroids, the carpet below and the white halves of many points at once: to the last bit the loops' for each,
    for points anywhere in the image, of radii from under a pixel to a dozen, whole and half-way ones too."""
    rng = np.random.default_rng(seed)
    mask = rng.random((height, width)) < rng.random()
    value = rng.integers(0, 256, (height, width)).astype(np.uint8)
    xs = rng.uniform(0, width - 1, count)
    ys = rng.uniform(0, height - 1, count)
    halves = rng.random(count) < 0.3
    xs[halves], ys[halves] = np.round(xs[halves] * 2) / 2, np.round(ys[halves] * 2) / 2
    radii = np.where(rng.random(count) < 0.3, rng.integers(1, 10, count).astype(float), rng.uniform(0.3, 12.0, count))
    shifted = np.zeros((height, left + width), np.uint8)  # the mask as the columns from ``left`` on of a wider image
    shifted[:, left:] = mask
    x, y = centroids(mask.view(np.uint8), xs + left, ys, radii, left)
    below, whites = green_below(mask, xs, ys, radii), white_halves(value, xs, ys, radii)
    for i in range(count):
        assert (x[i], y[i]) == reference_centroid(shifted, xs[i] + left, ys[i], radii[i])
        assert below[i] == reference_green_below(mask, xs[i], ys[i], radii[i])
        assert whites[i] == reference_white_halves(value, xs[i], ys[i], radii[i])


# -------------------------------------------------------------- LineDetector and FieldBoundaryDetector
def reference_white_runs(white: np.ndarray, step: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    columns = white[:, ::step].astype(np.int8)
    edge = np.zeros((1, columns.shape[1]), np.int8)
    change = np.diff(np.vstack([edge, columns, edge]), axis=0).T
    start_columns, start_rows = np.nonzero(change == 1)
    _, end_rows = np.nonzero(change == -1)
    return start_columns * step, start_rows, end_rows - 1


def reference_green_on_both_sides(green: np.ndarray, line: np.ndarray, first: np.ndarray, last: np.ndarray, reach: int) -> np.ndarray:
    rows = green.shape[0]
    above = np.zeros(len(line), bool)
    below = np.zeros(len(line), bool)
    for offset in range(1, reach + 1):
        up, down = first - offset, last + offset
        above |= (up >= 0) & green[np.clip(up, 0, rows - 1), line]
        below |= (down < rows) & green[np.clip(down, 0, rows - 1), line]
    return above & below


def reference_ignored(self: LineDetector, camera: str, projection: ImageProjection) -> np.ndarray:
    height, width = projection.height, projection.width
    boundary = self.field_boundary.rows(camera)
    ignored = (np.arange(height)[:, None] < boundary[None, :]) if boundary.size == width else np.zeros((height, width), bool)
    ignored |= own_body_mask(projection, (height, width))
    for post in self.goal_post_percept.posts:
        if post.camera == camera:
            half = post.image_width
            ignored[: int(post.image_foot) + 2, max(0, int(post.image_x - half)) : int(post.image_x + half) + 1] = True
    balls = np.zeros((height, width), np.uint8)
    for ball in self.ball_image_percept.candidates:
        if ball.camera == camera:
            cv2.circle(balls, (int(ball.x), int(ball.y)), int(ball.radius * 1.4) + 2, 1, -1)
    return ignored | balls.astype(bool)


@settings(max_examples=300)
@given(st.integers(0, 2**32 - 1), st.integers(1, 60), st.integers(1, 60), st.floats(0.0, 1.0), st.integers(1, 6), st.integers(0, 12))
def test_line_runs_and_their_green_borders_are_the_loops(seed: int, rows: int, columns: int, share: float, step: int, reach: int) -> None:
    rng = np.random.default_rng(seed)
    white = rng.random((rows, columns)) < share
    green = rng.random((rows, columns)) < 1.0 - share
    for mask in (white, white.T, white[::2]):  # views as the scan lines cut them
        runs = white_runs(mask, step)
        for ours, theirs in zip(runs, reference_white_runs(mask, step)):
            np.testing.assert_array_equal(ours, theirs)
    line, first, last = white_runs(white, 1)
    for borders in (green, np.ascontiguousarray(green.T).T):
        np.testing.assert_array_equal(green_on_both_sides(borders, line, first, last, reach),
                                      reference_green_on_both_sides(borders, line, first, last, reach))


@settings(max_examples=100)
@given(st.integers(0, 2**32 - 1), st.sampled_from([(320, 240), (64, 48), (50, 37)]), st.floats(0.05, 0.9), st.integers(1, 7),
       st.sampled_from(["any", "whole", "nan", "inf"]))
def test_line_detectors_ignored_pixels_are_the_full_masks(seed: int, size: tuple[int, int], pitch: float, step: int, rows: str) -> None:
    """The pixels ignored on the scan lines are the full mask's there: off the field, the own body, posts, balls; the
    boundary anywhere, on whole rows (where a row's comparison with the limit's ceiling differs from one with the next),
    or not finite in places."""
    rng = np.random.default_rng(seed)
    width, height = size
    boundary = np.clip(rng.normal(height / 3, height / 6, width), 0, height).astype(np.float32)
    if rows == "whole":
        boundary = np.round(boundary)
    elif rows in ("nan", "inf"):
        boundary[rng.integers(0, width, 3)] = np.nan if rows == "nan" else rng.choice([np.inf, -np.inf])
    posts = [GoalPost(0.0, 0.0, str(rng.choice(["top", "bottom"])), float(rng.uniform(0, width)), float(rng.uniform(1, 20)),
                      float(rng.uniform(0, height))) for _ in range(int(rng.integers(0, 3)))]
    balls = [BallCandidate(str(rng.choice(["top", "bottom"])), float(rng.uniform(-5, width + 5)), float(rng.uniform(-5, height + 5)),
                           float(rng.uniform(1, 20))) for _ in range(int(rng.integers(0, 3)))]
    self = make_module(LineDetector, parameters=LineDetector.Parameters(), field_boundary=FieldBoundary(top=boundary),
                       goal_post_percept=GoalPostPercept(posts=posts), ball_image_percept=BallImagePercept(candidates=balls))
    projection = level_projection(width, height, pitch)
    full = reference_ignored(self, "top", projection)  # type: ignore[arg-type]
    for grid in ((slice(None), slice(None, None, step)), (slice(None, None, step), slice(None)), (slice(None), slice(None))):
        np.testing.assert_array_equal(self.ignored("top", projection, grid), full[grid])  # type: ignore[attr-defined]


@settings(max_examples=200)
@given(st.integers(0, 2**32 - 1), st.integers(1, 90), st.integers(1, 90), st.sampled_from([2, 3, 4, 5, 8]), st.floats(0.0, 1.0))
def test_cell_shares_are_opencvs_area_resize(seed: int, rows: int, columns: int, cell: int, share: float) -> None:
    mask = np.random.default_rng(seed).random((rows, columns)) < share
    shares = cell_shares(mask, cell)
    expected = cv2.resize(mask.astype(np.float32), (max(1, columns // cell), max(1, rows // cell)), interpolation=cv2.INTER_AREA)
    assert shares.dtype == np.float32
    np.testing.assert_array_equal(shares, expected)


@settings(max_examples=300)
@given(st.integers(0, 2**32 - 1), st.one_of(st.floats(-20.0, 280.0), st.integers(-2, 258).map(float), st.sampled_from([math.inf, -math.inf, math.nan])),
       st.one_of(st.floats(-20.0, 280.0), st.integers(-2, 258).map(float), st.sampled_from([math.inf, -math.inf, math.nan])))
def test_white_pixels_are_numpys_comparisons(seed: int, saturation_max: float, value_min: float) -> None:
    hsv = np.random.default_rng(seed).integers(0, 256, (6, 8, 3)).astype(np.uint8)
    mask = white_pixels(hsv, saturation_max, value_min)
    assert mask.dtype == np.bool_
    np.testing.assert_array_equal(mask, (hsv[..., 1] <= saturation_max) & (hsv[..., 2] >= value_min))


@settings(max_examples=300)
@given(st.lists(st.integers(0, 255), max_size=300))
def test_byte_median_is_numpys(values: list[int]) -> None:
    array = np.array(values, np.uint8)
    if values:
        assert byte_median(array) == np.median(array)


@settings(max_examples=500)
@given(st.integers(0, 2**32 - 1), st.integers(1, 3000), st.integers(0, 255), st.integers(0, 255),
       st.one_of(st.sampled_from([99, 0, 100, 50, 99.0]), st.floats(0.0, 100.0)))
def test_byte_percentile_is_numpys(seed: int, count: int, low: int, high: int, q: float) -> None:
    """The white's percentile from a histogram: numpy's percentile of the same bytes, to the last bit."""
    values = np.random.default_rng(seed).integers(min(low, high), max(low, high) + 1, count).astype(np.uint8)
    assert byte_percentile(values, q) == float(np.percentile(values, q))


@settings(max_examples=300)
@given(st.integers(0, 2**32 - 1), st.integers(1, 70), st.integers(1, 70), st.integers(1, 9), st.sampled_from([0, 1, 3]), st.booleans(),
       st.integers(0, 69))
def test_every_is_numpys_strided_copy(seed: int, rows: int, columns: int, step: int, channels: int, boolean: bool, start: int) -> None:
    """The subsample by OpenCV's nearest-neighbour resize: numpy's ``[::step, ::step]``, for any size (part-blocks at the
    ends) and from any first row (the field colour's samples start below the horizon)."""
    rng = np.random.default_rng(seed)
    shape = (rows, columns, channels) if channels else (rows, columns)
    image = rng.random(shape) < 0.5 if boolean else rng.integers(0, 256, shape).astype(np.uint8)
    image = image[min(start, rows - 1) :]
    for strided in (image[:, ::2], image.swapaxes(0, 1)):  # pixels not side by side: numpy's copy
        np.testing.assert_array_equal(every(strided, step), strided[::step, ::step])
    sampled = every(image, step)
    assert sampled.dtype == image.dtype and sampled.flags.c_contiguous
    np.testing.assert_array_equal(sampled, image[::step, ::step])


@settings(max_examples=300)
@given(st.integers(0, 2**32 - 1), st.integers(1, 60), st.integers(1, 60), st.integers(0, 2), st.floats(0.0, 1.0),
       st.one_of(st.sampled_from([99, 0, 100, 50]), st.floats(0.0, 100.0)))
def test_histograms_give_the_medians_and_percentiles_of_the_gathered_bytes(seed: int, rows: int, columns: int, channel: int, share: float,
                                                                         q: float) -> None:
    """A channel's histogram under a mask counts the bytes the mask gathers; their median and percentile from it are
    numpy's of those bytes, to the last bit."""
    rng = np.random.default_rng(seed)
    image = rng.integers(0, 256, (rows, columns, 3)).astype(np.uint8)
    mask = rng.random((rows, columns)) < share
    counts = channel_histogram(image, channel, mask)
    gathered = image[..., channel][mask]
    np.testing.assert_array_equal(counts, np.bincount(gathered, minlength=256))
    if gathered.size:
        assert histogram_median(counts) == float(np.median(gathered))
        assert histogram_percentile(counts, q) == float(np.percentile(gathered, q))


@settings(max_examples=200)
@given(scenes)
def test_the_carpets_light_from_histograms_is_the_samples(painted: tuple[np.ndarray, np.ndarray, np.ndarray, float]) -> None:
    """The carpet's count and medians from the sample's histograms: those of the gathered sample."""
    hsv, green, _, _ = painted
    light, sampled = carpet_light(hsv, green), carpet_sample(hsv, green)
    assert light.count == len(sampled)
    if len(sampled):
        assert (light.value, light.saturation) == (float(np.median(sampled[:, 2])), float(np.median(sampled[:, 1])))


@settings(max_examples=200)
@given(st.integers(0, 2**32 - 1), st.floats(-1.5, 1.5), st.floats(-0.6, 1.2), st.integers(0, 300), st.sampled_from([(640, 480), (320, 240)]),
       st.booleans())
def test_rays_filled_in_place_are_the_stacked_ones(seed: int, yaw: float, pitch: float, count: int, size: tuple[int, int], exact: bool) -> None:
    """The pixels' rays from a camera array filled in place: those of the stacked columns, to the last bit."""
    rng = np.random.default_rng(seed)
    c, s, cp, sp = math.cos(yaw), math.sin(yaw), math.cos(pitch), math.sin(pitch)
    rotation = np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]]) @ np.array([[cp, 0, sp], [0, 1, 0], [-sp, 0, cp]])
    projection = ImageProjection(CameraMatrix(rotation, np.array([0.0, 0.0, 503.0]), True), *size, math.radians(56.3), math.radians(43.7))
    xs = rng.uniform(-10, size[0] + 10, count) if count % 2 else rng.integers(0, size[0], count)
    ys = rng.uniform(-10, size[1] + 10, count) if count % 2 else rng.integers(0, size[1], count)
    camera = np.stack([np.ones_like(xs, dtype=float), -(np.asarray(xs, float) - size[0] / 2) / projection.fx,
                       -(np.asarray(ys, float) - size[1] / 2) / projection.fy], axis=-1)
    np.testing.assert_array_equal(projection.rays(xs, ys, exact), rows_times(camera, projection.rotation.T, exact))


@settings(max_examples=300)
@given(st.integers(0, 2**32 - 1), st.integers(1, 60), st.integers(1, 60), st.integers(0, 12), st.floats(0.0, 1.0))
def test_dark_shares_from_the_part_the_squares_cover_are_the_whole_masks(seed: int, rows: int, columns: int, count: int, share: float) -> None:
    """The dark shares round spots anywhere (squares reaching out of the mask too), from the integral of only the part
    the squares cover: those of the whole mask's integral, to the last bit."""
    rng = np.random.default_rng(seed)
    dark = rng.random((rows, columns)) < share
    xs, ys = rng.integers(-5, columns + 5, count), rng.integers(-5, rows + 5, count)
    radii = rng.uniform(0.5, 12.0, count)
    shares = dark_share(dark, xs, ys, radii)
    expected = reference_dark_share(dark, xs, ys, radii)
    assert shares.dtype == expected.dtype
    np.testing.assert_array_equal(shares, expected)


@settings(max_examples=300)
@given(st.integers(0, 2**32 - 1), st.integers(1, 170), st.sampled_from(["noise", "flat", "ridge", "steps"]))
def test_the_lower_hull_over_opencvs_hull_is_the_chain_over_every_point(seed: int, count: int, kind: str) -> None:
    """The boundary's lower hull from the vertices of OpenCV's convex hull: the monotone chain over every point,
    for noisy, flat (all collinear), ridged and stepped columns of cells."""
    rng = np.random.default_rng(seed)
    xs = (np.arange(count) + 0.5) * 4
    ys = {"noise": rng.integers(0, 120, count), "flat": np.full(count, int(rng.integers(0, 120))),
          "ridge": np.abs(np.arange(count) - count // 2) * int(rng.integers(0, 3)),
          "steps": rng.integers(0, 3, count) + np.arange(count) // 7}[kind].astype(np.float32) * 4
    for ours, theirs in zip(lower_hull(xs, ys), chain(xs, ys), strict=True):
        assert ours.dtype == theirs.dtype
        np.testing.assert_array_equal(ours, theirs)


def test_byte_percentile_interpolates_as_numpy_does() -> None:
    """Between two bytes numpy interpolates from the upper one past the middle (4 and 17 at 99 %: the
    lower one's way rounds differently); so does the histogram's percentile."""
    for low in range(0, 256, 3):
        for high in range(low, 256, 7):
            values = np.array([high, low], np.uint8)
            for q in (99, 75.5, 50, 12.5):
                assert byte_percentile(values, q) == float(np.percentile(values, q))


def reference_fit_circle(self: LineDetector, points: np.ndarray) -> np.ndarray:
    p, out = self.parameters, self.line_percept
    if len(points) < p.min_circle_points:
        return points
    pairs = self.rng.integers(0, len(points), (p.iterations * 2, 2))
    a, b = points[pairs[:, 0]], points[pairs[:, 1]]
    chord = np.linalg.norm(b - a, axis=1)
    usable = (chord > 200.0) & (chord < 2 * CIRCLE_RADIUS)
    a, b, chord = a[usable], b[usable], chord[usable]
    if len(a) == 0:
        return points
    normal = np.column_stack([-(b - a)[:, 1], (b - a)[:, 0]]) / chord[:, None]
    offset = np.sqrt(CIRCLE_RADIUS**2 - (chord / 2) ** 2)[:, None]
    centres = np.vstack([(a + b) / 2 + offset * normal, (a + b) / 2 - offset * normal])
    residual = np.abs(np.linalg.norm(points[None, :, :] - centres[:, None, :], axis=2) - CIRCLE_RADIUS)
    counts = (residual < p.inlier_distance).sum(axis=1)
    best = int(np.argmax(counts))
    if counts[best] < p.min_circle_points:
        return points
    centre, inliers = centres[best], residual[best] < p.inlier_distance
    angles = np.arctan2(points[inliers, 1] - centre[1], points[inliers, 0] - centre[0])
    if longest_arc(angles, math.radians(p.max_arc_gap)) < math.radians(p.min_arc):
        return points
    out.circle_seen, out.circle_x, out.circle_y = True, float(centre[0]), float(centre[1])
    return points[~inliers]


@settings(max_examples=200)
@given(st.integers(0, 2**32 - 1), st.integers(0, 200), st.floats(0.0, 1.0))
def test_the_centre_circle_is_found_as_before(seed: int, count: int, on_circle: float) -> None:
    rng = np.random.default_rng(seed)
    centre = rng.normal(0, 1500, 2)
    angles = rng.uniform(0, 2 * math.pi, count)
    points = np.where((rng.random(count) < on_circle)[:, None], centre + CIRCLE_RADIUS * np.column_stack([np.cos(angles), np.sin(angles)]),
                      rng.normal(0, 2000, (count, 2))) + rng.normal(0, 20, (count, 2))
    found = []
    for fit in (LineDetector.fit_circle, reference_fit_circle):
        self = make_module(LineDetector, parameters=LineDetector.Parameters(), line_percept=LinePercept(segments=[]))
        self.rng = np.random.default_rng(seed)  # type: ignore[attr-defined]
        rest = fit(self, points)  # type: ignore[arg-type]
        percept = self.line_percept  # type: ignore[attr-defined]
        found.append((rest.tobytes(), percept.circle_seen, percept.circle_x, percept.circle_y))
    assert found[0] == found[1]


# -------------------------------------------------------------- GoalPostDetector: the loops as they were
def reference_running_sums(values: np.ndarray) -> np.ndarray:
    return np.concatenate([np.zeros((1, *values.shape[1:]), np.float32), np.cumsum(values, axis=0, dtype=np.float32)])


def reference_edge_profile(summed: np.ndarray, top: np.ndarray, band: int, first_row: int, step: int = 1) -> np.ndarray:
    rows, width = summed.shape[0] - 1, summed.shape[1]
    columns = np.arange(step, width - step)
    low = np.clip(top[columns] - first_row, 0, rows)
    high = np.clip(top[columns] - band - first_row, 0, rows)
    change = (summed[low, columns + step] - summed[high, columns + step] - summed[low, columns - step] + summed[high, columns - step])
    profile = np.zeros(width, np.float32)
    profile[columns] = np.linalg.norm(change, axis=1) / np.maximum(low - high, 1)
    return profile


def reference_band_means(summed: np.ndarray, top: np.ndarray, band: int, first_row: int) -> np.ndarray:
    rows, width = summed.shape[0] - 1, summed.shape[1]
    columns = np.arange(width)
    low = np.clip(top - first_row, 0, rows)
    high = np.clip(top - band - first_row, 0, rows)
    count = np.maximum(low - high, 1).reshape((width,) + (1,) * (summed.ndim - 2))
    return np.asarray((summed[low, columns] - summed[high, columns]) / count)

def reference_posts(self: GoalPostDetector, camera: str, image: np.ndarray, boundary: np.ndarray, projection: ImageProjection) -> list[GoalPost]:
    p = self.parameters
    hsv, green = self.segmented_image.hsv(camera), self.segmented_image.green(camera)
    height, width = green.shape
    if image.shape[:2] != green.shape:
        return []
    white = (hsv[..., 1] <= p.saturation_max) & ~green & (hsv[..., 2] >= p.white_share * self.segmented_image.white(camera))
    band = max(3, int(round(p.band * height)))
    top = np.round(boundary).astype(int)
    room = top > band
    if not room.any():
        return []
    self.colour = cv2.cvtColor(np.ascontiguousarray(image), cv2.COLOR_RGB2YCrCb).astype(np.float32)
    first_row, last_row = int(top[room].min()) - band, int(top[room].max())
    colour = self.colour[first_row:last_row]
    summed = reference_running_sums(colour)
    profile = np.where(room, reference_edge_profile(summed, top, band, first_row, max(1, width // 320)), 0.0)
    edges = edge_peaks(profile, p.edge_min)
    # the least width a post can have at each edge: the one it has standing on the boundary (its foot is no farther)
    ground, hit = projection.to_ground(edges + 0.5, top[edges] + 0.5)
    distance = np.linalg.norm(np.column_stack([ground, np.zeros(len(edges))]) - projection.translation, axis=1)
    least = np.where(hit, p.width_low * projection.fx * GOAL_POST_DIAMETER / np.maximum(distance, 1.0) - 1.0, 0.0)
    self.band_colour = reference_band_means(summed, top, band, first_row)
    self.band_white = reference_band_means(reference_running_sums(white[first_row:last_row].astype(np.float32)), top, band, first_row)
    found: list[GoalPost] = []
    for i, left in enumerate(edges):
        best: tuple[float, GoalPost] | None = None
        for right in edges[i + 1 : i + 5]:  # one of the next edges (stickers, dents and shadows on a post make more)
            if right - left < least[i]:
                continue
            post = reference_post(self, camera, int(left), int(right), top, white, green, projection)
            if post is not None:
                distance = float(np.linalg.norm(np.array([post.x, post.y, 0.0]) - projection.translation))
                misfit = abs(math.log(post.image_width * distance / (projection.fx * GOAL_POST_DIAMETER)))
                if best is None or misfit < best[0]:
                    best = (misfit, post)
        if best is not None:
            found.append(best[1])
    return self.nearest(self.distinct(found))


def reference_post(self: GoalPostDetector, camera: str, left: int, right: int, top: np.ndarray, white: np.ndarray, green: np.ndarray,
         projection: ImageProjection) -> GoalPost | None:
    p = self.parameters
    height, width = green.shape
    post_width = right - left
    side = max(2, post_width // 2)
    if post_width < 2 or left < 1 or right > width - 2:
        return None  # too thin to tell, or cut by the image's edge: its width is not known
    centre = (left + right) / 2
    column = int(centre)
    margin = post_width // 4
    inner = slice(left + 1 + margin // 2, max(left + 2 + margin // 2, right - margin // 2))
    # between the edges, in the band above the boundary: white, and unlike both sides
    if self.band_white[inner].mean() < 0.6:
        return None
    inside = self.band_colour[inner].mean(axis=0)
    for outside in (self.band_colour[max(0, left - side) : left], self.band_colour[right + 1 : right + 1 + side]):
        if np.linalg.norm(inside - outside.mean(axis=0)) < p.contrast_min:
            return None
    # the foot: down between the edges to where the carpet begins (a few rows of it: the carpet's
    # light makes green spots on a post's lower part)
    start = max(0, int(top[column]) - 1)
    carpet = (green[start:, inner].mean(axis=1) >= 0.5).astype(np.int32)
    run = max(2, post_width // 6)
    lasting = np.convolve(carpet, np.ones(run, np.int32), mode="valid") == run
    if not lasting.any():
        return None  # the foot is not in the image
    foot = start + int(np.argmax(lasting)) - 1
    if foot < start:
        foot = start
    ground, hit = projection.to_ground(np.array([centre]), np.array([foot + 0.5]))
    if not hit[0]:
        return None
    distance = float(np.linalg.norm(np.append(ground[0], 0.0) - projection.translation))
    expected = projection.fx * GOAL_POST_DIAMETER / distance
    if post_width - expected > p.width_tolerance * expected + 1.5 or post_width < p.width_low * expected - 1.0:
        return None
    # the foot near the boundary: the boundary no farther behind it than max_behind
    eye = projection.translation[:2]
    direction = (ground[0] - eye) / max(float(np.linalg.norm(ground[0] - eye)), 1.0)
    behind, front = projection.to_image(np.array([[*(ground[0] + direction * p.max_behind), 0.0]]))
    if front[0] and top[column] < behind[0, 1] - 2.0 - 0.01 * height:
        return None
    # the post rises from the foot along its projected axis: white, of one colour, unlike what is beside it
    post_centre = ground[0] + direction * GOAL_POST_DIAMETER / 2
    summit, front = projection.to_image(np.array([[*post_centre, p.rise * GOAL_HEIGHT]]))
    if not front[0] or summit[0, 1] >= foot:
        return None
    upper = max(0, int(summit[0, 1]))
    if foot - upper < p.min_height * post_width:
        return None
    def axis(ys: np.ndarray) -> np.ndarray:
        return np.round(centre + (summit[0, 0] - centre) * (foot - ys) / max(foot - summit[0, 1], 1.0)).astype(int)

    ys = np.unique(np.linspace(upper, foot, min(foot - upper + 1, 48)).round().astype(int))  # at most 48 rows: enough to judge
    if reference_post_rows(self, ys, axis(ys), post_width, white).mean() < p.white_rows:
        return None
    # down to the foot (above the line it stands on): a thing behind the field's edge stands on the hall's
    # floor (or its reflection on a glossy floor continues it), with something else between it and the carpet
    line = max(2, post_width // 3)
    ys = np.arange(max(upper, foot - 3 * line), foot - line + 1)
    if ys.size and reference_post_rows(self, ys, axis(ys), post_width, white).mean() < 0.5:
        return None
    x, y = post_centre
    return GoalPost(float(x), float(y), camera, float(centre), float(post_width), float(foot))


def reference_post_rows(self: GoalPostDetector, ys: np.ndarray, xs: np.ndarray, post_width: int, white: np.ndarray) -> np.ndarray:
    p = self.parameters
    height, width = white.shape
    half = max(1, post_width // 4)
    side = max(2, post_width // 2)

    def strip(first: int, last: int) -> np.ndarray:
        columns = np.clip(xs[:, None] + np.arange(first, last + 1)[None, :], 0, width - 1)
        return np.asarray(self.colour[ys[:, None], columns].mean(axis=1))

    columns = np.clip(xs[:, None] + np.arange(-half, half + 1)[None, :], 0, width - 1)
    inside = strip(-half, half)
    edge = (post_width + 1) // 2
    left, right = strip(-edge - side, -edge - 1), strip(edge + 1, edge + side)
    unlike = np.maximum(np.linalg.norm(inside - left, axis=1), np.linalg.norm(inside - right, axis=1)) >= p.contrast_min
    same = np.linalg.norm(inside - np.median(inside, axis=0), axis=1) <= p.uniform_max
    return np.asarray((white[ys[:, None], columns].mean(axis=1) >= 0.5) & unlike & same)


SHARED_IMAGES = Path(__file__).resolve().parent.parent.parent / "shared" / "real-images"


def post_tuples(posts: list[GoalPost]) -> list[tuple[float, float, str, float, float, float]]:
    return [(post.x, post.y, post.camera, post.image_x, post.image_width, post.image_foot) for post in posts]


def same_posts_as_the_loops(self: GoalPostDetector, camera: str, image: np.ndarray, boundary: np.ndarray,
                            projection: ImageProjection) -> list[GoalPost]:
    """The detector's posts in one image, asserted bit for bit those of the loops (and its band measures too)."""
    self.band_colour, self.band_white = np.zeros((0, 3)), np.zeros(0)
    before = reference_posts(self, camera, image, boundary, projection)
    band_colour, band_white = self.band_colour, self.band_white
    self.band_colour, self.band_white = np.zeros((0, 3)), np.zeros(0)
    after = self.posts(camera, image, boundary, projection)
    assert post_tuples(after) == post_tuples(before)
    for ours, theirs in ((self.band_colour, band_colour), (self.band_white, band_white)):
        assert ours.dtype == theirs.dtype
        np.testing.assert_array_equal(ours, theirs)
    return after


def recorded_frames() -> Iterator[dict[str, Any]]:
    """Both cameras' frames for the perception: each real image of ../shared/real-images at 640x480 and
    shrunk to 320x240 (the other camera empty); MuJoCo renders of random scenes where those are absent."""
    empty = SimpleNamespace(image=np.zeros((0, 0, 3), np.uint8), horizontal_fov=0.0, vertical_fov=0.0, matrix=CameraMatrix())
    if not (SHARED_IMAGES / "labels.csv").is_file():
        from tafel.tools.simulation.scene_frames import SceneRenderer

        with SceneRenderer("mujoco", resolution="640x480") as renderer:
            for frame in renderer.random_frames(24, seed=3):
                yield {"top": empty, "bottom": empty, frame.camera: frame}
        return
    with open(SHARED_IMAGES / "labels.csv", newline="") as handle:
        rows = list(csv.DictReader(handle))
    for row in rows:
        camera = row.get("camera") or "top"
        posed = posed_image(SHARED_IMAGES / row["image"], camera=camera)
        for scale in (1.0, 0.5):
            image = posed.image if scale == 1.0 else cv2.resize(posed.image, None, fx=scale, fy=scale, interpolation=cv2.INTER_AREA)
            view = SimpleNamespace(image=image, horizontal_fov=posed.horizontal_fov, vertical_fov=posed.vertical_fov, matrix=posed.matrix)
            yield {"top": empty, "bottom": empty, camera: view}


def test_goal_posts_and_the_band_search_in_recorded_frames_are_the_loops() -> None:
    """On every real image (at both resolutions; renders where the set is absent), after the perception
    before it has run: the same posts as the loops, bit for bit, and the band search's spots as the loops over the
    whole band found them."""
    found = band_spots = 0
    for frames in recorded_frames():
        perception = Perception()
        perception(frames)  # type: ignore[arg-type]
        self = perception.manager.module("GoalPostDetector")
        ball = perception.manager.module("SPLBallDetector")
        assert isinstance(ball, SPLBallDetector)
        for camera, image, projection in camera_views(self.camera_image_top, self.camera_image_bottom, self.camera_matrix_buffer):
            boundary = self.field_boundary.rows(camera)
            if boundary.size == projection.width:
                found += len(same_posts_as_the_loops(self, camera, np.asarray(image.image), boundary, projection))
            hsv, green = ball.segmented_image.hsv(camera), ball.segmented_image.green(camera)
            band_spots += same_band_spots(ball, hsv, green, boundary, projection, [])
    assert found > 0  # the frames held posts, so the whole of the check ran
    assert band_spots > 0  # the loose band search found spots, so the whole of it ran


def post_scene(seed: int, width: int, height: int, pitch: float) -> tuple[np.ndarray, np.ndarray, np.ndarray, float, np.ndarray, ImageProjection]:
    """(image, hsv, green, white, boundary rows, projection) of a painted field seen by a standing robot:
    carpet below a wavy edge, a hall above, white posts of about a post's width at their foot's distance
    (some too thin or too wide, some standing on a goal line, some cut by the image's edge), noise."""
    rng = np.random.default_rng(seed)
    projection = level_projection(width, height, pitch)
    image = np.empty((height, width, 3), np.uint8)
    image[:] = (40 + rng.integers(-15, 15), 140 + rng.integers(-30, 30), 50 + rng.integers(-15, 15))
    edge = int(rng.integers(height // 10, height // 2))
    image[:edge] = rng.integers(60, 230, 3)
    for _ in range(int(rng.integers(0, 5))):
        x, foot = float(rng.uniform(-10, width + 10)), int(rng.integers(edge - 2, min(height - 1, edge + height // 4)))
        ground, hit = projection.to_ground(np.array([x]), np.array([foot + 0.5]))
        distance = float(np.linalg.norm(np.append(ground[0], 0.0) - projection.translation)) if hit[0] else 5000.0
        half = max(1.0, projection.fx * GOAL_POST_DIAMETER / distance * float(rng.uniform(0.4, 1.8)) / 2)
        shade = int(rng.integers(170, 256))
        cv2.rectangle(image, (int(x - half), int(rng.integers(0, max(1, edge // 2)))), (int(x + half), foot), (shade, shade, shade - 10), -1)
        if rng.random() < 0.5:  # the goal line it stands on
            cv2.line(image, (0, foot + 1), (width - 1, foot + 1 + int(rng.integers(-3, 4))), (235, 235, 235), int(rng.integers(1, 5)))
    image = np.clip(image.astype(int) + rng.integers(-10, 11, image.shape), 0, 255).astype(np.uint8)
    hsv = cv2.cvtColor(image, cv2.COLOR_RGB2HSV)
    green = (hsv[..., 0] > 35) & (hsv[..., 0] < 85) & (hsv[..., 1] > 60) & (hsv[..., 2] > 40)
    boundary = np.clip(edge + rng.normal(0, 2, width), 0, height).astype(np.float32)
    return image, hsv, green, float(hsv[..., 2].max()), boundary, projection


@settings(max_examples=150, deadline=None)
@given(st.integers(0, 2**32 - 1), st.sampled_from([(640, 480), (320, 240), (160, 120), (96, 72)]), st.floats(0.0, 0.5))
def test_goal_posts_in_painted_scenes_are_the_loops(seed: int, size: tuple[int, int], pitch: float) -> None:
    """Posts of many widths over a wavy field edge, at the image's edges too: the same posts as the loops."""
    image, hsv, green, white, boundary, projection = post_scene(seed, *size, pitch)
    self = make_module(GoalPostDetector, parameters=GoalPostDetector.Parameters(),
                       segmented_image=SegmentedImage(top_hsv=hsv, top_green=green, top_white=white))
    same_posts_as_the_loops(self, "top", image, boundary, projection)  # type: ignore[arg-type]


@settings(max_examples=200)
@given(st.integers(0, 2**32 - 1), st.floats(-1.5, 1.5), st.floats(-0.6, 1.2), st.floats(300.0, 600.0), st.integers(1, 40))
def test_the_geometry_of_many_posts_at_once_is_each_ones(seed: int, yaw: float, pitch: float, height: float, count: int) -> None:
    """Pixels to the ground, points to the image and lengths for many posts at once: to the last bit
    what the projection gives for each one alone (the detector's posts must not move by a rounding)."""
    rng = np.random.default_rng(seed)
    c, s, cp, sp = math.cos(yaw), math.sin(yaw), math.cos(pitch), math.sin(pitch)
    rotation = np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]]) @ np.array([[cp, 0, sp], [0, 1, 0], [-sp, 0, cp]])
    projection = ImageProjection(CameraMatrix(rotation, np.array([*rng.normal(0, 50, 2), height]), True), 640, 480,
                                 math.radians(56.3), math.radians(43.7))
    xs, ys = rng.uniform(-20, 660, count), rng.uniform(-20, 500, count)
    ground, hits = projection.to_ground(xs, ys, exact=True)
    points = np.column_stack([rng.normal(0, 3000, (count, 2)), rng.uniform(0, 800, count)])
    pixels, fronts = projection.to_image(points, exact=True)
    for k in range(count):
        one, hit = projection.to_ground(xs[k : k + 1], ys[k : k + 1])
        assert hit[0] == hits[k] and np.array_equal(one[0], ground[k])
        pixel, front = projection.to_image(points[k : k + 1])
        assert front[0] == fronts[k] and np.array_equal(pixel[0], pixels[k])
    for size in (2, 3):
        vectors = points[:, :size] * rng.uniform(0.01, 10)
        assert np.array_equal(exact_norms(vectors), [float(np.linalg.norm(vector)) for vector in vectors])


@settings(max_examples=300)
@given(st.integers(0, 2**32 - 1), st.integers(1, 30), st.integers(1, 40), st.integers(1, 6))
def test_strips_and_medians_of_many_posts_at_once_are_numpys(seed: int, rows: int, columns: int, posts: int) -> None:
    """The strips' means (clipped at the image's sides) and each post's median along its rows: numpy's
    float32 means of the pixels and np.median, to the last bit."""
    rng = np.random.default_rng(seed)
    image = rng.integers(0, 256, (rows, columns, 3)).astype(np.uint8)
    mask = rng.random((rows, columns)) < 0.5
    lengths = rng.integers(1, 12, posts)
    ys = rng.integers(0, rows, int(lengths.sum()))
    xs = rng.integers(-10, columns + 10, len(ys))
    first = xs + rng.integers(-15, 3, len(ys))
    last = first + rng.integers(0, 12, len(ys))
    first_row = int(ys.min())  # the strips of the rows from there on
    colour = cv2.integral(image[first_row:], sdepth=cv2.CV_32S)
    means = strip_means(colour, image[first_row:], ys - first_row, first, last)
    whites = strip_sums(cv2.integral(mask[first_row:].view(np.uint8), sdepth=cv2.CV_32S), mask[first_row:], ys - first_row, first, last)
    for k in range(len(ys)):
        strip = np.clip(np.arange(first[k], last[k] + 1), 0, columns - 1)
        assert np.array_equal(means[k], image.astype(np.float32)[ys[k], strip].mean(axis=0))
        assert whites[k] == mask[ys[k], strip].sum()
    medians = segment_medians(means, lengths)
    assert medians.dtype == np.float32
    for k, (start, length) in enumerate(zip(np.cumsum(lengths) - lengths, lengths, strict=True)):
        assert np.array_equal(medians[k], np.median(means[start : start + length], axis=0))


@settings(max_examples=300)
@given(st.integers(0, 2**32 - 1), st.integers(8, 120), st.sampled_from([1, 3, 5, 10]), st.floats(1.0, 40.0))
def test_the_band_checks_of_all_pairs_at_once_let_through_what_may_pass(seed: int, width: int, levels: int, contrast_min: float) -> None:
    """Every pair of edges whose band passes the slices' checks (the loops') passes the running sums'
    ones; a pair they call sure (not near a threshold) passes exactly when the slices' checks pass, and
    the detector decides the others by those checks. Shares and colours on a coarse grid, so that means
    land on the thresholds exactly."""
    rng = np.random.default_rng(seed)
    self = make_module(GoalPostDetector, parameters=GoalPostDetector.Parameters(contrast_min=contrast_min))
    self.band_white = rng.integers(0, levels + 1, width) / levels  # type: ignore[attr-defined]
    self.band_colour = rng.integers(0, 4, (width, 3)) * float(rng.choice([contrast_min / 2, contrast_min / 3, 7.0]))  # type: ignore[attr-defined]
    left = rng.integers(1, width - 3, 60)
    right = np.minimum(left + rng.integers(2, 40, 60), width - 2)
    keep = right - left >= 2
    left, right = left[keep], right[keep]
    passes, near = band_passes(self.band_white, self.band_colour, left, right, contrast_min, 1e-6)  # type: ignore[attr-defined]
    for k in range(len(left)):
        post_width = int(right[k] - left[k])
        side, margin = max(2, post_width // 2), post_width // 4
        inner = slice(int(left[k]) + 1 + margin // 2, max(int(left[k]) + 2 + margin // 2, int(right[k]) - margin // 2))
        inside = self.band_colour[inner].mean(axis=0)  # type: ignore[attr-defined]
        loops = self.band_white[inner].mean() >= 0.6 and all(  # type: ignore[attr-defined]
            np.linalg.norm(inside - outside.mean(axis=0)) >= contrast_min
            for outside in (self.band_colour[max(0, int(left[k]) - side) : int(left[k])], self.band_colour[int(right[k]) + 1 : int(right[k]) + 1 + side]))  # type: ignore[attr-defined]
        assert band_checks(self.band_white, self.band_colour, int(left[k]), int(right[k]), contrast_min) == loops  # type: ignore[attr-defined]
        assert passes[k] or not loops
        if not near[k]:
            assert passes[k] == loops


@settings(max_examples=300)
@given(st.lists(st.tuples(st.integers(0, 479), st.integers(1, 479)), max_size=12), st.integers(2, 60))
def test_the_rows_of_many_posts_at_once_are_numpys(spans: list[tuple[int, int]], most: int) -> None:
    """The rows along each post (rounded linspace, each once) and the runs down to their feet: those numpy
    gives for each post alone."""
    upper = np.array([a for a, _ in spans], int)
    foot = upper + np.array([b for _, b in spans], int)
    ys, lengths = rising_rows(upper, foot, most)
    expected = [np.unique(np.linspace(a, b, min(b - a + 1, most)).round().astype(int)) for a, b in zip(upper, foot, strict=True)]
    assert lengths.tolist() == [len(rows) for rows in expected]
    np.testing.assert_array_equal(ys, np.concatenate([np.zeros(0, int), *expected]))
    first, stop = upper - foot // 3, foot - foot // 4  # some runs empty
    ys, lengths = runs_of_rows(first, stop)
    expected = [np.arange(a, b) for a, b in zip(first, stop, strict=True)]
    assert lengths.tolist() == [len(rows) for rows in expected]
    np.testing.assert_array_equal(ys, np.concatenate([np.zeros(0, int), *expected]))


# ------------------------------------------------------------ the projections the detectors share, the own body, fresh poses
def reference_paint_own_body(projection: ImageProjection, mask: np.ndarray) -> None:
    for points in BODY_POINTS:
        pixels, front = projection.to_image(points)
        if front.sum() >= 3:
            cv2.fillConvexPoly(mask, cv2.convexHull(np.minimum(np.maximum(pixels[front], -1e4), 1e4).astype(np.int32)), 1)


@settings(max_examples=300)
@given(st.floats(-3.1, 3.1), st.floats(-1.5, 1.5), st.floats(-1.0, 1.0), st.floats(-100.0, 600.0), st.sampled_from([(640, 480), (320, 240), (1280, 960)]))
def test_the_own_body_projected_at_once_is_each_boxs(yaw: float, pitch: float, roll: float, height: float, size: tuple[int, int]) -> None:
    """The robot's own body with all its boxes' points projected in one call: the mask of one call per box."""
    c, s, cp, sp, cr, sr = math.cos(yaw), math.sin(yaw), math.cos(pitch), math.sin(pitch), math.cos(roll), math.sin(roll)
    rotation = np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]]) @ np.array([[cp, 0, sp], [0, 1, 0], [-sp, 0, cp]]) @ np.array([[1, 0, 0], [0, cr, -sr], [0, sr, cr]])
    projection = ImageProjection(CameraMatrix(rotation, np.array([20.0, -10.0, height]), True), *size, math.radians(56.3), math.radians(43.7))
    np.testing.assert_array_equal(projection.to_image(BODY_POINTS_ALL)[0], np.concatenate([projection.to_image(points)[0] for points in BODY_POINTS]))
    expected = np.zeros(size[::-1], np.uint8)
    reference_paint_own_body(projection, expected)
    np.testing.assert_array_equal(own_body_mask(projection, size[::-1]), expected.view(bool))


def test_the_frames_projections_are_worked_out_once_and_anew_when_what_they_come_from_changes() -> None:
    """Six detectors ask for the same frame's projections: the second asker gets the same (read-only) ones; a new
    matrix in the buffer, a new image time or a new image size gives new ones, as worked out afresh."""
    pitch = 0.4
    rotation = np.array([[math.cos(pitch), 0, math.sin(pitch)], [0, 1, 0], [-math.sin(pitch), 0, math.cos(pitch)]])
    buffer = CameraMatrixBuffer.of(CameraMatrix(rotation, np.array([0.0, 0.0, 503.0]), True), CameraMatrix(rotation, np.array([0.0, 0.0, 450.0]), True), 100)
    top = CameraImageTop(image=np.zeros((480, 640, 3), np.uint8), horizontal_fov=math.radians(56.3), vertical_fov=math.radians(43.7), time_ns=100)
    bottom = CameraImageBottom(image=np.zeros((240, 320, 3), np.uint8), horizontal_fov=math.radians(56.3), vertical_fov=math.radians(43.7), time_ns=100)

    def views() -> dict[str, ImageProjection]:
        return {camera: projection for camera, _, projection in camera_views(top, bottom, buffer)}

    first, again = views(), views()
    assert first.keys() == {"top", "bottom"} and all(again[camera] is first[camera] for camera in first)
    with pytest.raises(ValueError):
        first["top"].translation[2] = 0.0  # shared: nobody changes it
    buffer.top_translation[0, 2] = 480.0  # the top camera's matrix changed: its projection anew, the bottom one's kept
    moved = views()
    assert moved["top"] is not first["top"] and moved["bottom"] is first["bottom"]
    assert moved["top"].translation[2] == 480.0
    buffer.time_ns[1], buffer.top_translation[1, 2], buffer.count = 200, 520.0, 2  # an image taken later: between the entries
    top.time_ns = 150
    between = views()["top"]
    assert between.translation[2] == pytest.approx(500.0)
    top.image = np.zeros((240, 320, 3), np.uint8)
    smaller = views()["top"]
    assert (smaller.width, smaller.height) == (320, 240) and smaller.fx == pytest.approx(between.fx / 2)


def reference_from_lines(rng: np.random.Generator, count: int, lines: LinePercept) -> np.ndarray:
    segments = [s for s in lines.segments if s.length >= 300.0]
    seen = [segments[i] for i in rng.integers(0, len(segments), count)]
    middle = np.array([((s.x1 + s.x2) / 2, (s.y1 + s.y2) / 2) for s in seen])
    seen_angle = np.array([math.atan2(s.y2 - s.y1, s.x2 - s.x1) for s in seen])
    true = FIELD_MODEL.lines[rng.integers(0, len(FIELD_MODEL.lines), count)]
    along = rng.random(count)[:, None]
    point = true[:, :2] + along * (true[:, 2:] - true[:, :2])
    headings = np.arctan2(true[:, 3] - true[:, 1], true[:, 2] - true[:, 0]) - seen_angle + math.pi * rng.integers(0, 2, count)
    c, s = np.cos(headings), np.sin(headings)
    positions = point - np.column_stack([c * middle[:, 0] - s * middle[:, 1], s * middle[:, 0] + c * middle[:, 1]])
    return np.column_stack([positions, np.remainder(headings + math.pi, math.tau) - math.pi])


def reference_from_posts(rng: np.random.Generator, count: int, posts: GoalPostPercept) -> np.ndarray:
    seen = [posts.posts[i] for i in rng.integers(0, len(posts.posts), count)]
    distance = np.array([math.hypot(p.x, p.y) for p in seen]) * rng.normal(1.0, 0.05, count)
    bearing = np.array([math.atan2(p.y, p.x) for p in seen])
    true = FIELD_MODEL.posts[rng.integers(0, len(FIELD_MODEL.posts), count)]
    around = rng.uniform(-math.pi, math.pi, count)
    positions = true + distance[:, None] * np.column_stack([np.cos(around), np.sin(around)])
    headings = np.remainder(around + math.pi - bearing + math.pi, math.tau) - math.pi
    on_field = (np.abs(positions[:, 0]) < FIELD_MODEL.half_x) & (np.abs(positions[:, 1]) < FIELD_MODEL.half_y)
    fresh = np.column_stack([positions, headings])[on_field]
    return np.vstack([fresh, FIELD_MODEL.uniform(rng, count - len(fresh))])


@settings(max_examples=100)
@given(st.integers(0, 2**32 - 1), st.integers(1, 120), st.integers(1, 6), st.integers(1, 4))
def test_fresh_poses_from_lines_and_posts_are_those_drawn_one_by_one(seed: int, count: int, segments: int, posts: int) -> None:
    """Sensor resetting's poses from line segments and from posts, each segment's and post's measures worked out once:
    the poses (and the random numbers after them) of the measures worked out for every pose drawn."""
    rng = np.random.default_rng(seed)
    lines = LinePercept(segments=[LineSegment(*(float(v) for v in rng.uniform(-3000, 3000, 4))) for _ in range(segments)])
    lines.segments.append(LineSegment(0.0, 0.0, 1000.0, 0.0))  # one at least is long enough
    seen = GoalPostPercept(posts=[GoalPost(*(float(v) for v in rng.uniform(-4000, 4000, 2)), "top") for _ in range(posts)])
    for make, reference, percept in ((FIELD_MODEL._from_lines, reference_from_lines, lines), (FIELD_MODEL._from_posts, reference_from_posts, seen)):
        a, b = np.random.default_rng(seed + 1), np.random.default_rng(seed + 1)
        np.testing.assert_array_equal(make(a, count, lines, seen), reference(b, count, percept))  # type: ignore[operator]
        assert a.random() == b.random()


@settings(max_examples=200)
@given(st.integers(0, 2**32 - 1), st.floats(-3.1, 3.1), st.floats(-1.5, 1.5), st.floats(-100.0, 600.0), st.floats(0.0, 200.0), st.booleans())
def test_ground_points_with_one_division_are_the_masked_ones(seed: int, yaw: float, pitch: float, height: float, z: float, exact: bool) -> None:
    """Pixels to the ground dividing only where the rays meet the plane: the points of the division by the masked rays
    (0 for the others), to the last bit."""
    rng = np.random.default_rng(seed)
    c, s, cp, sp = math.cos(yaw), math.sin(yaw), math.cos(pitch), math.sin(pitch)
    rotation = np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]]) @ np.array([[cp, 0, sp], [0, 1, 0], [-sp, 0, cp]])
    projection = ImageProjection(CameraMatrix(rotation, np.array([10.0, -5.0, height]), True), 640, 480, math.radians(56.3), math.radians(43.7))
    xs, ys = rng.uniform(-50, 700, 40), rng.uniform(-50, 530, 40)
    rays = projection.rays(xs, ys, exact)
    hits = rays[:, 2] < -1e-6
    scale = np.where(hits, (z - projection.translation[2]) / np.where(hits, rays[:, 2], -1.0), 0.0)
    points, found = projection.to_ground(xs, ys, z, exact)
    np.testing.assert_array_equal(found, hits)
    np.testing.assert_array_equal(points, projection.translation[:2] + scale[:, None] * rays[:, :2])


@settings(max_examples=200)
@given(st.integers(0, 2**32 - 1), st.integers(0, 40), st.floats(0.0, 5.0))
def test_ball_ranges_are_the_norms_of_the_stacked_points(seed: int, count: int, scale: float) -> None:
    """The camera's range to balls on the ground: ``np.linalg.norm`` of the stacked points' offsets, to the last bit."""
    rng = np.random.default_rng(seed)
    centres, eye = rng.normal(0.0, 10**scale, (count, 2)), rng.normal(0.0, 500.0, 3)
    np.testing.assert_array_equal(ball_ranges(centres, eye),
                                  np.linalg.norm(np.column_stack([centres, np.full(count, BALL_RADIUS)]) - eye, axis=1))


def reference_line_distance(points: np.ndarray) -> np.ndarray:
    """``FieldModel.line_distance`` before issue 34: range tests, clips and a choice over the map."""
    column = np.round((points[..., 0] + FIELD_MODEL.half_x) / 20.0).astype(int)
    row = np.round((points[..., 1] + FIELD_MODEL.half_y) / 20.0).astype(int)
    rows, columns = FIELD_MODEL.distance.shape
    inside = (column >= 0) & (column < columns) & (row >= 0) & (row < rows)
    return np.where(inside, FIELD_MODEL.distance[np.clip(row, 0, rows - 1), np.clip(column, 0, columns - 1)], 2000.0)


@settings(max_examples=200)
@given(st.integers(0, 2**32 - 1), st.integers(1, 500), st.integers(1, 60), st.floats(0.5, 4.0), st.booleans())
def test_line_distances_seen_from_every_particle_are_the_stacked_ones(seed: int, count: int, points: int, spread: float,
                                                                      broken: bool) -> None:
    """The particle filter's line distances worked out in place from the poses and points: the distances of the stacked
    field positions (``seen_from``), to the last bit, also off the map and for positions that are not finite."""
    rng = np.random.default_rng(seed)
    poses = np.column_stack([rng.normal(0.0, 10**spread, count), rng.normal(0.0, 10**spread, count), rng.uniform(-7.0, 7.0, count)])
    seen = rng.normal(0.0, 10**spread, (points, 2))
    if broken:  # a NaN pose and an infinite point
        poses[rng.integers(count), rng.integers(3)] = np.nan
        seen[rng.integers(points), rng.integers(2)] = np.inf
    with np.errstate(invalid="ignore"):
        expected = reference_line_distance(seen_from(poses, seen))
    got = FIELD_MODEL.line_distance_seen(poses, seen)
    assert got.dtype == expected.dtype
    np.testing.assert_array_equal(got, expected)


@given(st.lists(st.floats(allow_nan=True, allow_infinity=True), max_size=30), st.booleans())
def test_robust_log_likelihoods_in_place_are_the_formulas(values: list[float], scalar: bool) -> None:
    """``robust`` in place: -0.5 * min(x, 2.5) ** 2, to the last bit, for arrays and for a number."""
    if scalar and values:
        assert np.array_equal(robust(values[0]), -0.5 * np.minimum(values[0], 2.5) ** 2, equal_nan=True)
    array = np.array(values, float)
    np.testing.assert_array_equal(robust(array), -0.5 * np.minimum(array, 2.5) ** 2)


def reference_verdict(self: SPLBallDetector, hsv: np.ndarray, green: np.ndarray, spot: Spot, white: float, beside_post: bool = False,
                      parameters: SPLBallDetector.Parameters | None = None) -> tuple[float, bool, str]:
    """``ball_checks.verdict`` before its dark pixels were counted from the histogram: the own pixels gathered,
    compared and averaged."""
    p = parameters or self.parameters
    height, width = green.shape
    r = spot.radius
    reach = int(math.ceil(r * 1.7)) + 1
    x0, x1 = max(0, int(spot.x) - reach), min(width, int(spot.x) + reach + 1)
    y0, y1 = max(0, int(spot.y) - reach), min(height, int(spot.y) + reach + 1)
    d = np.hypot(np.arange(x0, x1)[None, :] - spot.x, np.arange(y0, y1)[:, None] - spot.y)
    inside, around = d <= 0.9 * r, (d >= 1.2 * r) & (d <= 1.7 * r)
    n_inside, n_around = np.count_nonzero(inside), np.count_nonzero(around)
    if n_inside < 3 or n_around < 3:
        return 0.0, False, "size"
    patch_green, patch = green[y0:y1, x0:x1], hsv[y0:y1, x0:x1]
    solid = inside & ~patch_green
    if np.count_nonzero(solid) < 3:
        return 0.0, False, "size"
    if not beside_post and under_post(hsv, green, spot, white, self.parameters):
        return 0.0, True, "post"
    green_inside = np.count_nonzero(patch_green & inside) / n_inside
    green_around = np.count_nonzero(patch_green & around) / n_around
    if green_inside > p.green_inside_max or green_around < p.green_around_min:
        return 0.0, False, "green"
    saturation = float(patch[..., 1][inside].mean())
    if saturation > p.saturation_max:
        return 0.0, False, "saturation"
    own = patch[..., 2][solid]
    bright = byte_percentile(own, 90)
    value = own.astype(float)
    is_dark = value < p.dark_ratio * bright
    dark = np.count_nonzero(is_dark) / len(value)
    if not p.dark_share_min <= dark <= p.dark_share_max:
        return 0.0, False, "dark"
    carpet = patch[..., 2][around & patch_green]
    field_value = byte_median(carpet if carpet.size >= 3 else patch[..., 2][around])
    black = value[is_dark]
    darkest = float(black.mean()) if black.size else math.inf
    if darkest > p.black_contrast * field_value and not alone_on_dark_carpet(green, spot, bright, field_value, green_around, p):
        return 0.0, False, "black"
    return float(min(1.0, 0.5 + dark + 0.3 * green_around - green_inside)), False, ""


@settings(max_examples=200)
@given(scenes, st.data())
def test_spl_verdicts_from_the_histogram_are_the_gathered_pixels(painted: tuple[np.ndarray, np.ndarray, np.ndarray, float],
                                                                 data: st.DataObject) -> None:
    """The checks' verdict (score, under a post, the test failed) with the dark pixels counted and summed from the own
    pixels' histogram: the verdict of the gathered pixels, to the last bit, for spots anywhere, with the module's
    thresholds, the second look's, and thresholds drawn (every test's branch)."""
    hsv, green, _, white = painted
    height, width = green.shape
    self = detector()
    drawn = SPLBallDetector.Parameters(dark_ratio=data.draw(st.floats(0.0, 1.5)), dark_share_min=data.draw(st.floats(0.0, 0.5)),
                                       dark_share_max=data.draw(st.floats(0.3, 1.0)), black_contrast=data.draw(st.floats(0.0, 2.0)),
                                       white_over_dark_carpet=data.draw(st.floats(1.0, 10.0)), green_inside_max=1.0, green_around_min=0.0, saturation_max=255.0)
    for _ in range(5):
        x, y = data.draw(st.floats(-3.0, width + 2.0)), data.draw(st.floats(-3.0, height + 2.0))
        spot = Spot(x, y, data.draw(st.floats(0.5, 25.0)), data.draw(st.floats(0.5, 25.0)))
        for parameters in (None, self.looser(), drawn):
            for beside in (False, True):
                assert (verdict(hsv, green, spot, white, self.parameters, beside, parameters)
                        == reference_verdict(self, hsv, green, spot, white, beside, parameters))


@settings(max_examples=300)
@given(st.integers(-200, 900), st.integers(-200, 700), st.integers(0, 140), st.integers(0, 140), st.integers(-2, 2), st.integers(-2, 2),
       st.sampled_from([0.0, 0.5, 0.25, 1e-9]), st.sampled_from([0.0, 0.5, 0.75]))
def test_distances_from_a_whole_pixel_are_numpys_hypot(x: int, y: int, reach_x: int, reach_y: int, skew_x: int, skew_y: int,
                                                       fraction_x: float, fraction_y: float) -> None:
    """The pixels' distances from a spot, looked up for spots on whole pixels (up to the table's reach and beyond it,
    windows not centred on the spot), computed by hypot for the others: ``np.hypot`` of the offsets, to the last bit."""
    sx, sy = x + fraction_x, y + fraction_y
    x0, x1, y0, y1 = x - reach_x + skew_x, x + reach_x + 1 + skew_x, y - reach_y + skew_y, y + reach_y + 1 + skew_y
    expected = np.hypot(np.arange(x0, x1)[None, :] - sx, np.arange(y0, y1)[:, None] - sy)
    got = ball_checks.distances(x0, x1, y0, y1, sx, sy)
    assert got.shape == expected.shape
    np.testing.assert_array_equal(got, expected)


def test_the_distance_table_is_numpys_hypot_of_signed_offsets() -> None:
    """Every offset of the table with either sign: its value (hypot does not depend on the signs)."""
    offsets = np.arange(-ball_checks.HYPOT_REACH + 1, ball_checks.HYPOT_REACH, dtype=float)
    index = np.abs(offsets).astype(int)
    np.testing.assert_array_equal(np.hypot(offsets[None, :], offsets[:, None]), ball_checks.HYPOT[index][:, index])
