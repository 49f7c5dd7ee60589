"""A goal post candidate's shape (GoalPostDetector): its width at its foot's distance, its foot near the boundary, its
summit (``shapes``); the rows along its rise and above its foot (``Rows``), judged all at once (``upright``) by the
means of strips of pixels and their medians, as numpy gives them for each post alone."""

from __future__ import annotations

from collections.abc import Callable
from typing import Protocol

import cv2
import numpy as np

from tafel.modules.perception.goal_post_band import corner_sums, row_norms, ycrcb
from tafel.modules.perception.image_geometry import ImageProjection
from tafel.representations.field import GOAL_HEIGHT, GOAL_POST_DIAMETER
from tafel.representations.perception import GoalPost


class ShapeParameters(Protocol):
    """What these functions read of GoalPostDetector.Parameters."""

    contrast_min: float  # YCrCb
    max_behind: float  # mm
    min_height: float  # post widths
    rise: float
    uniform_max: float  # YCrCb
    width_low: float
    width_tolerance: float


Rows = tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]
"""rows of the image (``ys``), a post's centre column in each (``xs``) and the post's width (px) in each, the
posts' rows one post after the other; and how many rows each post has"""


def shapes(camera: str, left: np.ndarray, right: np.ndarray, foot: np.ndarray, top: np.ndarray, projection: ImageProjection,
           height: int, p: ShapeParameters) -> tuple[list[GoalPost | None], Rows, Rows]:
    """For the edges at columns ``left`` and ``right`` with a foot at row ``foot`` (the first rows of
    carpet below the boundary between them) whose band passed its checks, in an image ``height`` rows high:
    the post, if its width and height fit one, else None; and for those posts in turn the rows in which the
    white must rise along its axis and those in which it must reach down to the foot (for ``upright``). All at once, by the
    very operations the pixel-by-pixel code did for each (``ImageProjection``'s ``exact``, ``exact_norms``, numpy's
    linspace), so the posts are the same to the last bit."""
    if not len(left):
        nothing = np.zeros(0, int)
        return [], (nothing, nothing, nothing, nothing), (nothing, nothing, nothing, nothing)
    post_width = right - left
    centre = (left + right) / 2
    column = (left + right) // 2  # int(centre)
    ground, hit = projection.to_ground(centre, foot + 0.5, exact=True)
    distance = exact_norms(np.column_stack([ground, np.zeros(len(left))]) - projection.translation)
    expected = projection.fx * GOAL_POST_DIAMETER / np.where(hit, distance, 1.0)
    fits = hit & ~((post_width - expected > p.width_tolerance * expected + 1.5) | (post_width < p.width_low * expected - 1.0))
    # the foot near the boundary: the boundary no farther behind it than max_behind
    eye = projection.translation[:2]
    direction = (ground - eye) / np.maximum(exact_norms(ground - eye), 1.0)[:, None]
    behind, front = projection.to_image(np.column_stack([ground + direction * p.max_behind, np.zeros(len(left))]), exact=True)
    fits &= ~(front & (top[column] < behind[:, 1] - 2.0 - 0.01 * height))
    # the post rises from the foot along its projected axis: white, of one colour, unlike what is beside it
    post_centre = ground + direction * GOAL_POST_DIAMETER / 2
    summit, front = projection.to_image(np.column_stack([post_centre, np.full(len(left), p.rise * GOAL_HEIGHT)]), exact=True)
    fits &= front & (summit[:, 1] < foot)
    upper = np.maximum(0, np.trunc(np.where(fits, summit[:, 1], 0.0))).astype(int)  # int(): towards zero
    fits &= ~(foot - upper < p.min_height * post_width)
    fitting = np.nonzero(fits)[0]
    posts: list[GoalPost | None] = [None] * len(left)
    for k in fitting:
        x, y = post_centre[k]
        posts[k] = GoalPost(float(x), float(y), camera, float(centre[k]), float(post_width[k]), float(foot[k]))
    centre, summit, foot, upper, post_width = centre[fitting], summit[fitting], foot[fitting], upper[fitting], post_width[fitting]
    rising = post_rows(*rising_rows(upper, foot, 48), centre, summit, foot, post_width)  # 48 rows: enough to judge
    # down to the foot (above the line it stands on): a thing behind the field's edge stands on the hall's floor
    # (or its reflection on a glossy floor continues it), with something else between it and the carpet
    line = np.maximum(2, post_width // 3)
    down = post_rows(*runs_of_rows(np.maximum(upper, foot - 3 * line), foot - line + 1), centre, summit, foot, post_width)
    return posts, rising, down


def upright(rows: Rows, image: np.ndarray, white: Callable[[slice, slice], np.ndarray], p: ShapeParameters) -> np.ndarray:
    """For each post's ``rows`` of ``image`` (RGB): the share of them in which its middle is white, of the
    post's colour (the median along those rows) and unlike at least one side (nan for a post without rows). All posts'
    rows at once: the strips' means from the integral of the block of rows and columns they lie in (their
    sums are exact integers, so the means are the ones the strips' pixels give; a strip reaches out of the
    block only where it reaches out of the image)."""
    ys, xs, post_width, lengths = rows
    shares = np.full(len(lengths), np.nan)
    if not len(ys):
        return shares
    half, side, edge = np.maximum(1, post_width // 4), np.maximum(2, post_width // 2), (post_width + 1) // 2
    first_row = int(ys.min())
    block = slice(first_row, int(ys.max()) + 1)
    width = image.shape[1]
    first, last = max(0, int((xs - edge - side).min())), min(width, int((xs + edge + side).max()) + 1)
    if first >= last:  # every strip beyond the image's sides: its whole width, as the strips clip to it
        first, last = 0, width
    columns, xs = slice(first, last), xs - first
    pixels = ycrcb(image, block, columns)
    colour = cv2.integral(pixels, sdepth=cv2.CV_32S)
    inside = strip_means(colour, pixels, ys - first_row, xs - half, xs + half)
    left, right = (strip_means(colour, pixels, ys - first_row, xs + a, xs + b) for a, b in ((-edge - side, -edge - 1), (edge + 1, edge + side)))
    unlike = np.maximum(row_norms(inside - left), row_norms(inside - right)) >= p.contrast_min
    some = lengths[lengths > 0]
    same = row_norms(inside - segment_medians(inside, some).repeat(some, axis=0)) <= p.uniform_max
    bright = white(block, columns)
    whites = strip_sums(cv2.integral(bright.view(np.uint8), sdepth=cv2.CV_32S), bright, ys - first_row, xs - half, xs + half)
    judged = (2 * whites >= 2 * half + 1) & unlike & same  # white: at least half the middle's pixels
    shares[lengths > 0] = np.add.reduceat(judged.astype(np.int64), some.cumsum() - some) / some
    return shares


def post_rows(ys: np.ndarray, lengths: np.ndarray, centre: np.ndarray, summit: np.ndarray, foot: np.ndarray,
              post_width: np.ndarray) -> Rows:
    """The rows ``ys`` of each post (``lengths`` of them each) with its centre column in each: on the line
    from its foot (row ``foot``, column ``centre``) to its ``summit`` (x, y px)."""
    each = [values.repeat(lengths) for values in (centre, summit[:, 0], summit[:, 1], foot, post_width)]
    centres, summit_x, summit_y, feet, widths = each
    xs = (centres + (summit_x - centres) * (feet - ys) / np.maximum(feet - summit_y, 1.0)).round().astype(int)
    return ys, xs, widths, lengths


def rising_rows(upper: np.ndarray, foot: np.ndarray, most: int) -> tuple[np.ndarray, np.ndarray]:
    """For each post (from row ``upper`` down to row ``foot`` below it) the rows ``np.unique(np.linspace(upper,
    foot, min(foot - upper + 1, most)).round().astype(int))``, one post's after the other, and how many each
    has: numpy's linspace step by step for all at once (the step multiplied, the start added, the end set)."""
    count = np.minimum(foot - upper + 1, most)
    steps = np.arange(most, dtype=float)[None, :]
    spaced = steps * ((foot - upper).astype(float) / (count - 1))[:, None]
    spaced += upper[:, None]
    spaced[np.arange(len(foot)), count - 1] = foot
    rows = spaced.round().astype(int)  # ascending along each post: np.unique drops the repeats
    chosen = (steps < count[:, None]) & np.concatenate([np.ones((len(foot), 1), bool), rows[:, 1:] != rows[:, :-1]], axis=1)
    return rows[chosen], chosen.sum(axis=1)


def runs_of_rows(first: np.ndarray, stop: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """For each post the rows ``np.arange(first, stop)``, one post's after the other, and how many each has."""
    lengths = np.maximum(stop - first, 0)
    return np.arange(int(lengths.sum())) - (lengths.cumsum() - lengths - first).repeat(lengths), lengths


def strip_sums(integral: np.ndarray, image: np.ndarray, ys: np.ndarray, first: np.ndarray, last: np.ndarray) -> np.ndarray:
    """For each row ``ys`` the sum of ``image``'s pixels in the columns ``first`` to ``last`` (both kept), a
    column left of the image counting as its first one and right of it as its last (as clipped indices
    do); ``integral`` is ``cv2.integral`` of ``image``. Exact integers."""
    width = image.shape[1]
    count = last - first + 1
    out_left, out_right = np.minimum(np.maximum(-first, 0), count), np.minimum(np.maximum(last - width + 1, 0), count)
    low = np.minimum(np.maximum(first, 0), width)
    high = low + count - out_left - out_right
    sums = corner_sums(integral, ys, ys + 1, low, high)
    shape = (-1,) + (1,) * (image.ndim - 2)
    if out_left.any():
        sums = sums + out_left.reshape(shape) * image[ys, 0]
    if out_right.any():
        sums = sums + out_right.reshape(shape) * image[ys, width - 1]
    return np.asarray(sums)


def strip_means(integral: np.ndarray, image: np.ndarray, ys: np.ndarray, first: np.ndarray, last: np.ndarray) -> np.ndarray:
    """The means of ``strip_sums`` (float32): what numpy's mean of those pixels as float32 gives, as their
    sum is an exact integer in float32 and numpy divides it by the count in float64."""
    count = (last - first + 1)[:, None]
    return np.asarray((strip_sums(integral, image, ys, first, last) / count).astype(np.float32))


def segment_medians(values: np.ndarray, lengths: np.ndarray) -> np.ndarray:
    """The median of each channel of ``values`` (float32, rows x channels) in each run of ``lengths``
    rows, as ``np.median`` gives it (of two middle values their float32 sum halved)."""
    segment = np.arange(len(lengths)).repeat(lengths)
    order = (segment[:, None] * 1024.0 + values).argsort(axis=0, kind="stable")  # the segments in turn, each sorted
    ordered = values[order, np.arange(values.shape[1])]
    starts = lengths.cumsum() - lengths
    upper = ordered[starts + lengths // 2]
    lower = ordered[starts + (lengths - 1) // 2]
    return np.asarray(np.where((lengths % 2 == 1)[:, None], upper, ((lower + upper) / 2).astype(np.float32)))


def exact_norms(vectors: np.ndarray) -> np.ndarray:
    """``np.linalg.norm`` of each row as numpy gives it for that row alone (the square root of its dot
    product with itself)."""
    return np.asarray(np.sqrt((vectors[:, None, :] @ vectors[:, :, None])[:, 0, 0]))
