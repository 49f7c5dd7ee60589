"""How SPLBallDetector's ball candidates are found: peaks of the non-green field's distance transform whose thickness
fits a ball there (``spots``), and the measures of the light they are judged by (the carpet's value and saturation,
``carpet_light``). The far balls on the field's edge are looked for in a band round the boundary (``far_ball_spots``);
each candidate is then checked (``ball_checks``)."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Protocol

import cv2
import numpy as np

from tafel.modules.perception.image_geometry import ImageProjection
from tafel.modules.perception.pixel_statistics import (
    below,
    byte_median,
    channel_histogram,
    every,
    histogram_median,
)
from tafel.representations.field import BALL_RADIUS


class SpotParameters(Protocol):
    """What these functions read of SPLBallDetector.Parameters."""

    above_boundary: float  # px
    black_contrast: float
    dark_spot_min: float
    max_spots: int
    min_radius: float  # px
    size_high: float
    size_low: float
    strict_saturation: float


#: candidates after ``spots``' tests up to which the greedy choice among them runs as a Python loop
#: (a frame mostly leaves a few dozen; beyond, numpy's calls on arrays cost less than the loop)
FEW_PEAKS = 64


@dataclass
class Spot:
    """A place in the image where a ball of the expected size could be (px)."""

    x: float
    y: float
    radius: float
    expected: float
    edge: bool = False
    """found by ``far_ball_spots.edge_spots`` (the field's edge, where the hall behind is)"""


def spots(green: np.ndarray, boundary: np.ndarray, projection: ImageProjection, p: SpotParameters,
          dark: np.ndarray | None = None) -> list[Spot]:
    """Peaks of the non-green field's distance transform whose thickness fits a ball there (and, given
    ``dark``, the pixels darker than the carpet, with black patches near them)."""
    height, width = green.shape
    known = boundary.size == width
    top = max(0, int(boundary.min() - p.above_boundary)) if known else 0  # nothing above the field is looked at
    solid = ~green[top:]
    if known:  # on the field: from the boundary (less above_boundary) down; below its lowest row, every row is
        lowest = boundary - p.above_boundary
        limit = float(lowest.max())
        rows = min(height - top, max(0, math.ceil(limit) - top)) if math.isfinite(limit) else height - top
        solid[:rows] &= np.arange(top, top + rows)[:, None] >= lowest[None, :]
    solid = solid.view(np.uint8)
    if not solid.any():
        return []
    thickness = cv2.distanceTransform(solid, cv2.DIST_L2, 3)
    peaks = (thickness >= p.min_radius) & (thickness >= cv2.dilate(thickness, np.ones((3, 3), np.uint8)))
    index = np.flatnonzero(peaks)  # a third of np.nonzero's time on a 2-D mask, same order
    if len(index) == 0:
        return []
    ys, xs = np.divmod(index, width)
    radii = thickness.ravel()[index]
    ys = ys + top
    if known:  # the centre lies on the field; only the top may reach over its edge
        on_field = ys >= boundary[xs]
        xs, ys, radii = xs[on_field], ys[on_field], radii[on_field]
    if dark is not None and len(xs):  # a ball has black patches: spots without dark pixels near their centre are none
        # (a field without any green leaves the distance transform unbounded: radii beyond the image are none).
        # The cheaper test first: it leaves a fifth of the peaks, whose size is then compared with a ball's there
        reach = np.minimum(np.maximum(radii, 1.0), max(height, width))
        first, last = max(0, int((ys - reach).min())), min(height, int((ys + reach).max()) + 1)  # the rows the squares reach
        patched = dark_share(dark[first:last], xs, ys - first, reach) >= p.dark_spot_min
        xs, ys, radii = xs[patched], ys[patched], radii[patched]
    centres, hits = projection.to_ground(xs, ys, BALL_RADIUS)
    distance = ball_ranges(centres, projection.translation)
    expected = np.where(hits, projection.fx * BALL_RADIUS / np.maximum(distance, 1.0), 0.0)
    fits = hits & (radii >= p.size_low * expected) & (radii <= p.size_high * expected + 1.0)
    xs, ys, radii, expected = xs[fits], ys[fits], radii[fits], expected[fits]
    # the spots most like a ball's size first: lines are thinner, robots and the border thicker
    order = np.argsort(np.abs(np.log(np.maximum(radii, 0.5) / np.maximum(expected, 0.5))))
    xs, ys, radii, expected = xs[order], ys[order], radii[order], expected[order]
    # greedily, each spot taken keeps the ones after it that are too close to it out
    if len(xs) > FEW_PEAKS:
        return chosen_spots(green, xs, ys, radii, expected, p)
    # the few peaks a frame mostly leaves as Python numbers: a loop over them is cheaper than numpy's calls on
    # arrays of a few elements (the same arithmetic: x * x is numpy's square of the offsets)
    xl, yl, rl, el = xs.tolist(), ys.tolist(), radii.tolist(), expected.tolist()
    free = [True] * len(xl)
    chosen: list[Spot] = []
    for i in range(len(xl)):
        if len(chosen) >= p.max_spots:
            break
        if not free[i]:
            continue
        r, e = rl[i], el[i]
        spot = Spot(float(xl[i]), float(yl[i]), max(r, 0.5 * (r + e)), e)
        if spot.x < e or spot.x > width - 1 - e or spot.y > height - 1 - e:
            spot = inside_image(spot, green, negated=True)  # moved: it may now be a spot chosen already
            if any((spot.x - s.x) ** 2 + (spot.y - s.y) ** 2 <= (s.expected * 1.5) ** 2 for s in chosen):
                continue
        chosen.append(spot)
        x, y, reach = spot.x, spot.y, (spot.expected * 1.5) ** 2
        for j in range(i + 1, len(xl)):
            if free[j]:
                dx, dy = xl[j] - x, yl[j] - y
                free[j] = dx * dx + dy * dy > reach
    return chosen


def chosen_spots(green: np.ndarray, xs: np.ndarray, ys: np.ndarray, radii: np.ndarray, expected: np.ndarray,
                 p: SpotParameters) -> list[Spot]:
    """``spots``' greedy choice over many peaks (each spot taken keeps the ones after it that are too close to it
    out, all at once)."""
    height, width = green.shape
    free = np.ones(len(xs), bool)
    chosen: list[Spot] = []
    start = 0
    while len(chosen) < p.max_spots and start < len(xs):
        start += int(np.argmax(free[start:]))
        if not free[start]:
            break
        x, y, r, e = xs[start], ys[start], radii[start], expected[start]
        start += 1
        spot = Spot(float(x), float(y), float(max(r, 0.5 * (r + e))), float(e))
        if spot.x < e or spot.x > width - 1 - e or spot.y > height - 1 - e:
            spot = inside_image(spot, green, negated=True)  # moved: it may now be a spot chosen already
            if any((spot.x - s.x) ** 2 + (spot.y - s.y) ** 2 <= (s.expected * 1.5) ** 2 for s in chosen):
                continue
        chosen.append(spot)
        free[start:] &= (xs[start:] - spot.x) ** 2 + (ys[start:] - spot.y) ** 2 > (spot.expected * 1.5) ** 2
    return chosen


def inside_image(spot: Spot, solid: np.ndarray, negated: bool = False) -> Spot:
    """A spot at the image's edge moved to where the ball's centre is: the peak of a ball cut by the
    edge lies on the edge, and the ball's far side is one expected radius from its centre. ``negated``:
    ``solid`` is the green mask, whose negation is the solid (only the row and column read are negated)."""
    height, width = solid.shape
    x, y, e = int(spot.x), int(spot.y), spot.expected
    if x < e or x > width - 1 - e:
        row = solid[min(max(y, 0), height - 1)]
        row = ~row if negated else row
        step = 1 if x < e else -1
        far = x
        while 0 <= far + step < width and row[far + step]:
            far += step
        spot.x = float(far - step * e)
    if y > height - 1 - e:  # a close ball cut by the image's bottom edge (its top is always in view)
        column = solid[:, min(max(int(spot.x), 0), width - 1)]
        column = ~column if negated else column
        far = min(y, height - 1)
        while far - 1 >= 0 and column[far - 1]:
            far -= 1
        spot.y = float(far + e)
    return spot


def dark_share(dark: np.ndarray, xs: np.ndarray, ys: np.ndarray, radii: np.ndarray) -> np.ndarray:
    """Share of dark pixels in the square of half side ``radii`` round each (x, y), by an integral image (of the
    part of the mask the squares cover: the same counts)."""
    height, width = dark.shape
    x0, x1 = np.minimum(np.maximum((xs - radii).astype(int), 0), width), np.minimum(np.maximum((xs + radii).astype(int) + 1, 0), width)
    y0, y1 = np.minimum(np.maximum((ys - radii).astype(int), 0), height), np.minimum(np.maximum((ys + radii).astype(int) + 1, 0), height)
    area = np.maximum((x1 - x0) * (y1 - y0), 1)
    if not len(area):
        return np.zeros(0)
    left, top = int(x0.min()), int(y0.min())
    part = dark[top : int(y1.max()), left : int(x1.max())]
    integral = cv2.integral(part.view(np.uint8) if part.dtype == np.bool_ else part.astype(np.uint8))
    x0, x1, y0, y1 = x0 - left, x1 - left, y0 - top, y1 - top
    return (integral[y1, x1] - integral[y0, x1] - integral[y1, x0] + integral[y0, x0]) / area


def ball_ranges(centres: np.ndarray, eye: np.ndarray) -> np.ndarray:
    """mm from the camera at ``eye`` (x, y, z) to balls lying at ``centres`` (N x 2, their centres ``BALL_RADIUS`` up):
    ``np.linalg.norm`` of the offsets (N x 3) along their rows, the same sums of squares in the same order, without
    building the points."""
    dx, dy, dz = centres[:, 0] - eye[0], centres[:, 1] - eye[1], BALL_RADIUS - eye[2]
    return np.sqrt(dx * dx + dy * dy + dz * dz)


def carpet_sample(hsv: np.ndarray, green: np.ndarray) -> np.ndarray:
    """The carpet's pixels (N x 3, HSV) on every fourth row and column: what the measures of the light use."""
    return hsv[::4, ::4][green[::4, ::4]]


@dataclass
class CarpetLight:
    """The measures of the light from ``carpet_sample``: how many pixels it holds, and their median value and
    saturation (0 where it holds none)."""

    count: int
    value: float
    saturation: float


def carpet_light(hsv: np.ndarray, green: np.ndarray) -> CarpetLight:
    """``carpet_sample``'s count and medians (the same numbers), from the sample's histograms instead of its pixels."""
    sampled, carpet = every(hsv, 4), every(green, 4)
    values, saturations = (channel_histogram(sampled, channel, carpet) for channel in (2, 1))
    count = int(values.sum())
    if not count:
        return CarpetLight(0, 0.0, 0.0)
    return CarpetLight(count, histogram_median(values), histogram_median(saturations))


def carpet(hsv: np.ndarray, green: np.ndarray, light: CarpetLight | None = None) -> tuple[float, float]:
    """The carpet's median value and saturation (sampled), the measures of the light; (128, 128) without carpet.
    ``light``: ``carpet_light(hsv, green)`` where it is at hand."""
    if light is None:
        light = carpet_light(hsv, green)
    if light.count < 10:
        return 128.0, 128.0
    return light.value, light.saturation


def strict_green(hsv: np.ndarray, green: np.ndarray, p: SpotParameters, sampled: CarpetLight | None = None) -> np.ndarray:
    """The green mask without the pixels much less saturated than the carpet's median. ``sampled``:
    ``carpet_light(hsv, green)`` where it is at hand."""
    if not green.any():
        return green
    if sampled is None:
        sampled = carpet_light(hsv, green)
    median = sampled.saturation if sampled.count else byte_median(hsv[..., 1][green])
    threshold = p.strict_saturation * median
    limit = math.ceil(threshold) - 1 if math.isfinite(threshold) else -1  # for bytes, not below t is above ceil(t) - 1
    if hsv.size and 0 <= limit < 255:  # by OpenCV in one pass each, without numpy's negation and its arrays
        saturated = cv2.threshold(cv2.extractChannel(hsv, 1), limit, 1, cv2.THRESH_BINARY)[1]
        return cv2.bitwise_and(np.ascontiguousarray(green).view(np.uint8), saturated).view(bool)
    return green & ~below(hsv, 1, threshold)


def dark_pixels(hsv: np.ndarray, green: np.ndarray, p: SpotParameters, sampled: CarpetLight | None = None) -> np.ndarray | None:
    """Pixels darker than ``black_contrast`` times the carpet's median value (the ball's black patches
    are); None without carpet to compare with. ``sampled``: ``carpet_light(hsv, green)`` where it is at hand."""
    if sampled is None:
        sampled = carpet_light(hsv, green)
    if sampled.count < 10:
        return None
    return below(hsv, 2, p.black_contrast * sampled.value)
