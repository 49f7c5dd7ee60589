"""GoalPostDetector: the feet of the goal posts on the ground.

Every pair of edges is judged at once, not in a loop per pair (issue 34: several times faster on real
640x480 images): band sums from integral images, the pairs that may hold a post chosen with a little
slack and the few near a threshold checked again as the per-pair code did, the candidates' geometry as
stacks of single products. The posts are those of the per-pair code to the last bit, which
``tests/test_perception_speed.py`` keeps as the reference and compares on real images."""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import cv2
import numpy as np

from tafel.core import Module, bounded, provides, requires
from tafel.debug import Canvas, DebugRequest
from tafel.modules.perception.image_geometry import ImageProjection, camera_views
from tafel.modules.perception.pixel_statistics import white_pixels
from tafel.representations.field import GOAL_DEPTH, GOAL_HEIGHT, GOAL_POST_DIAMETER
from tafel.representations.motion import CameraMatrixBuffer
from tafel.representations.perception import (
    CameraImageBottom,
    CameraImageTop,
    FieldBoundary,
    FieldColor,
    GoalPost,
    GoalPostPercept,
    SegmentedImage,
)


def band_sums(integral: np.ndarray, low: np.ndarray, high: np.ndarray, columns: np.ndarray) -> np.ndarray:
    """For each of ``columns``, the sum of its pixels in the rows ``high`` up to (not with) ``low`` (of the
    image whose ``cv2.integral`` is ``integral``): exact integers, where a cumulative sum down the rows
    costs a pass over every pixel of the band's rows (and numpy's is slow along them)."""
    return corner_sums(integral, high, low, columns, columns + 1)


def corner_sums(integral: np.ndarray, top: np.ndarray, bottom: np.ndarray, left: np.ndarray, right: np.ndarray) -> np.ndarray:
    """The sums of the boxes from rows ``top`` and columns ``left`` up to (not with) ``bottom`` and ``right``
    from the image's ``cv2.integral``: its four corners taken from the flat array (numpy's take is several
    times faster than indexing by rows and columns)."""
    stride = integral.shape[1]
    flat = integral.reshape((-1, *integral.shape[2:]))
    return np.asarray(flat.take(bottom * stride + right, axis=0) - flat.take(top * stride + right, axis=0)
                      - flat.take(bottom * stride + left, axis=0) + flat.take(top * stride + left, axis=0))


def edge_profile(integral: np.ndarray, low: np.ndarray, high: np.ndarray, step: int = 1) -> np.ndarray:
    """For each column, the strength of a vertical edge in its band (rows ``high`` up to ``low`` of the
    image whose ``cv2.integral`` is ``integral``): the length of the colour change from ``step`` px left
    of it to ``step`` px right of it, averaged over those rows. Averaged before its length is taken, so
    an edge that runs straight up through the band adds up and noise cancels; over a few px, so that the
    soft edge of a shaded round post counts as much as a sharp one."""
    width = integral.shape[1] - 1
    columns = np.arange(step, width - step)
    low, high = low[columns], high[columns]
    # float32 as the running sums this replaced: the integers are exact in it, the length rounds the same
    change = (band_sums(integral, low, high, columns + step) - band_sums(integral, low, high, columns - step)).astype(np.float32)
    profile = np.zeros(width, np.float32)
    profile[columns] = row_norms(change) / np.maximum(low - high, 1)
    return profile


def band_means(integral: np.ndarray, low: np.ndarray, high: np.ndarray) -> np.ndarray:
    """For each column, the mean of its pixels in its band (rows ``high`` up to ``low`` of the image whose
    ``cv2.integral`` is ``integral``), channels last where the image has them."""
    width = integral.shape[1] - 1
    count = np.maximum(low - high, 1).reshape((width,) + (1,) * (integral.ndim - 2))
    return np.asarray(band_sums(integral, low, high, np.arange(width)).astype(np.float32) / count)


def window_means(prefix: np.ndarray, first: np.ndarray, stop: np.ndarray) -> np.ndarray:
    """The means of ``values[first:stop]`` for each pair of bounds, ``prefix`` being ``values``' running sum
    with a zero in front (up to rounding: for the checks that only let through what may pass)."""
    count = (stop - first).reshape((-1,) + (1,) * (prefix.ndim - 1))
    return np.asarray((prefix[stop] - prefix[first]) / count)


def band_passes(band_white: np.ndarray, band_colour: np.ndarray, left: np.ndarray, right: np.ndarray, contrast_min: float,
                slack: float) -> tuple[np.ndarray, np.ndarray]:
    """For pairs of edges at columns ``left`` and ``right`` (at least 2 apart, inside the image): which may
    pass the band's checks (white between the edges, unlike both sides: ``GoalPostDetector.band_checks``)
    and which lie within ``slack`` of a threshold there. From running sums, all pairs at once: their
    means may differ from the slices' in the last bits, so only a pair off by more than ``slack`` is sure."""
    width = len(band_white)
    post_width = right - left
    margin, side = post_width // 4, np.maximum(2, post_width // 2)
    first = left + 1 + margin // 2
    stop = np.maximum(left + 2 + margin // 2, right - margin // 2)
    white_prefix = np.concatenate([[0.0], band_white.cumsum()])
    colour_prefix = np.concatenate([np.zeros((1, 3)), band_colour.cumsum(axis=0)])
    inside = window_means(colour_prefix, first, stop)
    white = window_means(white_prefix, first, stop)
    passes, near = white >= 0.6 - slack, white < 0.6 + slack
    for outside_first, outside_stop in ((np.maximum(0, left - side), left), (right + 1, np.minimum(width, right + 1 + side))):
        contrast = row_norms(inside - window_means(colour_prefix, outside_first, outside_stop))
        passes &= contrast >= contrast_min - slack
        near |= contrast < contrast_min + slack
    return passes, near


def edge_peaks(profile: np.ndarray, minimum: float) -> np.ndarray:
    """Columns where ``profile`` is at least ``minimum`` and no lower than its neighbours (one per plateau)."""
    padded = np.concatenate([[-np.inf], profile, [-np.inf]])
    peak = (profile >= minimum) & (profile >= padded[:-2]) & (profile > padded[2:])
    return np.nonzero(peak)[0]


Rows = tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]
"""rows of the image (``ys``), a post's centre column in each (``xs``) and the post's width (px) in each, the
posts' rows one post after the other; and how many rows each post has"""


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


def row_norms(vectors: np.ndarray) -> np.ndarray:
    """``np.linalg.norm(vectors, axis=1)`` of real vectors, as numpy computes it (the square root of the
    squares summed along the rows) without its Python around it: called a few dozen times a frame."""
    return np.asarray(np.sqrt(np.add.reduce(vectors * vectors, axis=1)))


def exact_norms(vectors: np.ndarray) -> np.ndarray:
    """``np.linalg.norm`` of each row as numpy gives it for that row alone (the square root of its dot
    product with itself)."""
    return np.asarray(np.sqrt((vectors[:, None, :] @ vectors[:, :, None])[:, 0, 0]))


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


def post_rows(ys: np.ndarray, lengths: np.ndarray, centre: np.ndarray, summit: np.ndarray, foot: np.ndarray,
              post_width: np.ndarray) -> Rows:
    """The rows ``ys`` of each post (``lengths`` of them each) with its centre column in each: on the line
    from its foot (row ``foot``, column ``centre``) to its ``summit`` (x, y px)."""
    each = [values.repeat(lengths) for values in (centre, summit[:, 0], summit[:, 1], foot, post_width)]
    centres, summit_x, summit_y, feet, widths = each
    xs = (centres + (summit_x - centres) * (feet - ys) / np.maximum(feet - summit_y, 1.0)).round().astype(int)
    return ys, xs, widths, lengths


@requires(CameraImageTop, CameraImageBottom, SegmentedImage, FieldColor, FieldBoundary, CameraMatrixBuffer)
@provides(GoalPostPercept)
class GoalPostDetector(Module):
    """A post stands on the field and rises over its boundary, as the teams find it:

    - Edges: just above the field boundary, columns where the colour changes sharply and the change
      runs straight up (a vertical edge); two edges with something white between them that differs
      from both sides are a post candidate. Edges, not white alone: a hall's pale floor is as
      unsaturated as a post, and merged with it into one wide white stretch.
    - Foot: followed down between the edges to where the carpet begins (the post stands on the goal
      line, so its foot may lie below the boundary the carpet behind the goal makes). The foot must lie
      near the boundary: no more than ``max_behind`` mm in front of it (a robot's leg on the field is
      not a post), and the white must reach down to it (something behind the field's edge stands on
      the hall's floor, with floor between it and the carpet).
    - Size: the width fits a 100 mm post at the foot's distance, by the camera matrix, and the white
      rises between the edges along the post's projected axis to most of a goal's height.
    - The goal's frame: its rear pipes stand half a metre behind the posts and are thinner; of two
      posts found within a goal's depth of each other, the nearer one is the post.
    """

    camera_image_top: CameraImageTop
    camera_image_bottom: CameraImageBottom
    segmented_image: SegmentedImage
    field_color: FieldColor
    field_boundary: FieldBoundary
    camera_matrix_buffer: CameraMatrixBuffer
    goal_post_percept: GoalPostPercept

    draw = DebugRequest("goal posts found, in the images and on the robot canvas")

    @dataclass
    class Parameters:
        band: float = bounded(0.01, 0.2, 0.04)
        """share of the image height above the boundary in which the posts' edges are measured"""
        edge_min: float = bounded(1.0, 100.0, 14.0)
        """the least colour change (YCrCb, averaged over the band) across a post's edge (2 px at 320x240, 4 at 640x480)"""
        contrast_min: float = bounded(1.0, 100.0, 14.0)
        """the least colour difference between a post and what is beside it (YCrCb)"""
        saturation_max: int = bounded(0, 255, 60)
        white_share: float = bounded(0.3, 1.0, 0.55)
        """white is at least this share of the brightest unsaturated value"""
        width_tolerance: float = bounded(0.1, 2.0, 0.5)
        """share by which the width may exceed a post's at that distance (shading, blur)"""
        width_low: float = bounded(0.1, 1.0, 0.7)
        """the least share of a post's width at that distance: the goal's rear frame and the net's poles are
        thinner pipes, and farther away than the foot the scan finds for them"""
        max_behind: float = bounded(100.0, 5000.0, 1500.0)
        """mm the field's boundary may lie behind a post's foot (the border strip behind the goal line)"""
        rise: float = bounded(0.2, 1.0, 0.85)
        """share of a goal's height along which the white must rise above the foot (where it is in the image)"""
        white_rows: float = bounded(0.3, 1.0, 0.75)
        """share of the rows along that rise in which the post's middle is white, of its colour, unlike its sides"""
        uniform_max: float = bounded(1.0, 100.0, 20.0)
        """the most a row of the post may differ from the post's median colour (YCrCb)"""
        min_height: float = bounded(1.0, 20.0, 3.0)
        """the white above the foot in the image must be this many widths high"""

    parameters: Parameters

    def __init__(self) -> None:
        self.image: np.ndarray = np.zeros((0, 0, 3), np.uint8)
        """the image being searched (RGB); ``ycrcb`` gives its rows in YCrCb"""
        self.band_colour = np.zeros((0, 3), np.float32)
        """each column's mean colour (YCrCb) in the band above the boundary"""
        self.band_white = np.zeros(0, np.float32)
        """each column's share of white pixels in that band"""

    def execute(self) -> None:
        self.goal_post_percept.posts = []
        if not self.field_color.valid:
            return
        for camera, image, projection in camera_views(self.camera_image_top, self.camera_image_bottom, self.camera_matrix_buffer):
            boundary = self.field_boundary.rows(camera)
            if boundary.size != projection.width:
                continue
            self.goal_post_percept.posts += self.posts(camera, np.asarray(image.image), boundary, projection)
        self.goal_post_percept.posts.sort(key=lambda post: post.x * post.x + post.y * post.y)

    def posts(self, camera: str, image: np.ndarray, boundary: np.ndarray, projection: ImageProjection) -> list[GoalPost]:
        """The posts in one camera's image."""
        p = self.parameters
        hsv, green = self.segmented_image.hsv(camera), self.segmented_image.green(camera)
        height, width = green.shape
        if image.shape[:2] != green.shape:
            return []
        white_min = p.white_share * self.segmented_image.white(camera)

        def white(rows: slice, columns: slice) -> np.ndarray:
            """The white pixels (unsaturated, bright, not green) of those rows and columns: only where they are looked at."""
            return np.asarray(white_pixels(hsv[rows, columns], p.saturation_max, white_min) & ~green[rows, columns])

        band = max(3, int(round(p.band * height)))
        top = np.round(boundary).astype(int)
        room = top > band
        if not room.any():
            return []
        self.image = image
        first_row, last_row = int(top[room].min()) - band, int(top[room].max())
        # each column's band: its rows from high up to low (in the rows from first_row on)
        low = np.minimum(np.maximum(top - first_row, 0), last_row - first_row)  # np.clip's, without its checks
        high = np.minimum(np.maximum(top - band - first_row, 0), last_row - first_row)
        colour = cv2.integral(self.ycrcb(slice(first_row, last_row)), sdepth=cv2.CV_32S)
        profile = np.where(room, edge_profile(colour, low, high, max(1, width // 320)), 0.0)
        edges = edge_peaks(profile, p.edge_min)
        # the least width a post can have at each edge: the one it has standing on the boundary (its foot is no farther)
        ground, hit = projection.to_ground(edges + 0.5, top[edges] + 0.5)
        distance = row_norms(np.column_stack([ground, np.zeros(len(edges))]) - projection.translation)
        least = np.where(hit, p.width_low * projection.fx * GOAL_POST_DIAMETER / np.maximum(distance, 1.0) - 1.0, 0.0)
        self.band_colour = band_means(colour, low, high)
        self.band_white = band_means(cv2.integral(white(slice(first_row, last_row), slice(None)).view(np.uint8), sdepth=cv2.CV_32S), low, high)
        # each edge with one of the next edges (stickers, dents and shadows on a post make more)
        lefts, rights = (np.concatenate(ends).astype(int) for ends in
                         zip(*((np.arange(len(edges) - k), np.arange(k, len(edges))) for k in range(1, 5))))
        wide = ~(edges[rights] - edges[lefts] < least[lefts])
        lefts, rights = lefts[wide], rights[wide]
        possible, feet, unsure = self.possible(edges[lefts], edges[rights], top, green, projection)
        # the pairs that may hold a post, each edge with the edges after it in their order: their shapes
        order = np.lexsort((rights, lefts))
        order = order[possible[order]]
        order = order[[not unsure[k] or self.band_checks(int(edges[lefts[k]]), int(edges[rights[k]])) for k in order]]
        posts, rising, down = self.shapes(camera, edges[lefts[order]], edges[rights[order]], feet[order], top, projection)
        # and whether the white rises along each one's axis and reaches down to its foot (all their rows at once)
        ys, xs, widths, lengths = (np.concatenate(pair) for pair in zip(rising, down, strict=True))
        shares = self.upright((ys, xs, widths, lengths), white)
        rises, reaches = shares[: len(rising[3])], shares[len(rising[3]) :]
        shaped = [(int(lefts[k]), post) for k, post in zip(order, posts, strict=True) if post is not None]
        best: dict[int, tuple[float, GoalPost]] = {}  # of each left edge's posts the one whose width fits best (the first of equals)
        for (i, post), rise, reach, below in zip(shaped, rises, reaches, down[3], strict=True):
            if rise >= p.white_rows and not (below and reach < 0.5):  # below: the white reaches down to the foot
                away = float(np.linalg.norm(np.array([post.x, post.y, 0.0]) - projection.translation))
                misfit = abs(math.log(post.image_width * away / (projection.fx * GOAL_POST_DIAMETER)))
                if i not in best or misfit < best[i][0]:
                    best[i] = (misfit, post)
        found = self.nearest(self.distinct([best[i][1] for i in sorted(best)]))
        if self.draw:
            for post in found:
                self.draw.canvas(Canvas.image(camera)).line(post.image_x, 0, post.image_x, post.image_foot, color="yellow", width=2)
                self.draw.canvas(Canvas.ROBOT).circle(post.x, post.y, GOAL_POST_DIAMETER / 2, color="yellow", width=2)
        return found

    def ycrcb(self, rows: slice, columns: slice = slice(None)) -> np.ndarray:
        """Those rows and columns of the image in YCrCb (a pixel's conversion depends on it alone: only the pixels
        looked at are converted, the band's and the posts')."""
        return cv2.cvtColor(np.ascontiguousarray(self.image[rows, columns]), cv2.COLOR_RGB2YCrCb)

    def possible(self, left: np.ndarray, right: np.ndarray, top: np.ndarray, green: np.ndarray,
                 projection: ImageProjection) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Which of the pairs of edges at columns ``left`` and ``right`` may hold a post, the row of each
        one's foot, and which lie so near the thresholds of the band's checks that only ``band_checks``
        can tell: the first checks (white between the edges, unlike both sides, a foot, a post's width at
        its distance), all pairs at once. The band's means here (running sums) may differ from the
        slices' means in the last bits, and the distances from ``shapes``', so a pair is dropped only when
        it misses a threshold by more than that; ``shapes`` decides the rest. The feet are exact (counts)."""
        p = self.parameters
        height, width = green.shape
        slack = 1e-6  # far more than the rounding of the means and distances, far less than any real difference
        post_width = right - left
        keep = (post_width >= 2) & (left >= 1) & (right <= width - 2)
        left, right, post_width = left[keep], right[keep], post_width[keep]
        possible, feet, unsure = np.zeros(len(keep), bool), np.full(len(keep), -1), np.zeros(len(keep), bool)
        if not len(left):
            return possible, feet, unsure
        margin = post_width // 4
        first = left + 1 + margin // 2
        stop = np.maximum(left + 2 + margin // 2, right - margin // 2)
        chosen, near = band_passes(self.band_white, self.band_colour, left, right, p.contrast_min, slack)
        unsure[np.nonzero(keep)[0][near]] = True
        index = np.nonzero(keep)[0][chosen]  # the pairs whose band may pass: on to their feet
        left, right, post_width, first, stop = (values[chosen] for values in (left, right, post_width, first, stop))
        if not len(left):
            return possible, feet, unsure
        # the foot: the first of ``run`` rows of carpet between the edges, down from the boundary
        # (a row is carpet where at least half the columns between the edges are green)
        start = np.maximum(0, top[(left + right) // 2] - 1)
        below = int(start.min())  # the rows from here down
        columns = int(first.min())  # only the columns between the edges: their differences are the whole rows' (exact counts)
        rows = cv2.integral(green[below:, columns : int(stop.max())].view(np.uint8), sdepth=cv2.CV_32S)
        between = rows.take(stop - columns, axis=1) - rows.take(first - columns, axis=1)  # green from the top to each row, between the edges
        counts = (between[1:] - between[:-1]).T  # pairs x rows
        row = np.arange(below, height)[None, :]
        carpet = (2 * counts >= (stop - first)[:, None]) & (row >= start[:, None])
        run = np.maximum(2, post_width // 6)
        carpets = np.concatenate([np.zeros((len(left), 1), np.int32), np.cumsum(carpet, axis=1, dtype=np.int32)], axis=1)
        ends = row - below + run[:, None]  # each run's end (not in it), among those rows
        lasting = (np.take_along_axis(carpets, np.minimum(ends, height - below), axis=1) - carpets[:, :-1] == run[:, None]) & (ends <= height - below)
        feet[index] = foot = np.maximum(start, below + np.argmax(lasting, axis=1) - 1)
        # the width a post has at that foot's distance
        ground, hit = projection.to_ground((left + right) / 2, foot + 0.5)
        distance = row_norms(np.column_stack([ground, np.zeros(len(left))]) - projection.translation)
        expected = projection.fx * GOAL_POST_DIAMETER / np.where(hit, distance, 1.0)
        misfit = (post_width - expected > p.width_tolerance * expected + 1.5 + slack) | (post_width < p.width_low * expected - 1.0 - slack)
        possible[index[lasting.any(axis=1) & ~(hit & misfit)]] = True
        return possible, feet, unsure

    def band_checks(self, left: int, right: int) -> bool:
        """Whether the band above the boundary is white between the edges at columns ``left`` and ``right``
        and unlike both sides (the slices' means: for the pairs whose running sums lie near a threshold)."""
        post_width = right - left
        side = max(2, post_width // 2)
        margin = post_width // 4
        inner = slice(left + 1 + margin // 2, max(left + 2 + margin // 2, right - margin // 2))
        if self.band_white[inner].mean() < 0.6:
            return False
        inside = self.band_colour[inner].mean(axis=0)
        return all(np.linalg.norm(inside - outside.mean(axis=0)) >= self.parameters.contrast_min
                   for outside in (self.band_colour[max(0, left - side) : left], self.band_colour[right + 1 : right + 1 + side]))

    def shapes(self, camera: str, left: np.ndarray, right: np.ndarray, foot: np.ndarray, top: np.ndarray,
               projection: ImageProjection) -> tuple[list[GoalPost | None], Rows, Rows]:
        """For the edges at columns ``left`` and ``right`` with a foot at row ``foot`` (the first rows of
        carpet below the boundary between them) whose band passed its checks: the post, if its width and
        height fit one, else None; and for those posts in turn the rows in which the white must rise along
        its axis and those in which it must reach down to the foot (for ``upright``). All at once, by the
        very operations the pixel-by-pixel code did for each (``ImageProjection``'s ``exact``, ``exact_norms``, numpy's
        linspace), so the posts are the same to the last bit."""
        p = self.parameters
        height = self.image.shape[0]
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

    def upright(self, rows: Rows, white: Callable[[slice, slice], np.ndarray]) -> np.ndarray:
        """For each post's ``rows``: the share of them in which its middle is white, of the post's colour (the
        median along those rows) and unlike at least one side (nan for a post without rows). All posts'
        rows at once: the strips' means from the integral of the block of rows and columns they lie in (their
        sums are exact integers, so the means are the ones the strips' pixels give; a strip reaches out of the
        block only where it reaches out of the image)."""
        p = self.parameters
        ys, xs, post_width, lengths = rows
        shares = np.full(len(lengths), np.nan)
        if not len(ys):
            return shares
        half, side, edge = np.maximum(1, post_width // 4), np.maximum(2, post_width // 2), (post_width + 1) // 2
        first_row = int(ys.min())
        block = slice(first_row, int(ys.max()) + 1)
        width = self.image.shape[1]
        first, last = max(0, int((xs - edge - side).min())), min(width, int((xs + edge + side).max()) + 1)
        if first >= last:  # every strip beyond the image's sides: its whole width, as the strips clip to it
            first, last = 0, width
        columns, xs = slice(first, last), xs - first
        pixels = self.ycrcb(block, columns)
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

    @staticmethod
    def distinct(posts: list[GoalPost]) -> list[GoalPost]:
        """One post per stretch of columns: of overlapping ones, the first found."""
        kept: list[GoalPost] = []
        for post in posts:
            if all(abs(post.image_x - other.image_x) > (post.image_width + other.image_width) / 2 for other in kept):
                kept.append(post)
        return kept

    @staticmethod
    def nearest(posts: list[GoalPost]) -> list[GoalPost]:
        """Without the posts that stand within a goal's depth behind a nearer one: the goal's rear frame
        (behind each post), seen past the post."""
        kept: list[GoalPost] = []
        for post in sorted(posts, key=lambda post: post.x * post.x + post.y * post.y):
            if all((post.x - other.x) ** 2 + (post.y - other.y) ** 2 > (GOAL_DEPTH + GOAL_POST_DIAMETER) ** 2 for other in kept):
                kept.append(post)
        return kept
