"""RobotDetector: other robots in both camera images, where their feet stand on the ground.

As SPL teams do it cheaply (NaoTH's and B-Human's obstacle scans): on a grid of subsampled vertical
scan columns below the field boundary, runs of pixels that are not field green. A robot is tall: the
lowest pixel of a run is its foot on the ground, and from there the run rises at least as high in the
image as ``min_height`` mm above that foot would (or up to the field boundary, which a robot farther
away crosses). Lines on the ground and the ball are low, so their runs end below that; goal posts are
narrow (and seen as posts); the hall above the field is never scanned. Neighbouring columns with feet
near each other are one robot, which must be wider than a post.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from tafel.core import Module, bounded, provides, requires, uses
from tafel.debug import Canvas, DebugRequest
from tafel.modules.perception.image_geometry import BODY_BOXES, ImageProjection, camera_views
from tafel.representations.motion import CameraMatrixBuffer
from tafel.representations.obstacles import RobotsPercept, SeenRobot
from tafel.representations.perception import (
    CameraImageBottom,
    CameraImageTop,
    FieldBoundary,
    FieldColor,
    GoalPostPercept,
    SegmentedImage,
)


def on_own_body(projection: ImageProjection, xs: np.ndarray, ys: np.ndarray) -> np.ndarray:
    """Which pixels' rays pass through a box where the own body may be (``BODY_BOXES``, the boxes
    ``own_body_mask`` paints): a slab test per box for the few pixels asked about, not a mask of the image."""
    rays = projection.rays(xs, ys)
    safe = np.where(np.abs(rays) < 1e-9, 1e-9, rays)
    hit = np.zeros(len(xs), bool)
    for box in BODY_BOXES:
        low, high = (np.array([bound[k] for bound in box]) for k in (0, 1))
        near, far = (low - projection.translation) / safe, (high - projection.translation) / safe
        enter = np.minimum(near, far).max(axis=1)
        leave = np.maximum(near, far).min(axis=1)
        hit |= (enter <= leave) & (leave > 0.0)
    return hit


@dataclass
class Foot:
    """One scan column's robot foot: on the ground (mm, robot frame) and in the image (px)."""

    x: float
    y: float
    column: int
    image_x: float
    image_y: float
    top_y: float
    own: bool = False
    """where the own body may show"""


@requires(SegmentedImage, FieldColor, FieldBoundary, CameraMatrixBuffer)
@uses(CameraImageTop, CameraImageBottom, GoalPostPercept)
@provides(RobotsPercept)
class RobotDetector(Module):
    """Scan columns (``columns`` per image, every ``rows``-th row) below the field boundary; in each, the
    lowest run of non-green pixels (gaps of one sample closed) that rises from its
    foot at least ``min_height`` mm (or, where that lies above the boundary, to the boundary and at least
    ``low_height`` mm) is a robot's foot. Feet of neighbouring columns whose runs overlap in the image are one robot
    (with what hangs beside it within ``robot_width`` mm: its arms), kept if at least ``min_width`` mm wide, within ``max_distance`` mm and not at a
    goal post; its centre lies ``centre_behind`` mm behind the nearest foot point, along the view. Robots
    seen by both cameras (within ``same_robot`` mm) count once."""

    segmented_image: SegmentedImage
    field_color: FieldColor
    field_boundary: FieldBoundary
    camera_matrix_buffer: CameraMatrixBuffer
    camera_image_top: CameraImageTop
    camera_image_bottom: CameraImageBottom
    goal_post_percept: GoalPostPercept
    robots_percept: RobotsPercept

    draw = DebugRequest("robots found: their feet in the images")

    @dataclass
    class Parameters:
        columns: int = bounded(8, 320, 64)
        """scan columns per image"""
        rows: int = bounded(20, 480, 120)
        """samples per scan column (over the image's height)"""
        min_height: float = bounded(50.0, 600.0, 250.0)
        """mm above its foot that a robot's run must reach in the image"""
        low_height: float = bounded(50.0, 600.0, 150.0)
        """mm it must reach at least where the boundary cuts it off"""
        min_width: float = bounded(0.0, 500.0, 70.0)
        """mm: narrower clusters are no robots (a robot seen from the side is about 100 mm wide)"""
        robot_width: float = bounded(50.0, 1000.0, 300.0)
        """mm beside a robot's feet within which what hangs above the ground (arms) is the same robot"""
        max_distance: float = bounded(500.0, 9000.0, 4500.0)
        """mm: robots farther away are too small to be told from lines"""
        centre_behind: float = bounded(0.0, 300.0, 80.0)
        """mm from the nearest point of a robot's feet to its centre"""
        post_distance: float = bounded(0.0, 1000.0, 300.0)
        """mm: a cluster this near a seen goal post is that post"""
        own_reach: float = bounded(0.0, 1000.0, 300.0)
        """mm: a foot this near the own centre, where the own body may show in the image, is the own body's"""
        bottom_max_distance: float = bounded(300.0, 5000.0, 1500.0)
        """mm: the bottom camera looks down at the near ground; farther things at its upper edge are posts and legs cut off"""
        same_direction: float = bounded(0.0, 1.0, 0.3)
        """rad: a robot the top image's lower edge cuts off is the bottom camera's robot this near in bearing"""
        same_robot: float = bounded(0.0, 1000.0, 350.0)
        """mm: robots of both cameras this near each other are one"""

    parameters: Parameters

    def execute(self) -> None:
        p = self.parameters
        self.robots_percept.robots = []
        if not self.field_color.valid:
            return
        robots: list[SeenRobot] = []
        bottom_bearings: list[float] = []  # of the robots the bottom camera found
        views = camera_views(self.camera_image_top, self.camera_image_bottom, self.camera_matrix_buffer)
        for camera, _, projection in sorted(views, key=lambda view: view[0] != "bottom"):  # the bottom camera first
            green = self.segmented_image.green(camera)
            boundary = self.field_boundary.rows(camera)
            if green.shape != (projection.height, projection.width) or boundary.size != projection.width:
                continue
            feet = self.feet(camera, green, boundary, projection)
            for robot, cut in self.clusters(camera, feet, projection):
                # feet below the top image are the bottom camera's to find; where it found none in that
                # direction (its upper edge cut the robot), the top image's lower edge is as near as it is known
                bearing = math.atan2(robot.y, robot.x)
                if cut and any(abs(math.remainder(bearing - other, math.tau)) < p.same_direction for other in bottom_bearings):
                    continue
                if all(math.hypot(robot.x - other.x, robot.y - other.y) > p.same_robot for other in robots):
                    robots.append(robot)
                    if camera == "bottom":
                        bottom_bearings.append(bearing)
            if self.draw:
                canvas = self.draw.canvas(Canvas.image(camera))
                for foot in feet:
                    canvas.line(foot.image_x, foot.image_y, foot.image_x, foot.top_y, color="orange", width=2)
        self.robots_percept.robots = sorted(robots, key=lambda r: r.x * r.x + r.y * r.y)

    def feet(self, camera: str, green: np.ndarray, boundary: np.ndarray, projection: ImageProjection) -> list[Foot]:
        """Each scan column's lowest robot foot (columns without one are left out)."""
        p = self.parameters
        height, width = green.shape
        column_step, row_step = max(1, width // p.columns), max(1, height // p.rows)
        xs = np.arange(column_step // 2, width, column_step)
        ys = np.arange(row_step // 2, height, row_step)
        samples = green[row_step // 2 :: row_step, column_step // 2 :: column_step]
        below = ys[:, None] >= boundary[xs][None, :]
        other = ~samples & below
        # gaps of one sample closed (a stripe of green between a robot's legs, noise)
        other[1:-1] |= other[:-2] & other[2:] & below[1:-1]
        n_rows = len(ys)
        rows = np.arange(n_rows, dtype=np.int16)[:, None]
        # each run's first row (index): along the columns as rows of the transposed grid (contiguous, far faster)
        run_top = np.maximum.accumulate(np.where(other.T, np.int16(-1), rows.T), axis=1).T + 1
        lowest = np.zeros_like(other)
        lowest[:-1] = other[:-1] & ~other[1:]
        lowest[-1] = other[-1]
        lowest &= rows - run_top >= 1  # a single sample is no robot (and most of the line crossings)
        found_rows, found_cols = np.nonzero(lowest)
        if not len(found_rows):
            return []
        count = len(found_rows)
        foot_x, foot_y = xs[found_cols].astype(float), ys[found_rows] + row_step / 2.0
        ground, hits = projection.to_ground(foot_x, foot_y)
        distance = np.hypot(ground[:, 0], ground[:, 1])
        heights = np.repeat([[p.min_height], [p.low_height]], count, axis=1).reshape(-1, 1)
        pixels, front = projection.to_image(np.hstack([np.tile(ground, (2, 1)), heights]))
        high, low, front_high, front_low = pixels[:count, 1], pixels[count:, 1], front[:count], front[count:]
        top = ys[run_top[found_rows, found_cols]] - row_step / 2.0  # the run's highest pixel
        edge = boundary[xs[found_cols]]
        tall = ~front_high | (top <= high + row_step)
        # cut off by the field's boundary or the image's upper edge, with at least low_height mm of it below
        # (a ball or a post's foot at the bottom image's upper edge shows less)
        cut = (((top <= edge + row_step) & (~front_low | (top <= low + row_step)))
               | ((top <= row_step) & front_low & (low >= 0.0)))
        keep = hits & (distance <= p.max_distance + p.centre_behind) & (tall | cut)
        own = np.zeros(count, bool)
        near = keep & ((distance < p.own_reach) | ((found_rows == n_rows - 1) & (camera == "bottom")))
        if near.any():  # where the own feet, legs and arms may show (boxes round the limbs where they may be)
            own[near] = on_own_body(projection, foot_x[near], foot_y[near] - row_step / 2.0)
            keep &= ~(own & (distance < p.own_reach))  # a foot near the own centre is the own body's
        chosen = np.nonzero(keep)[0]
        # the bottom-most per column: the last of each column's (rows ascend in nonzero's order)
        columns = found_cols[chosen][::-1]
        _, first = np.unique(columns, return_index=True)
        return [Foot(float(ground[k, 0]), float(ground[k, 1]), int(found_cols[k]), float(foot_x[k]), float(foot_y[k]), float(top[k]), bool(own[k]))
                for k in chosen[::-1][first]]

    def clusters(self, camera: str, feet: list[Foot], projection: ImageProjection) -> list[tuple[SeenRobot, bool]]:
        """Feet of neighbouring columns whose runs overlap in the image as robots (robot frame, mm), and
        whether the top image's lower edge cut them off. Feet cut off by the image's lower edge where the
        own body may show or in a lower corner (real lenses darken them) are left out."""
        p = self.parameters
        groups: list[list[Foot]] = []
        for foot in feet:
            last = groups[-1][-1] if groups else None
            if last is not None and foot.column - last.column <= 2 and foot.top_y <= last.image_y and last.top_y <= foot.image_y:
                groups[-1].append(foot)
            else:
                groups.append([foot])
        groups = self.merged(groups, projection)
        robots = []
        column_step = projection.width / p.columns
        bottom = projection.height - projection.height / p.rows
        for group in groups:
            nearest = max(group, key=lambda f: f.image_y)  # the lowest foot in the image: the robot's nearest point
            distance = math.hypot(nearest.x - projection.translation[0], nearest.y - projection.translation[1])
            width = (group[-1].column - group[0].column + 1) * column_step * distance / projection.fx
            at_edge = group[0].column == 0 or group[-1].column == p.columns - 1  # partly outside the image: as wide as it may be
            if width < p.min_width and not at_edge:
                continue
            lowest = [f for f in group if f.image_y >= nearest.image_y - projection.height / p.rows * 2]
            x, y = sum(f.x for f in lowest) / len(lowest), sum(f.y for f in lowest) / len(lowest)
            bearing = math.atan2(y - projection.translation[1], x - projection.translation[0])
            x, y = x + p.centre_behind * math.cos(bearing), y + p.centre_behind * math.sin(bearing)
            if math.hypot(x, y) > (p.max_distance if camera == "top" else p.bottom_max_distance):
                continue
            cut = nearest.image_y >= bottom
            if cut and (nearest.own or at_edge):  # the own body, or a lower corner (real lenses darken them)
                continue
            if any(math.hypot(x - post.x, y - post.y) < p.post_distance for post in self.goal_post_percept.posts):
                continue
            robots.append((SeenRobot(x, y), cut and camera == "top"))
        return robots

    def merged(self, groups: list[list[Foot]], projection: ImageProjection) -> list[list[Foot]]:
        """Groups with the groups beside them that belong to the same robot: a hanging arm ends above the
        ground, apart from the legs, and would be a robot farther away. A group whose lowest foot lies
        higher in the image than a nearer group's, within ``robot_width`` mm of it at that group's
        distance and overlapping it in the image's rows, joins that group."""
        p = self.parameters
        column_step = projection.width / p.columns
        kept: list[list[Foot]] = []
        for group in sorted(groups, key=lambda g: -max(f.image_y for f in g)):  # nearest first
            foot, top = max(f.image_y for f in group), min(f.top_y for f in group)
            for near in kept:
                lowest = max(near, key=lambda f: f.image_y)
                distance = max(1.0, math.hypot(lowest.x - projection.translation[0], lowest.y - projection.translation[1]))
                reach = p.robot_width * projection.fx / distance / column_step  # columns
                gap = max(group[0].column - near[-1].column, near[0].column - group[-1].column)
                if gap <= reach and top <= lowest.image_y and min(f.top_y for f in near) <= foot:
                    near.extend(group)
                    near.sort(key=lambda f: f.column)
                    break
            else:
                kept.append(list(group))
        return sorted(kept, key=lambda g: g[0].column)
