"""How SPLBallDetector finds far balls on the field's edge (``edge_search``): ball-coloured blobs in a band round the
field boundary (``edge_spots``), where the hall's non-green merges with a ball in ``ball_spots.spots``' distance
transform; the band's candidates measured all at once (their centroids, the carpet below them, the white in both
their halves)."""
from __future__ import annotations

import math
from typing import Protocol

import cv2
import numpy as np

from tafel.modules.perception.ball_spots import Spot, ball_ranges, dark_share
from tafel.modules.perception.image_geometry import ImageProjection
from tafel.modules.perception.pixel_statistics import below, white_pixels
from tafel.representations.field import BALL_RADIUS


class EdgeParameters(Protocol):
    """What these functions read of SPLBallDetector.Parameters."""

    dark_spot_min: float
    edge_above: int  # px
    edge_below: int  # px
    edge_black: float
    edge_green_below: float
    edge_max_radius: float  # px
    edge_max_spots: int
    edge_white: float
    edge_white_halves: float
    min_radius: float  # px
    saturation_max: float
    size_high: float
    size_low: float


#: px round a candidate of the band search that its checks look at: its thickness (a ball at most 14.5 px, from the
#: distance transform of the pixels within 17 px), its black patches (a square of its thickness) and its centre
#: moved twice by up to a radius (9 px), then its disc (9 px); beyond them, the band's pixels change nothing
EDGE_REACH = 30


def edge_spots(hsv: np.ndarray, green: np.ndarray, boundary: np.ndarray, projection: ImageProjection, carpet_value: float,
               taken: list[Spot], p: EdgeParameters) -> list[Spot]:
    """Far balls on the field's edge: there a ball reaches over the carpet into the hall, whose non-green merges with it
    in ``spots``' distance transform. In a band round the boundary only ball-coloured pixels count (white: brighter
    than the carpet, without colour; black: far darker than it), so the hall's middle greys part the ball from what
    is behind it; peaks of their distance transform whose thickness fits a small ball there, with black pixels
    near, away from the spots ``taken`` already."""
    height, width = green.shape
    if boundary.size != width:
        return []
    columns = np.linspace(0, width - 1, 9).astype(int)  # a ball on the edge would be too large for the band here?
    centres, hits = projection.to_ground(columns, np.minimum(boundary[columns], height - 1), BALL_RADIUS)
    ranges = ball_ranges(centres, projection.translation)
    if not (hits & (projection.fx * BALL_RADIUS / np.maximum(ranges, 1.0) <= p.edge_max_radius)).any():
        return []  # the bottom camera, or the top one looking down: the edge is near, its balls stand out on the green
    top = max(0, int(boundary.min()) - p.edge_above)
    bottom = min(height, int(boundary.max()) + p.edge_below + 1)
    if bottom - top < 3:
        return []
    left, right, bottom = edge_window(boundary, projection, bottom, p)
    rows = np.arange(top, bottom)[:, None]
    band = (rows >= boundary[None, left:right] - p.edge_above) & (rows <= boundary[None, left:right] + p.edge_below)
    box = hsv[top:bottom, left:right]
    value = box[..., 2]
    black = below(box, 2, math.floor(p.edge_black * carpet_value) + 1)  # value <= edge_black * carpet_value
    white = white_pixels(box, p.saturation_max, p.edge_white * carpet_value)
    ballish = cv2.bitwise_and(cv2.morphologyEx(cv2.bitwise_and(cv2.bitwise_or(white.view(np.uint8), black.view(np.uint8)),
                                                               (~green[top:bottom, left:right]).view(np.uint8)),
                                               cv2.MORPH_CLOSE, np.ones((3, 3), np.uint8)), band.view(np.uint8))
    if not ballish.any():
        return []
    thickness = cv2.distanceTransform(ballish, cv2.DIST_L2, 3)
    peaks = (thickness >= p.min_radius) & (thickness >= cv2.dilate(thickness, np.ones((3, 3), np.uint8)))
    peaks &= thickness <= np.float64(p.size_high * p.edge_max_radius + 1.0)  # thicker than any ball the band looks for
    index = np.flatnonzero(peaks)
    if len(index) == 0:
        return []
    ys, xs = np.divmod(index, right - left)
    radii = thickness.ravel()[index]
    patched = dark_share(black, xs, ys, np.maximum(radii, 1.0)) >= p.dark_spot_min  # the cheaper test first
    xs, ys, radii = xs[patched], ys[patched], radii[patched]
    centres, hits = projection.to_ground(xs + left, ys + top, BALL_RADIUS)
    distance = ball_ranges(centres, projection.translation)
    expected = np.where(hits, projection.fx * BALL_RADIUS / np.maximum(distance, 1.0), 0.0)
    fits = hits & (expected <= p.edge_max_radius) & (radii >= p.size_low * expected) & (radii <= p.size_high * expected + 1.0)
    if not fits.any():
        return []
    xs, ys, radii, expected = xs[fits] + left, ys[fits] + top, radii[fits], expected[fits]
    order = np.argsort(np.abs(np.log(np.maximum(radii, 0.5) / np.maximum(expected, 0.5))))
    best = order[: 10 * p.edge_max_spots]  # the best fitting few: a noisy hall has thousands of peaks
    xs, ys, radii, expected = xs[best].astype(float), ys[best].astype(float), radii[best], expected[best]
    # each one's centre: the peak lies off the centre of a ball this small, the centroid of its pixels round it (twice)
    cx, cy = xs, ys - top
    for _ in range(2):
        cx, cy = centroids(ballish, cx, cy, expected, left)
    cy = cy + top
    on_carpet = green_below(green, cx, cy, expected) >= p.edge_green_below  # not a shoe or a box on the hall's floor
    # white on both sides, not white beside black (a pair of shoes, a white box with a dark one)
    whites = white_halves(value, cx, cy - top, expected, left) >= p.edge_white_halves
    chosen: list[Spot] = []
    for i in np.flatnonzero(on_carpet & whites):  # in their order; the others are never chosen
        x, y, e = float(xs[i]), float(ys[i]), float(expected[i])
        if any((x - s.x) ** 2 + (y - s.y) ** 2 <= (max(s.expected, e) * 1.5) ** 2 for s in (*taken, *chosen)):
            continue
        chosen.append(Spot(float(cx[i]), float(cy[i]), max(float(radii[i]), e), e, edge=True))
        if len(chosen) >= p.edge_max_spots:
            break
    return chosen


def edge_window(boundary: np.ndarray, projection: ImageProjection, bottom: int, p: EdgeParameters
                ) -> tuple[int, int, int]:
    """(first column, column after the last, row after the last) of the band (rows down to ``bottom``) round the part
    where a ball would be at most ``edge_max_radius`` px (nearer ones the candidates of the green find), with everything
    that decides about a ball there (``EDGE_REACH`` px round it); the band's whole rows where it is nowhere.
    Down a column a ball grows: in each column the ball's size at the band's top, middle and bottom row tells where
    that part ends (at the highest row where it is too large, or the band's bottom)."""
    width = boundary.size
    xs = np.arange(width)
    levels = (-p.edge_above, (p.edge_below - p.edge_above) // 2, p.edge_below)  # px from the boundary
    rows = np.concatenate([np.minimum(np.maximum(boundary + level, 0), projection.height - 1) for level in levels])
    centres, hits = projection.to_ground(np.tile(xs, len(levels)), rows, BALL_RADIUS)
    offset = centres - projection.translation[:2]
    reach2 = np.einsum("ij,ij->i", offset, offset) + (BALL_RADIUS - projection.translation[2]) ** 2
    small = (hits & (reach2 >= (projection.fx * BALL_RADIUS / p.edge_max_radius) ** 2)).reshape(len(levels), width)
    # the band's top above the horizon: just below the horizon a ball is as small as can be
    small[0] |= ~hits[:width] & hits[-width:]
    seen = small[0] | small[1] | small[2]
    if not seen.any():
        return 0, width, bottom
    ends = rows.reshape(len(levels), width)
    last = np.where(small[1] | small[2] | ~hits[width : 2 * width], ends[2], ends[1])  # the lowest row it may reach
    columns = xs[seen]
    # OpenCV's distance transform rounds a pixel's distance as its place in the row's blocks of 64 lets it: the window
    # keeps the blocks the whole row has (the same distances to the last bit)
    left = max(0, int(columns[0]) - EDGE_REACH) // 64 * 64
    right = min(width, left + -(-(int(columns[-1]) + EDGE_REACH + 1 - left) // 64) * 64)
    if right > width - width % 64:
        right = width
    return left, right, min(bottom, int(last[seen].max()) + EDGE_REACH + 2)


def centroids(mask: np.ndarray, xs: np.ndarray, ys: np.ndarray, radii: np.ndarray, left: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """For each point (xs, ys; px, float): the centroid of ``mask``'s pixels within its radius; the point itself where
    there are none. ``left``: the image column of the mask's first one (xs and the centroids' x are the image's)."""
    if len(xs) == 0:
        return xs, ys
    reach = int(math.ceil(float(radii.max())))
    span = range(-reach, reach + 1)
    cols, rows, inside, flat = windows(np.rint(xs).astype(int), np.rint(ys).astype(int), span, span, mask.shape, left)
    dx, dy = cols - xs[:, None], rows - ys[:, None]
    near = (mask.ravel()[flat] > 0) & inside & ((dx * dx)[:, None, :] + (dy * dy)[:, :, None] <= (radii * radii)[:, None, None])
    count = np.count_nonzero(near, axis=(1, 2))
    some = count > 0
    share = np.maximum(count, 1)
    x = np.where(some, (near.sum(axis=1) * cols).sum(axis=1) / share, xs)
    y = np.where(some, (near.sum(axis=2) * rows).sum(axis=1) / share, ys)
    return x, y


def green_below(green: np.ndarray, xs: np.ndarray, ys: np.ndarray, radii: np.ndarray) -> np.ndarray:
    """For each point (px): the carpet's share of the lower half of the ring 1.2 to 1.7 radii round it (0 where the
    ring lies out of the image): a ball lies on the carpet."""
    if len(xs) == 0:
        return np.zeros(0)
    reach = int(math.ceil(1.7 * float(radii.max()))) + 1
    cols, rows, inside, flat = windows(xs.astype(int), ys.astype(int), range(-reach, reach + 1), range(reach + 1), green.shape)
    d = np.hypot((cols - xs[:, None])[:, None, :], (rows - ys[:, None])[:, :, None])
    ring = (d >= (1.2 * radii)[:, None, None]) & (d <= (1.7 * radii)[:, None, None]) & (rows > ys[:, None])[:, :, None] & inside
    count = np.count_nonzero(ring, axis=(1, 2))
    return np.where(count > 0, np.count_nonzero(green.ravel()[flat] & ring, axis=(1, 2)) / np.maximum(count, 1), 0.0)


def white_halves(value: np.ndarray, xs: np.ndarray, ys: np.ndarray, radii: np.ndarray, left: int = 0) -> np.ndarray:
    """For each point (px): the lesser share of white (at least 0.6 of the brightest) in the left and the right half
    of the disc of its radius in the value image (0 where a half lies out of it): a ball's black patches lie among
    its white, on both sides. ``left``: the image column of the value image's first one (xs are the image's)."""
    if len(xs) == 0:
        return np.zeros(0)
    reach = int(math.ceil(float(radii.max())))
    span = range(-reach, reach + 1)
    cols, rows, inside, flat = windows(np.rint(xs).astype(int), np.rint(ys).astype(int), span, span, value.shape, left)
    dx, dy = cols - xs[:, None], rows - ys[:, None]
    disc = ((dx * dx)[:, None, :] + (dy * dy)[:, :, None] <= (radii**2)[:, None, None]) & inside
    patch = value.ravel()[flat] if value.flags.c_contiguous else np.ascontiguousarray(value).ravel()[flat]
    brightest = np.where(disc, patch, 0).max(axis=(1, 2))
    white = patch >= (0.6 * brightest)[:, None, None]
    shares = []
    for side in (cols < xs[:, None], cols > xs[:, None]):
        half = disc & side[:, None, :]
        count = np.count_nonzero(half, axis=(1, 2))
        shares.append((count > 0, np.count_nonzero(white & half, axis=(1, 2)) / np.maximum(count, 1)))
    (left_seen, left_share), (right_seen, right_share) = shares
    return np.where(left_seen & right_seen, np.minimum(left_share, right_share), 0.0)


def windows(xs: np.ndarray, ys: np.ndarray, columns: range, rows: range, shape: tuple[int, int], left: int = 0
            ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """For n points: the image columns (n x c) and rows (n x r) of a window round each (offsets ``columns`` from
    ``xs``, ``rows`` from ``ys``, both integers), which of its pixels lie in an image of ``shape`` whose first column
    is image column ``left`` (n x r x c), and the indices (n x r x c) that gather them from it (the nearest inside
    for those outside)."""
    height, width = shape
    cols = xs[:, None] + np.asarray(columns)[None, :]
    rws = ys[:, None] + np.asarray(rows)[None, :]
    inside = ((rws >= 0) & (rws < height))[:, :, None] & ((cols >= left) & (cols < left + width))[:, None, :]
    flat = np.minimum(np.maximum(rws, 0), height - 1)[:, :, None] * width + np.minimum(np.maximum(cols - left, 0), width - 1)[:, None, :]
    return cols, rws, inside, flat
