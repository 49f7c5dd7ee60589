"""LineDetector: the field lines on the ground, as segments and the centre circle."""

from __future__ import annotations

import math
from dataclasses import dataclass

import cv2
import numpy as np

from tafel.core import Module, bounded, provides, requires, uses
from tafel.debug import Canvas, DebugRequest, Stopwatch
from tafel.modules.perception.image_geometry import ImageProjection, camera_views, paint_own_body
from tafel.representations.field import CENTER_CIRCLE_DIAMETER, LINE_WIDTH
from tafel.representations.motion import CameraMatrixBuffer
from tafel.representations.perception import (
    BallImagePercept,
    CameraImageBottom,
    CameraImageTop,
    FieldBoundary,
    FieldColor,
    GoalPostPercept,
    LinePercept,
    LineSegment,
    SegmentedImage,
)

CIRCLE_RADIUS = CENTER_CIRCLE_DIAMETER / 2


def white_runs(white: np.ndarray, step: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Runs of white down every ``step``-th column of a mask: (column x, first row, last row) per run."""
    columns = white[:, ::step]
    n_rows, n_cols = columns.shape
    padded = np.zeros((n_cols, n_rows + 2), bool)  # a column per row, a pixel of no white at both ends
    padded[:, 1:-1] = columns.T
    start_columns, start_rows = np.divmod(np.flatnonzero(padded[:, 1:] & ~padded[:, :-1]), n_rows + 1)
    end_rows = np.flatnonzero(~padded[:, 1:] & padded[:, :-1]) % (n_rows + 1)  # in the same order: column by column
    return start_columns * step, start_rows, end_rows - 1


def green_on_both_sides(green: np.ndarray, line: np.ndarray, first: np.ndarray, last: np.ndarray, reach: int) -> np.ndarray:
    """Whether each run (down column ``line`` of ``green``, rows ``first`` to ``last``) has green within
    ``reach`` pixels above and below it. Lines lie on the field; a white run with no green on one
    side is the field's edge (the carpet's end, a wall), a robot or a goal. For all runs at once: the
    green mask dilated upwards and downwards by ``reach`` rows (not counting the row itself)."""
    if len(line) == 0 or reach < 1:
        return np.zeros(len(line), bool)
    mask = np.ascontiguousarray(green).view(np.uint8)
    kernel = np.ones((reach + 1, 1), np.uint8)
    kernel[reach] = 0
    above = cv2.dilate(mask, kernel, anchor=(0, reach))  # any green in the reach rows above each pixel
    below = cv2.dilate(mask, kernel[::-1].copy(), anchor=(0, 0))  # ... and below it
    return above[first, line].view(bool) & below[last, line].view(bool)


def longest_arc(angles: np.ndarray, max_gap: float) -> float:
    """The longest span (rad) of ``angles`` (rad) on the circle without a gap wider than ``max_gap``."""
    if len(angles) < 2:
        return 0.0
    ordered = np.sort(np.mod(angles, 2 * math.pi))
    gaps = np.diff(np.concatenate([ordered, ordered[:1] + 2 * math.pi]))
    breaks = np.nonzero(gaps > max_gap)[0]
    if len(breaks) == 0:
        return 2 * math.pi
    # walk round from just after each break to the next one: the arcs between the gaps
    spans = [(ordered[b2] - ordered[(b1 + 1) % len(ordered)]) % (2 * math.pi) for b1, b2 in zip(breaks, np.roll(breaks, -1))]
    return float(max(spans))


@requires(CameraImageTop, CameraImageBottom, SegmentedImage, FieldColor, FieldBoundary, CameraMatrixBuffer, GoalPostPercept)
@uses(BallImagePercept)
@provides(LinePercept)
class LineDetector(Module):
    """Scan lines find thin white runs on the field; their middles, put on the ground through the
    camera matrix, are line points. A run is kept if green borders it on both sides and its extent on the ground fits a 50 mm line seen at
    a slant, which rules out robots and the ball; the own feet, goal posts and ball candidates are
    masked out before. Then, on the ground: the centre circle (points on a
    circle of the known radius, found by RANSAC), then straight segments, greedily, by RANSAC too."""

    camera_image_top: CameraImageTop
    camera_image_bottom: CameraImageBottom
    segmented_image: SegmentedImage
    field_color: FieldColor
    field_boundary: FieldBoundary
    camera_matrix_buffer: CameraMatrixBuffer
    goal_post_percept: GoalPostPercept
    ball_image_percept: BallImagePercept
    line_percept: LinePercept

    draw_points = DebugRequest("line points in the images and on the robot canvas")
    draw_lines = DebugRequest("fitted segments and the centre circle on the robot canvas")
    fit = Stopwatch("fitting segments and the centre circle to the points")

    @dataclass
    class Parameters:
        step: int = bounded(1, 32, 5)
        """px between scan lines (both directions)"""
        max_run_ground: float = bounded(50.0, 1000.0, 220.0)
        """mm: a white run longer than this on the ground is no line"""
        max_distance: float = bounded(500.0, 10000.0, 5000.0)
        """mm: points farther away are too imprecise to use"""
        saturation_max: int = bounded(0, 255, 70)
        green_reach: int = bounded(1, 20, 8)
        """px: a line run needs green this close above and below it (left and right across); blurred edges, a
        ball or a foot beside a line take a few pixels"""
        white_share: float = bounded(0.3, 1.0, 0.7)
        """a pixel is white above this share of the field's brightest non-green value"""
        inlier_distance: float = bounded(5.0, 300.0, 60.0)
        """mm from a fitted line or circle that still counts"""
        min_line_points: int = bounded(3, 100, 6)
        min_circle_points: int = bounded(4, 200, 15)
        min_arc: float = bounded(10.0, 360.0, 90.0)
        """degrees of the circle that must be seen without a gap"""
        max_arc_gap: float = bounded(1.0, 90.0, 15.0)
        """degrees between neighbouring circle points that still count as one arc"""
        max_points: int = bounded(10, 2000, 200)
        """line points kept per frame"""
        iterations: int = bounded(5, 500, 40)
        """RANSAC tries per segment"""

    parameters: Parameters

    def __init__(self) -> None:
        self.rng = np.random.default_rng(0)  # fixed: a replay fits the same lines

    def execute(self) -> None:
        out = self.line_percept
        views = camera_views(self.camera_image_top, self.camera_image_bottom, self.camera_matrix_buffer) if self.field_color.valid else ()
        points = [np.zeros((0, 2)), *(self.points(camera, projection) for camera, _, projection in views)]
        found = np.concatenate(points)
        if len(found) > self.parameters.max_points:  # evenly thinned: near and far points alike
            found = found[np.linspace(0, len(found) - 1, self.parameters.max_points).astype(int)]
        out.points = found.astype(np.float32)
        out.segments, out.circle_seen = [], False
        with self.fit:
            rest = self.fit_circle(found)
            out.segments = self.fit_segments(rest)
        if self.draw_lines:
            canvas = self.draw_lines.canvas(Canvas.ROBOT)
            for segment in out.segments:
                canvas.line(segment.x1, segment.y1, segment.x2, segment.y2, color="white", width=3)
            if out.circle_seen:
                canvas.circle(out.circle_x, out.circle_y, CIRCLE_RADIUS, color="white", width=3)

    def points(self, camera: str, projection: ImageProjection) -> np.ndarray:
        """Line points (N x 2, mm, robot frame) of one camera's image."""
        p = self.parameters
        hsv, green = self.segmented_image.hsv(camera), self.segmented_image.green(camera)
        obstacles = self.obstacles(camera, projection)
        threshold = p.white_share * self.segmented_image.white(camera)
        found = []
        # white is only classified on the scan lines: every step-th column (runs down) and row (runs across)
        for transposed in (False, True):
            grid = (slice(None, None, p.step), slice(None)) if transposed else (slice(None), slice(None, None, p.step))
            cut = hsv[grid]
            ignored = self.ignored(camera, projection, grid, obstacles)
            white = ~green[grid] & ~ignored & (cut[..., 1] <= p.saturation_max) & (cut[..., 2] >= threshold)
            line, first, last = white_runs(white.T if transposed else white, 1)
            bordered = green_on_both_sides(green[grid].T if transposed else green[grid], line, first, last, p.green_reach)
            line = line * p.step
            xs0, ys0, xs1, ys1 = (first, line, last, line) if transposed else (line, first, line, last)
            if len(xs0) == 0:
                continue
            starts, hit0 = projection.to_ground(xs0.astype(float), ys0.astype(float))
            ends, hit1 = projection.to_ground(xs1.astype(float), ys1.astype(float))
            middles, hit = projection.to_ground((xs0 + xs1) / 2.0, (ys0 + ys1) / 2.0)
            extent = np.linalg.norm(ends - starts, axis=1)
            keep = bordered & hit0 & hit1 & hit & (extent <= p.max_run_ground) & (np.linalg.norm(middles, axis=1) <= p.max_distance)
            found.append(middles[keep])
            if self.draw_points:
                canvas = self.draw_points.canvas(Canvas.image(camera))
                for px, py in zip(((xs0 + xs1) / 2.0)[keep], ((ys0 + ys1) / 2.0)[keep]):
                    canvas.circle(float(px), float(py), 1.5, color="red")
        result = np.concatenate(found) if found else np.zeros((0, 2))
        if self.draw_points:
            canvas = self.draw_points.canvas(Canvas.ROBOT)
            for x, y in result:
                canvas.circle(float(x), float(y), 15, color="red")
        return result

    def ignored(self, camera: str, projection: ImageProjection, grid: tuple[slice, slice] = (slice(None), slice(None)),
                obstacles: np.ndarray | None = None) -> np.ndarray:
        """Pixels that are white but no line: off the field, the robot's own feet and arms, goal posts
        (on the ground they would be lines behind the goal) and ball candidates; only those of ``grid``
        (rows, columns: the scan lines), every pixel by default. ``obstacles``: ``self.obstacles(camera,
        projection)`` where it is at hand."""
        height, width = projection.height, projection.width
        if obstacles is None:
            obstacles = self.obstacles(camera, projection)
        ignored = obstacles[grid]
        boundary = self.field_boundary.rows(camera)
        if boundary.size == width:
            rows, limits = np.arange(height)[grid[0]], boundary[grid[1]]
            highest = float(limits.max()) if limits.size else 0.0
            # off the field: above the boundary; only the rows above its lowest point are compared
            above = int(np.searchsorted(rows, highest)) if math.isfinite(highest) else len(rows)
            ignored = ignored.copy()
            if math.isfinite(highest) and math.isfinite(float(limits.min())):  # a whole row lies above a limit where it
                ignored[:above] |= rows[:above, None] < np.ceil(limits).astype(rows.dtype)[None, :]  # lies above its ceiling
            else:
                ignored[:above] |= rows[:above, None] < limits[None, :]
        return ignored

    def obstacles(self, camera: str, projection: ImageProjection) -> np.ndarray:
        """The robot's own feet and arms, goal posts and ball candidates in one image (h x w bool), drawn
        into one mask."""
        drawn = np.zeros((projection.height, projection.width), np.uint8)
        paint_own_body(projection, drawn)
        for post in self.goal_post_percept.posts:
            if post.camera == camera:
                half = post.image_width
                drawn[: int(post.image_foot) + 2, max(0, int(post.image_x - half)) : int(post.image_x + half) + 1] = 1
        for ball in self.ball_image_percept.candidates:
            if ball.camera == camera:
                cv2.circle(drawn, (int(ball.x), int(ball.y)), int(ball.radius * 1.4) + 2, 1, -1)
        return drawn.view(bool)

    def fit_circle(self, points: np.ndarray) -> np.ndarray:
        """Find the centre circle among ``points``; returns the points it does not explain."""
        p, out = self.parameters, self.line_percept
        if len(points) < p.min_circle_points:
            return points
        # every try at once: two points and the known radius give two centres
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
        dx, dy = points[None, :, 0] - centres[:, None, 0], points[None, :, 1] - centres[:, None, 1]
        residual = np.abs(np.sqrt(dx * dx + dy * dy) - CIRCLE_RADIUS)  # the norm as np.linalg.norm sums it, without its copies
        counts = (residual < p.inlier_distance).sum(axis=1)
        best = int(np.argmax(counts))
        if counts[best] < p.min_circle_points:
            return points
        centre, inliers = centres[best], residual[best] < p.inlier_distance
        angles = np.arctan2(points[inliers, 1] - centre[1], points[inliers, 0] - centre[0])
        if longest_arc(angles, math.radians(p.max_arc_gap)) < math.radians(p.min_arc):
            return points  # pieces of straight lines crossing a circle, or too short an arc to tell from a line
        out.circle_seen, out.circle_x, out.circle_y = True, float(centre[0]), float(centre[1])
        return points[~inliers]

    def fit_segments(self, points: np.ndarray) -> list[LineSegment]:
        """Straight segments through ``points``, the best supported first, each cut to where its points are."""
        p = self.parameters
        segments: list[LineSegment] = []
        while len(points) >= p.min_line_points and len(segments) < 8:
            pairs = self.rng.integers(0, len(points), (p.iterations, 2))
            a, direction = points[pairs[:, 0]], points[pairs[:, 1]] - points[pairs[:, 0]]
            length = np.linalg.norm(direction, axis=1)
            usable = length >= 2 * LINE_WIDTH
            if not usable.any():
                break
            a, direction, length = a[usable], direction[usable], length[usable]
            normal = np.column_stack([-direction[:, 1], direction[:, 0]]) / length[:, None]
            offsets = np.abs(np.einsum("kj,nj->kn", normal, points) - np.einsum("kj,kj->k", normal, a)[:, None])
            counts = (offsets < p.inlier_distance).sum(axis=1)
            best = int(np.argmax(counts))
            if counts[best] < p.min_line_points:
                break
            inliers = offsets[best] < p.inlier_distance
            # refit on the inliers (principal axis), then cut at the outermost inliers
            chosen = points[inliers]
            centre = chosen.mean(axis=0)
            axis = np.linalg.svd(chosen - centre, full_matrices=False)[2][0]  # the full U (N x N) took ms for a few hundred points
            along = (chosen - centre) @ axis
            start, end = centre + along.min() * axis, centre + along.max() * axis
            if np.linalg.norm(end - start) >= 2 * LINE_WIDTH:
                segments.append(LineSegment(float(start[0]), float(start[1]), float(end[0]), float(end[1])))
            points = points[~inliers]
        return segments
