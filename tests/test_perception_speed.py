"""The perception modules' vectorized steps (issue 34) against the loops they replaced, kept here as the
reference: the same output on painted scenes drawn by hypothesis (balls with black patches, lines,
posts over the field's edge, dark corners). The real-image figures are benchmarks/real_images.py's."""

from __future__ import annotations

import math

import cv2
import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from tafel.core.framework.manager import make_module
from tafel.modules.perception.field_boundary_detector import cell_shares
from tafel.modules.perception.field_color_provider import below, byte_median, white_pixels
from tafel.modules.perception.image_geometry import ImageProjection, own_body_mask
from tafel.modules.perception.line_detector import CIRCLE_RADIUS, LineDetector, green_on_both_sides, longest_arc, white_runs
from tafel.modules.perception.spl_ball_detector import SPLBallDetector, Spot, carpet, carpet_sample
from tafel.representations.field import BALL_RADIUS
from tafel.representations.motion import CameraMatrix
from tafel.representations.perception import BallCandidate, BallImagePercept, FieldBoundary, GoalPost, GoalPostPercept, LinePercept


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
                spot = self.inside_image(spot, ~green)
                if any((spot.x - s.x) ** 2 + (spot.y - s.y) ** 2 <= (s.expected * 1.5) ** 2 for s in chosen):
                    continue
            chosen.append(spot)
            if len(chosen) >= p.max_spots:
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
    first, posts = self.post_columns(hsv, green, spot, white)
    if not beside_post and 0 <= int(spot.x) - first < len(posts) and posts[int(spot.x) - first]:
        return 0.0, True
    if (green_inside > p.green_inside_max or green_around < p.green_around_min or not p.dark_share_min <= dark <= p.dark_share_max
            or saturation > p.saturation_max or darkest > p.black_contrast * field_value):
        return 0.0, False
    return float(min(1.0, 0.5 + dark + 0.3 * green_around - green_inside)), False


def reference_beside_post(self: SPLBallDetector, hsv: np.ndarray, green: np.ndarray, spot: Spot, white: float) -> Spot | None:
    first, posts = self.post_columns(hsv, green, spot, white)
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
    sampled = carpet_sample(hsv, green)
    strict = self.strict_green(hsv, green, sampled)
    np.testing.assert_array_equal(strict, reference_strict_green(self, hsv, green))
    dark, old_dark = self.dark_pixels(hsv, green, sampled), reference_dark_pixels(self, hsv, green)
    assert (dark is None) == (old_dark is None)
    if dark is not None:
        np.testing.assert_array_equal(dark, old_dark)
    assert carpet(hsv, green, sampled) == carpet(hsv, green)
    for rows in (boundary, np.zeros(0, np.float32)):
        spots = self.spots(strict, rows, projection, dark)
        same_spots(spots, reference_spots(self, strict, rows, projection, old_dark))
    for spot in spots:
        for beside in (False, True):
            assert self.check(hsv, green, spot, white, beside) == reference_check(self, hsv, green, spot, white, beside)
        moved, old = self.beside_post(hsv, green, spot, white), reference_beside_post(self, hsv, green, spot, white)
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
            assert self.check(hsv, green, spot, white, beside) == reference_check(self, hsv, green, spot, white, beside)
        moved, old = self.beside_post(hsv, green, spot, white), reference_beside_post(self, hsv, green, spot, white)
        same_spots([moved] if moved else [], [old] if old else [])


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
@given(st.integers(0, 2**32 - 1), st.sampled_from([(320, 240), (64, 48), (50, 37)]), st.floats(0.05, 0.9), st.integers(1, 7))
def test_line_detectors_ignored_pixels_are_the_full_masks(seed: int, size: tuple[int, int], pitch: float, step: int) -> None:
    """The pixels ignored on the scan lines are the full mask's there: off the field, the own body, posts, balls."""
    rng = np.random.default_rng(seed)
    width, height = size
    boundary = np.clip(rng.normal(height / 3, height / 6, width), 0, height).astype(np.float32)
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
