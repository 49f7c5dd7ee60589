"""How SPLBallDetector checks each ball candidate (``check``, ``verdict``): not green inside, green round most of its
edge, black patches darker than the carpet around among its white, no colour, no post rising above it; a ball
behind a post is looked for beside it (``beside_post``), and one cut by the image's edge is centred on what is seen
of it (``fit_visible``)."""

from __future__ import annotations

import math
from typing import Protocol

import numpy as np

from tafel.modules.perception.ball_spots import Spot
from tafel.modules.perception.pixel_statistics import byte_median, byte_percentile, histogram_percentile


class CheckParameters(Protocol):
    """What these functions read of SPLBallDetector.Parameters."""

    black_contrast: float
    white_over_dark_carpet: float
    dark_ratio: float
    dark_share_max: float
    dark_share_min: float
    green_around_min: float
    green_inside_max: float
    post_share: float
    post_white: float
    saturation_max: float


#: every byte's value (int64), to sum bytes from their histogram
BYTE_VALUES = np.arange(256, dtype=np.int64)
#: ``HYPOT[i, j]``: ``np.hypot(j, i)`` (px), for the pixels' distances from a spot on a whole pixel (``distances``)
HYPOT_REACH = 128
HYPOT = np.hypot(np.arange(HYPOT_REACH, dtype=float)[None, :], np.arange(HYPOT_REACH, dtype=float)[:, None])

#: the tests of ``verdict`` whose thresholds the second look loosens: a spot that failed another one
#: (too few pixels, under a post, too much green round it) fails it again with the looser thresholds
LOOSER_TESTS = ("saturation", "dark", "black")


def check(hsv: np.ndarray, green: np.ndarray, spot: Spot, white: float, p: CheckParameters, beside_post: bool = False,
          parameters: CheckParameters | None = None) -> tuple[float, bool]:
    """(0 if the spot is no ball, else a score in (0, 1]: how well it fits; whether a post rises over
    it). ``white``: the value (V) of the image's brightest non-green pixels. ``p``: the module's parameters.
    ``beside_post``: the spot was moved off a post already (its edge may still be in the way above).
    ``parameters``: other thresholds than the module's (``second_look``)."""
    score, under, _ = verdict(hsv, green, spot, white, p, beside_post, parameters)
    return score, under


def verdict(hsv: np.ndarray, green: np.ndarray, spot: Spot, white: float, p: CheckParameters, beside_post: bool = False,
            parameters: CheckParameters | None = None) -> tuple[float, bool, str]:
    """``check``'s (score, under a post) and the test a spot that is no ball failed (``LOOSER_TESTS``: one that the
    second look's thresholds loosen; "" for a ball)."""
    thresholds = parameters or p  # the post's test is the module's always
    height, width = green.shape
    r = spot.radius
    reach = int(math.ceil(r * 1.7)) + 1
    x0, x1 = max(0, int(spot.x) - reach), min(width, int(spot.x) + reach + 1)
    y0, y1 = max(0, int(spot.y) - reach), min(height, int(spot.y) + reach + 1)
    d = distances(x0, x1, y0, y1, spot.x, spot.y)
    inside, around = d <= 0.9 * r, (d >= 1.2 * r) & (d <= 1.7 * r)
    n_inside, n_around = np.count_nonzero(inside), np.count_nonzero(around)
    if n_inside < 3 or n_around < 3:
        return 0.0, False, "size"
    patch_green, patch = green[y0:y1, x0:x1], hsv[y0:y1, x0:x1]
    solid = np.greater(inside, patch_green)  # inside & ~patch_green: the ball's own pixels (green ones would count as dark)
    n_solid = np.count_nonzero(solid)
    if n_solid < 3:
        return 0.0, False, "size"
    if not beside_post and under_post(hsv, green, spot, white, p):
        return 0.0, True, "post"
    # the tests one by one, the cheapest first: most spots fail one of the first
    green_inside = (n_inside - n_solid) / n_inside  # the inside's green pixels are those not solid
    green_around = np.count_nonzero(patch_green & around) / n_around
    if green_inside > thresholds.green_inside_max or green_around < thresholds.green_around_min:
        return 0.0, False, "green"
    saturation = int(np.add.reduce(patch[..., 1][inside], dtype=np.int64)) / n_inside  # the mean: an exact sum, divided
    if saturation > thresholds.saturation_max:
        return 0.0, False, "saturation"
    # the own pixels' values by their histogram: the 90th percentile (np.percentile's), and the dark ones (below
    # dark_ratio of it: the bytes below its ceiling) counted and summed from it, not gathered
    counts = np.bincount(patch[..., 2][solid], minlength=256)
    bright = histogram_percentile(counts, 90)
    dark_bytes = min(256, max(0, math.ceil(thresholds.dark_ratio * bright)))
    n_dark = int(np.add.reduce(counts[:dark_bytes]))
    dark = n_dark / n_solid
    if not thresholds.dark_share_min <= dark <= thresholds.dark_share_max:
        return 0.0, False, "dark"
    carpet = patch[..., 2][around & patch_green]
    field_value = byte_median(carpet if carpet.size >= 3 else patch[..., 2][around])
    darkest = int(counts[:dark_bytes] @ BYTE_VALUES[:dark_bytes]) / n_dark if n_dark else math.inf  # the black patches' mean
    if darkest > thresholds.black_contrast * field_value and not alone_on_dark_carpet(green, spot, bright, field_value, green_around,
                                                                                      thresholds):
        return 0.0, False, "black"
    return float(min(1.0, 0.5 + dark + 0.3 * green_around - green_inside)), False, ""


def alone_on_dark_carpet(green: np.ndarray, spot: Spot, bright: float, field_value: float, green_around: float,
                         p: CheckParameters) -> bool:
    """Whether the spot's white (``bright``) vouches for its black patches though they are no darker than the carpet
    (``field_value``): on a dark carpet, a white ``white_over_dark_carpet`` times the carpet's value, with the carpet
    round twice ``green_around_min`` of its edge (``green_around``) and right above it (rows 1.2 to 2 radii up, its
    middle). Shadows and dark corners have no such white, a robot's foot has its leg above it."""
    return (bright >= p.white_over_dark_carpet * field_value and green_around >= 2 * p.green_around_min
            and green_above(green, spot, 1.2, 2.0, 0.5) >= 0.8)


def green_above(green: np.ndarray, spot: Spot, nearest: float, farthest: float, half_width: float) -> float:
    """The carpet's share of the rows ``nearest`` to ``farthest`` radii above the spot, ``half_width`` radii to either
    side of its column (the larger of its radius and the expected one); 0 where none of them is in the image."""
    size = max(spot.radius, spot.expected)
    y0, y1 = int(max(0, spot.y - farthest * size)), int(max(0, spot.y - nearest * size))
    x0, x1 = int(max(0, spot.x - half_width * size)), int(spot.x + half_width * size) + 1
    above = green[y0:y1, x0:x1]
    return np.count_nonzero(above) / above.size if above.size else 0.0


def under_post(hsv: np.ndarray, green: np.ndarray, spot: Spot, white: float, p: CheckParameters) -> bool:
    """Whether ``post_columns`` flags the spot's own column (only that column measured)."""
    column = int(spot.x)
    x0, x1 = max(0, int(spot.x - 3 * spot.radius)), min(green.shape[1], int(spot.x + 3 * spot.radius) + 1)
    y0, y1 = int(max(0, spot.y - 4 * spot.radius)), int(max(0, spot.y - 1.5 * spot.radius))
    if not x0 <= column < x1 or y1 - y0 < 2:
        return False
    r = max(1, int(spot.radius))
    own = hsv[max(0, int(spot.y) - r) : int(spot.y) + r + 1, max(0, int(spot.x) - r) : int(spot.x) + r + 1, 2]
    white = max(white, float(own.max())) if own.size else white
    above = hsv[y0:y1, column]
    whites = (above[:, 2] >= p.post_white * white) & (above[:, 1] <= p.saturation_max) & ~green[y0:y1, column]
    return bool(np.count_nonzero(whites) / len(whites) >= p.post_share) and not carpet_below_post(green, spot)


def carpet_below_post(green: np.ndarray, spot: Spot) -> bool:
    """Whether the carpet shows between the spot's top and what rises above it (its column, 1.1 to 1.6 radii up): then
    the spot is no post's foot, which is the post itself, but a ball in front of a farther post or below a line running
    away from the camera (near-vertical in the image)."""
    return green_above(green, spot, 1.1, 1.6, 0.0) >= 0.5


def post_columns(hsv: np.ndarray, green: np.ndarray, spot: Spot, white: float, p: CheckParameters) -> tuple[int, np.ndarray]:
    """(first column, flags): for the columns within three radii of the spot, whether something white
    rises above the spot's row there (a goal post, or a robot's leg), judged on the rows 1.5 to 4
    radii above it. White is measured against the brighter of ``white`` and the spot's own white: where the
    image's white is taken too low, the hall's grey behind a far ball would be a post."""
    r = max(1, int(spot.radius))
    own = hsv[max(0, int(spot.y) - r) : int(spot.y) + r + 1, max(0, int(spot.x) - r) : int(spot.x) + r + 1, 2]
    white = max(white, float(own.max())) if own.size else white
    x0, x1 = max(0, int(spot.x - 3 * spot.radius)), min(green.shape[1], int(spot.x + 3 * spot.radius) + 1)
    y0, y1 = int(max(0, spot.y - 4 * spot.radius)), int(max(0, spot.y - 1.5 * spot.radius))
    if y1 - y0 < 2 or x1 <= x0:
        return x0, np.zeros(max(0, x1 - x0), bool)
    above = hsv[y0:y1, x0:x1]
    whites = (above[..., 2] >= p.post_white * white) & (above[..., 1] <= p.saturation_max) & ~green[y0:y1, x0:x1]
    return x0, whites.mean(axis=0) >= p.post_share


def beside_post(hsv: np.ndarray, green: np.ndarray, spot: Spot, white: float, p: CheckParameters) -> Spot | None:
    """Where a ball seen next to a post (partly behind it) has its centre. A post hides a vertical
    strip of it, so the row where the non-green run leaving the post's side is longest is the
    ball's centre row, and that run ends at its far edge, one radius from the centre."""
    first, posts = post_columns(hsv, green, spot, white, p)
    height, width = green.shape
    post = np.nonzero(posts)[0]
    if len(post) == 0:
        return None
    low, high = max(0, int(spot.y - 2 * spot.radius)), min(height, int(spot.y + 2 * spot.radius) + 1)
    if low >= high:
        return None
    solid = ~green[low:high]  # the rows searched
    solid[:, first : first + len(posts)] &= ~posts
    # per row, right of the post then left of it: the non-green run from the post's side outwards
    extents, centres = [], []
    for edge, step in ((first + int(post.max()) + 1, 1), (first + int(post.min()) - 1, -1)):
        if not 0 <= edge < width:
            extents.append(np.zeros(high - low, int))
            centres.append(np.zeros(high - low))
            continue
        run = solid[:, edge::step] if step == 1 else solid[:, edge::-1]
        extent = np.where(run.all(axis=1), run.shape[1], np.argmin(run, axis=1))  # 0 where the edge is green
        extents.append(extent)
        centres.append((edge + step * (extent - 1)) - step * spot.expected)
    extent = np.column_stack(extents).ravel()  # row by row, right before left: the order the first longest is taken in
    usable = (extent > 0) & (extent <= 2 * spot.expected + 2)
    if not usable.any():
        return None
    best = int(np.argmax(np.where(usable, extent, -1)))
    if extent[best] < 0.5 * spot.expected:
        return None
    return Spot(float(np.column_stack(centres).ravel()[best]), float(low + best // 2), spot.expected, spot.expected)


def near_edge(spot: Spot, shape: tuple[int, ...]) -> bool:
    """Whether the ball at ``spot`` may reach out of the image (its expected radius and a half)."""
    height, width = shape[:2]
    reach = 1.5 * max(spot.expected, spot.radius)
    return spot.x < reach or spot.x > width - 1 - reach or spot.y < reach or spot.y > height - 1 - reach


def fit_visible(hsv: np.ndarray, green: np.ndarray, spot: Spot, rays: int = 24) -> Spot | None:
    """The spot re-centred on the visible part of the ball's outline, or None if too little of it is seen.
    Near the image's edge the distance transform's peak is off the ball's centre (the edge cuts the ball,
    its shadow or a foot beside it widens the blob): along rays from the spot, the last of the ball's
    bright pixels before the carpet is a point of its outline; rays that leave the image first saw none.
    A circle of the expected radius is fitted to those points (Gauss-Newton, the worst fifth dropped)."""
    height, width = green.shape
    r = max(spot.expected, 1.0)
    angles = np.linspace(0.0, 2 * math.pi, rays, endpoint=False)
    steps = np.arange(0.3 * r, 1.8 * r, 1.0)
    xs = spot.x + np.cos(angles)[:, None] * steps[None, :]
    ys = spot.y + np.sin(angles)[:, None] * steps[None, :]
    seen = (xs >= 0) & (xs <= width - 1) & (ys >= 0) & (ys <= height - 1)
    xi, yi = np.clip(np.round(xs).astype(int), 0, width - 1), np.clip(np.round(ys).astype(int), 0, height - 1)
    inner = (np.hypot(xi - spot.x, yi - spot.y) <= 0.9 * r) & ~green[yi, xi]
    if inner.sum() < 3:
        return None
    bright = byte_percentile(hsv[yi, xi, 2][inner], 90)
    ball = seen & ~green[yi, xi] & (hsv[yi, xi, 2] >= 0.6 * bright)
    last = np.where(ball.any(axis=1), steps.size - 1 - np.argmax(ball[:, ::-1], axis=1), -1)
    index = np.arange(rays)
    ends = (last >= 0) & (last + 1 < steps.size)
    ends &= seen[index, np.minimum(last + 1, steps.size - 1)]  # the outline is in sight, not cut by the edge
    points = np.column_stack([xs[index, np.maximum(last, 0)], ys[index, np.maximum(last, 0)]])[ends]
    if len(points) < rays // 4:
        return None
    cx, cy = spot.x, spot.y
    for keep in (1.0, 0.8):
        for _ in range(10):
            dx, dy = points[:, 0] - cx, points[:, 1] - cy
            distance = np.maximum(np.hypot(dx, dy), 1e-6)
            ux, uy, residual = dx / distance, dy / distance, distance - r
            # the Gauss-Newton step: the least-squares solution of (the unit vectors) . step = residual, by the 2x2
            # normal equations (numpy's lstsq costs more than the fit)
            a, b, c = float(ux @ ux), float(ux @ uy), float(uy @ uy)
            determinant = a * c - b * b
            if determinant <= 1e-9 * max(a * c, 1e-12):  # the points on one line through the centre: no step is sure
                break
            gx, gy = float(ux @ residual), float(uy @ residual)
            sx, sy = (c * gx - b * gy) / determinant, (a * gy - b * gx) / determinant
            cx, cy = cx + sx, cy + sy
            if math.hypot(sx, sy) < 0.05:
                break
        if keep < 1.0:
            break
        residual = np.abs(np.hypot(points[:, 0] - cx, points[:, 1] - cy) - r)
        ordered = np.sort(residual)  # np.quantile(residual, 0.8), its linear interpolation, without its overhead
        virtual = 0.8 * (len(ordered) - 1)
        low = int(virtual)
        worst = ordered[low] + (ordered[min(low + 1, len(ordered) - 1)] - ordered[low]) * (virtual - low)
        points = points[residual <= worst]
    if math.hypot(cx - spot.x, cy - spot.y) > r:
        return None  # not the spot's ball any more
    return Spot(float(cx), float(cy), r, spot.expected)


def square_inside(spot: Spot, shape: tuple[int, ...]) -> bool:
    """Whether the classifier's square round ``spot`` (1.1 radii either side) lies within an image of ``shape``."""
    height, width = shape[:2]
    side = 1.1 * spot.radius
    return side <= spot.x <= width - side and side <= spot.y <= height - side


def distances(x0: int, x1: int, y0: int, y1: int, x: float, y: float) -> np.ndarray:
    """The distance (px) of each pixel of columns ``x0:x1`` and rows ``y0:y1`` from (x, y): ``np.hypot`` of the offsets.
    From a whole pixel (the distance transform's peaks mostly are), within ``HYPOT_REACH``, the offsets are whole and
    the distances are looked up in ``HYPOT`` (hypot's value does not depend on the offsets' signs): the same numbers,
    a fraction of the time."""
    if float(x).is_integer() and float(y).is_integer():
        dx0, dx1, dy0, dy1 = x0 - int(x), x1 - int(x), y0 - int(y), y1 - int(y)  # the offsets of the first and after the last
        if max(-dx0, dx1 - 1, -dy0, dy1 - 1) < HYPOT_REACH:
            return HYPOT.take(np.abs(np.arange(dy0, dy1)), axis=0).take(np.abs(np.arange(dx0, dx1)), axis=1)
    return np.hypot(np.arange(x0, x1)[None, :] - x, np.arange(y0, y1)[:, None] - y)
