"""GoalPostDetector: the feet of the goal posts on the ground."""

from __future__ import annotations

import math
from dataclasses import dataclass

import cv2
import numpy as np

from tafel.core import Module, bounded, provides, requires
from tafel.debug import Canvas, DebugRequest
from tafel.modules.perception.field_color_provider import white_pixels
from tafel.modules.perception.image_geometry import ImageProjection, camera_views
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


def column_groups(flags: np.ndarray) -> list[tuple[int, int]]:
    """(first, last) index of each run of true values."""
    padded = np.concatenate([[False], flags, [False]]).astype(np.int8)
    change = np.diff(padded)
    return list(zip(np.nonzero(change == 1)[0], np.nonzero(change == -1)[0] - 1))


def band_sums(integral: np.ndarray, low: np.ndarray, high: np.ndarray, columns: np.ndarray) -> np.ndarray:
    """For each of ``columns``, the sum of its pixels in the rows ``high`` up to (not with) ``low`` (of the
    image whose ``cv2.integral`` is ``integral``): exact integers, where a cumulative sum down the rows
    costs a pass over every pixel of the band's rows (and numpy's is slow along them)."""
    return np.asarray(integral[low, columns + 1] - integral[high, columns + 1] - integral[low, columns] + integral[high, columns])


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
    profile[columns] = np.linalg.norm(change, axis=1) / np.maximum(low - high, 1)
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


def edge_peaks(profile: np.ndarray, minimum: float) -> np.ndarray:
    """Columns where ``profile`` is at least ``minimum`` and no lower than its neighbours (one per plateau)."""
    padded = np.concatenate([[-np.inf], profile, [-np.inf]])
    peak = (profile >= minimum) & (profile >= padded[:-2]) & (profile > padded[2:])
    return np.nonzero(peak)[0]


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
        self.colour = np.zeros((0, 0, 3), np.uint8)
        """the image being searched, in YCrCb"""
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
        white = white_pixels(hsv, p.saturation_max, p.white_share * self.segmented_image.white(camera)) & ~green
        band = max(3, int(round(p.band * height)))
        top = np.round(boundary).astype(int)
        room = top > band
        if not room.any():
            return []
        self.colour = cv2.cvtColor(np.ascontiguousarray(image), cv2.COLOR_RGB2YCrCb)
        first_row, last_row = int(top[room].min()) - band, int(top[room].max())
        # each column's band: its rows from high up to low (in the rows from first_row on)
        low = np.clip(top - first_row, 0, last_row - first_row)
        high = np.clip(top - band - first_row, 0, last_row - first_row)
        colour = cv2.integral(self.colour[first_row:last_row], sdepth=cv2.CV_32S)
        profile = np.where(room, edge_profile(colour, low, high, max(1, width // 320)), 0.0)
        edges = edge_peaks(profile, p.edge_min)
        # the least width a post can have at each edge: the one it has standing on the boundary (its foot is no farther)
        ground, hit = projection.to_ground(edges + 0.5, top[edges] + 0.5)
        distance = np.linalg.norm(np.column_stack([ground, np.zeros(len(edges))]) - projection.translation, axis=1)
        least = np.where(hit, p.width_low * projection.fx * GOAL_POST_DIAMETER / np.maximum(distance, 1.0) - 1.0, 0.0)
        self.band_colour = band_means(colour, low, high)
        self.band_white = band_means(cv2.integral(white[first_row:last_row].view(np.uint8), sdepth=cv2.CV_32S), low, high)
        # each edge with one of the next edges (stickers, dents and shadows on a post make more)
        lefts, rights = (np.concatenate(ends).astype(int) for ends in
                         zip(*((np.arange(len(edges) - k), np.arange(k, len(edges))) for k in range(1, 5))))
        wide = ~(edges[rights] - edges[lefts] < least[lefts])
        lefts, rights = lefts[wide], rights[wide]
        possible = np.zeros((len(edges), len(edges)), bool)
        possible[lefts, rights] = self.possible(edges[lefts], edges[rights], top, green, projection)
        found: list[GoalPost] = []
        for i, left in enumerate(edges):
            best: tuple[float, GoalPost] | None = None
            for j in range(i + 1, min(i + 5, len(edges))):
                if not possible[i, j]:
                    continue
                post = self.post(camera, int(left), int(edges[j]), top, white, green, projection)
                if post is not None:
                    distance = float(np.linalg.norm(np.array([post.x, post.y, 0.0]) - projection.translation))
                    misfit = abs(math.log(post.image_width * distance / (projection.fx * GOAL_POST_DIAMETER)))
                    if best is None or misfit < best[0]:
                        best = (misfit, post)
            if best is not None:
                found.append(best[1])
        found = self.nearest(self.distinct(found))
        if self.draw:
            for post in found:
                self.draw.canvas(Canvas.image(camera)).line(post.image_x, 0, post.image_x, post.image_foot, color="yellow", width=2)
                self.draw.canvas(Canvas.ROBOT).circle(post.x, post.y, GOAL_POST_DIAMETER / 2, color="yellow", width=2)
        return found

    def possible(self, left: np.ndarray, right: np.ndarray, top: np.ndarray, green: np.ndarray, projection: ImageProjection) -> np.ndarray:
        """Which of the pairs of edges at columns ``left`` and ``right`` may hold a post: ``post``'s first
        checks (white between the edges, unlike both sides, a foot, a post's width at its distance), all
        pairs at once. Its means and distances may differ from ``post``'s in the last bits, so a pair is
        dropped only when it misses a threshold by more than that; ``post`` decides the rest."""
        p = self.parameters
        height, width = green.shape
        slack = 1e-6  # far more than the rounding, far less than any real difference
        post_width = right - left
        keep = (post_width >= 2) & (left >= 1) & (right <= width - 2)
        left, right, post_width = left[keep], right[keep], post_width[keep]
        possible = np.zeros(len(keep), bool)
        if not len(left):
            return possible
        margin = post_width // 4
        first = left + 1 + margin // 2
        stop = np.maximum(left + 2 + margin // 2, right - margin // 2)
        white_prefix = np.concatenate([[0.0], np.cumsum(self.band_white)])
        colour_prefix = np.concatenate([np.zeros((1, 3)), np.cumsum(self.band_colour, axis=0)])
        inside = window_means(colour_prefix, first, stop)
        side = np.maximum(2, post_width // 2)
        unlike = np.ones(len(left), bool)
        for outside_first, outside_stop in ((np.maximum(0, left - side), left), (right + 1, np.minimum(width, right + 1 + side))):
            unlike &= np.linalg.norm(inside - window_means(colour_prefix, outside_first, outside_stop), axis=1) >= p.contrast_min - slack
        chosen = (window_means(white_prefix, first, stop) >= 0.6 - slack) & unlike
        # the foot: the first of ``run`` rows of carpet between the edges, down from the boundary
        start = np.maximum(0, top[(left + right) // 2] - 1)
        rows = cv2.integral(green.view(np.uint8), sdepth=cv2.CV_32S)
        carpet_columns = (rows[1:, stop] - rows[:-1, stop] - rows[1:, first] + rows[:-1, first]).T  # pairs x rows
        carpet = (2 * carpet_columns >= (stop - first)[:, None]) & (np.arange(height)[None, :] >= start[:, None])
        run = np.maximum(2, post_width // 6)
        lasting = np.concatenate([np.zeros((len(left), 1), np.int32), np.cumsum(carpet, axis=1, dtype=np.int32)], axis=1)
        ends = np.arange(height)[None, :] + run[:, None]
        lasting = np.take_along_axis(lasting, np.minimum(ends, height), axis=1) - lasting[:, :height] == run[:, None]
        lasting &= ends <= height
        chosen &= lasting.any(axis=1)
        foot = np.maximum(start, np.argmax(lasting, axis=1) - 1)
        # the width a post has at that foot's distance
        ground, hit = projection.to_ground((left + right) / 2, foot + 0.5)
        distance = np.linalg.norm(np.column_stack([ground, np.zeros(len(left))]) - projection.translation, axis=1)
        expected = projection.fx * GOAL_POST_DIAMETER / np.where(hit, distance, 1.0)
        misfit = (post_width - expected > p.width_tolerance * expected + 1.5 + slack) | (post_width < p.width_low * expected - 1.0 - slack)
        chosen &= ~(hit & misfit)
        possible[np.nonzero(keep)[0][chosen]] = True
        return possible

    def post(self, camera: str, left: int, right: int, top: np.ndarray, white: np.ndarray, green: np.ndarray,
             projection: ImageProjection) -> GoalPost | None:
        """The post between the edges at columns ``left`` and ``right``, or None if there is none."""
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
            """The post's centre column in the rows ``ys``."""
            return np.round(centre + (summit[0, 0] - centre) * (foot - ys) / max(foot - summit[0, 1], 1.0)).astype(int)

        ys = np.unique(np.linspace(upper, foot, min(foot - upper + 1, 48)).round().astype(int))  # at most 48 rows: enough to judge
        if self.post_rows(ys, axis(ys), post_width, white).mean() < p.white_rows:
            return None
        # down to the foot (above the line it stands on): a thing behind the field's edge stands on the hall's
        # floor (or its reflection on a glossy floor continues it), with something else between it and the carpet
        line = max(2, post_width // 3)
        ys = np.arange(max(upper, foot - 3 * line), foot - line + 1)
        if ys.size and self.post_rows(ys, axis(ys), post_width, white).mean() < 0.5:
            return None
        x, y = post_centre
        return GoalPost(float(x), float(y), camera, float(centre), float(post_width), float(foot))

    def post_rows(self, ys: np.ndarray, xs: np.ndarray, post_width: int, white: np.ndarray) -> np.ndarray:
        """For each row ``ys`` with the post's centre at ``xs``: whether the post's middle is white, of the
        post's colour (the median along it) and unlike at least one side."""
        p = self.parameters
        height, width = white.shape
        half = max(1, post_width // 4)
        side = max(2, post_width // 2)

        def strip(first: int, last: int) -> np.ndarray:
            columns = np.clip(xs[:, None] + np.arange(first, last + 1)[None, :], 0, width - 1)
            return np.asarray(self.colour[ys[:, None], columns].astype(np.float32).mean(axis=1))

        columns = np.clip(xs[:, None] + np.arange(-half, half + 1)[None, :], 0, width - 1)
        inside = strip(-half, half)
        edge = (post_width + 1) // 2
        left, right = strip(-edge - side, -edge - 1), strip(edge + 1, edge + side)
        unlike = np.maximum(np.linalg.norm(inside - left, axis=1), np.linalg.norm(inside - right, axis=1)) >= p.contrast_min
        same = np.linalg.norm(inside - np.median(inside, axis=0), axis=1) <= p.uniform_max
        return np.asarray((white[ys[:, None], columns].mean(axis=1) >= 0.5) & unlike & same)

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
