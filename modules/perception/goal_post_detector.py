"""GoalPostDetector: the feet of the goal posts on the ground."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from tafel.core import Module, bounded, provides, requires
from tafel.debug import Canvas, DebugRequest
from tafel.modules.perception.image_geometry import ImageProjection, camera_views
from tafel.representations.field import GOAL_POST_DIAMETER
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


@requires(CameraImageTop, CameraImageBottom, SegmentedImage, FieldColor, FieldBoundary, CameraMatrixBuffer)
@provides(GoalPostPercept)
class GoalPostDetector(Module):
    """Posts stand on the field and rise over its boundary: columns that are white just above the
    boundary are grouped, and each group is followed down to where it meets the field (its foot).
    The goal line meets the foot, so the foot is where the white widens into the line. A group is a
    post if its width fits a 100 mm post at the distance of its foot and it rises well above it. The
    goal's rear frame and the net's poles are thinner pipes, farther away than the foot the scan finds
    for them: too thin for a post there."""

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
        band: int = bounded(2, 60, 12)
        """px above the boundary that must be white for a post column"""
        saturation_max: int = bounded(0, 255, 60)
        white_share: float = bounded(0.3, 1.0, 0.55)
        """white is at least this share of the brightest unsaturated value"""
        width_tolerance: float = bounded(0.1, 2.0, 0.6)
        """share by which the width may exceed a post's at that distance (shading, blur)"""
        width_low: float = bounded(0.1, 1.0, 0.75)
        """the least share of a post's width at that distance: the goal's rear frame and the net's poles are
        thinner pipes, and farther away than the foot the scan finds for them"""
        min_height: float = bounded(1.0, 20.0, 3.0)
        """the white above the foot must be this many widths high"""

    parameters: Parameters

    def execute(self) -> None:
        self.goal_post_percept.posts = []
        if not self.field_color.valid:
            return
        for camera, _, projection in camera_views(self.camera_image_top, self.camera_image_bottom, self.camera_matrix_buffer):
            boundary = self.field_boundary.rows(camera)
            if boundary.size != projection.width:
                continue
            self.goal_post_percept.posts += self.posts(camera, boundary, projection)
        self.goal_post_percept.posts.sort(key=lambda post: post.x * post.x + post.y * post.y)

    def posts(self, camera: str, boundary: np.ndarray, projection: ImageProjection) -> list[GoalPost]:
        p = self.parameters
        hsv, green = self.segmented_image.hsv(camera), self.segmented_image.green(camera)
        height = hsv.shape[0]
        unsaturated = (hsv[..., 1] <= p.saturation_max) & ~green
        if not unsaturated.any():
            return []
        white = unsaturated & (hsv[..., 2] >= p.white_share * self.segmented_image.white(camera))
        rows = np.arange(height)[:, None]
        top = np.round(boundary).astype(int)
        band = (rows < top[None, :]) & (rows >= top[None, :] - p.band)
        share = (white & band).sum(axis=0) / np.maximum(band.sum(axis=0), 1)
        found = []
        for first, last in column_groups((share >= 0.8) & (top > p.band)):
            post = self.post(camera, white, first, last, top, projection)
            if post is not None:
                found.append(post)
                if self.draw:
                    self.draw.canvas(Canvas.image(camera)).line(post.image_x, 0, post.image_x, height, color="yellow", width=2)
                    self.draw.canvas(Canvas.ROBOT).circle(post.x, post.y, GOAL_POST_DIAMETER / 2, color="yellow", width=2)
        return found

    def post(self, camera: str, white: np.ndarray, first: int, last: int, top: np.ndarray, projection: ImageProjection) -> GoalPost | None:
        """The post whose columns are ``first``..``last``, or None if they are no post."""
        p = self.parameters
        height, width = white.shape
        centre = (first + last) // 2
        post_width = last - first + 1
        foot = int(top[centre])
        while foot + 1 < height and white[foot + 1, centre]:
            run = white[foot + 1, max(0, first - post_width) : min(width, last + post_width + 1)]
            if run.mean() > 0.9 and post_width > 1:  # as wide as three posts: the goal line under the foot
                break
            foot += 1
        if foot + 1 >= height:
            return None  # the foot is not in the image
        ground, hit = projection.to_ground(np.array([centre + 0.5]), np.array([foot + 0.5]))
        if not hit[0]:
            return None
        distance = float(np.linalg.norm(np.append(ground[0], 0.0) - projection.translation))
        expected = projection.fx * GOAL_POST_DIAMETER / distance
        if post_width - expected > p.width_tolerance * expected + 1.5 or post_width < p.width_low * expected - 1.0:
            return None
        column = white[: foot + 1, centre]
        rise = foot - (np.nonzero(~column)[0].max() if (~column).any() else -1)
        if rise < p.min_height * max(post_width, expected):
            return None
        # the foot's edge is seen; the post's centre lies half a post behind it
        direction = ground[0] / max(np.linalg.norm(ground[0]), 1.0)
        x, y = ground[0] + direction * GOAL_POST_DIAMETER / 2
        return GoalPost(float(x), float(y), camera, float(centre), float(post_width), float(foot))
