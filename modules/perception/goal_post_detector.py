"""GoalPostDetector: the feet of the goal posts on the ground.

Every pair of edges is judged at once, not in a loop per pair (issue 34: several times faster on real
640x480 images): band sums from integral images, the pairs that may hold a post chosen with a little
slack and the few near a threshold checked again as the per-pair code did, the candidates' geometry as
stacks of single products. The posts are those of the per-pair code to the last bit, which
``tests/test_perception_speed.py`` keeps as the reference and compares on real images. The band above the
boundary and its edges are ``goal_post_band``, a candidate's shape and the rows along its rise ``goal_post_shapes``."""

from __future__ import annotations

import math
from dataclasses import dataclass

import cv2
import numpy as np

from tafel.core import Module, bounded, provides, requires
from tafel.debug import Canvas, DebugRequest
from tafel.modules.perception.goal_post_band import band_checks, band_means, band_passes, edge_peaks, edge_profile, row_norms, ycrcb
from tafel.modules.perception.goal_post_shapes import shapes, upright
from tafel.modules.perception.image_geometry import ImageProjection, camera_views
from tafel.modules.perception.pixel_statistics import white_pixels
from tafel.representations.field import GOAL_DEPTH, GOAL_POST_DIAMETER
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
        first_row, last_row = int(top[room].min()) - band, int(top[room].max())
        # each column's band: its rows from high up to low (in the rows from first_row on)
        low = np.minimum(np.maximum(top - first_row, 0), last_row - first_row)  # np.clip's, without its checks
        high = np.minimum(np.maximum(top - band - first_row, 0), last_row - first_row)
        colour = cv2.integral(ycrcb(image, slice(first_row, last_row)), sdepth=cv2.CV_32S)
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
        sure = [not unsure[k] or band_checks(self.band_white, self.band_colour, int(edges[lefts[k]]), int(edges[rights[k]]), p.contrast_min)
                for k in order]
        order = order[sure]
        posts, rising, down = shapes(camera, edges[lefts[order]], edges[rights[order]], feet[order], top, projection, height, p)
        # and whether the white rises along each one's axis and reaches down to its foot (all their rows at once)
        ys, xs, widths, lengths = (np.concatenate(pair) for pair in zip(rising, down, strict=True))
        shares = upright((ys, xs, widths, lengths), image, white, p)
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
