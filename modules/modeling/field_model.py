"""What the localization knows of the field: a distance map of its lines, the posts, and how to guess
poses from percepts. Built once from ``representations.field``; shared by the modelling modules."""

from __future__ import annotations

import math

import cv2
import numpy as np

from tafel.representations import field
from tafel.representations.perception import GoalPostPercept, LinePercept, LineSegment

CELL = 20.0  # mm per cell of the distance map
FAR = 2000.0  # mm: the distance reported for points off the map


class FieldModel:
    """The field's lines as a distance map (mm to the nearest painted line's centre), and its posts."""

    def __init__(self) -> None:
        self.half_x = field.LENGTH / 2 + field.BORDER_STRIP
        self.half_y = field.WIDTH / 2 + field.BORDER_STRIP
        width, height = int(2 * self.half_x / CELL) + 1, int(2 * self.half_y / CELL) + 1
        painted = np.full((height, width), 255, np.uint8)
        for x1, y1, x2, y2 in field.all_markings():
            cv2.line(painted, self.cell(x1, y1), self.cell(x2, y2), 0, 1)
        self.distance = cv2.distanceTransform(painted, cv2.DIST_L2, 5) * CELL
        # the map with a border of FAR round it, flat: ``line_distance_seen`` clamps cells off the map onto the border
        bordered = np.full((height + 2, width + 2), FAR, self.distance.dtype)
        bordered[1:-1, 1:-1] = self.distance
        self._bordered = bordered.ravel()
        self.posts = np.array(field.goal_post_positions())
        self.lines = np.array(field.line_segments())

    def cell(self, x: float, y: float) -> tuple[int, int]:
        return int(round((x + self.half_x) / CELL)), int(round((y + self.half_y) / CELL))

    def line_distance(self, points: np.ndarray) -> np.ndarray:
        """mm from each field point (... x 2) to the nearest line; ``FAR`` off the carpet."""
        column = np.round((points[..., 0] + self.half_x) / CELL).astype(int)
        row = np.round((points[..., 1] + self.half_y) / CELL).astype(int)
        rows, columns = self.distance.shape
        inside = (column >= 0) & (column < columns) & (row >= 0) & (row < rows)
        return np.where(inside, self.distance[np.clip(row, 0, rows - 1), np.clip(column, 0, columns - 1)], FAR)

    def line_distance_seen(self, poses: np.ndarray, points: np.ndarray) -> np.ndarray:
        """``line_distance`` of robot-frame ``points`` (M x 2, mm) as seen from each of the field ``poses`` (N x 3: mm,
        mm, rad): N x M mm, the same values to the last bit. The field positions' x and y are worked out apart (no
        N x M x 2 stack), in place, and each cell off the map (or not finite) is clamped onto the map's border of
        ``FAR``: one gather instead of the range tests, clips and choice (the particle filter's largest arrays)."""
        x, y, heading = poses[:, 0:1], poses[:, 1:2], poses[:, 2:3]
        c, s = np.cos(heading), np.sin(heading)
        px, py = points[:, 0], points[:, 1]
        rows, columns = self.distance.shape
        fx = x + c * px  # seen_from's x + c * px - s * py and y + s * px + c * py, in its order
        fx -= s * py
        fy = y + s * px
        fy += c * py
        # with sane inputs (finite, far below overflow) no position is NaN, and clipping keeps it; else NaN goes
        # to -1 (off the map, as its integer was) by the slower fmax
        sane = bool(np.abs(poses).max(initial=0.0) < 1e200) and bool(np.abs(points).max(initial=0.0) < 1e200)
        for value, half, last in ((fx, self.half_x, columns), (fy, self.half_y, rows)):
            value += half
            value /= CELL
            np.rint(value, out=value)  # np.round's for no decimals
            if sane:
                np.clip(value, -1.0, float(last), out=value)
            else:
                np.fmin(np.fmax(value, -1.0, out=value), float(last), out=value)
        row = fy.astype(np.intp)
        row += 1
        row *= columns + 2
        row += fx.astype(np.intp)
        row += 1
        return self._bordered.take(row)

    def post_distance(self, points: np.ndarray) -> np.ndarray:
        """mm from each field point (N x 2) to the nearest goal post."""
        return np.min(np.linalg.norm(points[:, None, :] - self.posts[None, :, :], axis=2), axis=1)

    def uniform(self, rng: np.random.Generator, count: int, x_range: tuple[float, float] | None = None) -> np.ndarray:
        """``count`` poses anywhere on the field (or within ``x_range``), facing anywhere."""
        low, high = x_range or (-field.LENGTH / 2, field.LENGTH / 2)
        return np.column_stack([rng.uniform(low, high, count), rng.uniform(-field.WIDTH / 2, field.WIDTH / 2, count),
                                rng.uniform(-math.pi, math.pi, count)])

    def own_half(self, rng: np.random.Generator, count: int) -> np.ndarray:
        return self.uniform(rng, count, (-field.LENGTH / 2, 0.0))

    def penalty_return(self, rng: np.random.Generator, count: int) -> np.ndarray:
        """Where a referee puts a robot back after a penalty: by a touchline of its own half, facing the field.
        The rules name a spot (about 0.5 m outside the touchline, level with the own penalty mark), referees
        place by eye and older rules put the robot on the line: this covers the own half's touchlines from on
        the line to the carpet's edge, either side."""
        side = rng.choice([-1.0, 1.0], count)
        return np.column_stack([rng.uniform(-field.LENGTH / 2 + 500.0, -500.0, count),
                                side * (field.WIDTH / 2 + rng.uniform(-100.0, field.BORDER_STRIP, count)),
                                -side * math.pi / 2 + rng.normal(0.0, 0.15, count)])

    def poses_from_percepts(self, rng: np.random.Generator, count: int, lines: LinePercept, posts: GoalPostPercept) -> np.ndarray:
        """``count`` poses that explain one of this frame's percepts (sensor resetting):

        - the centre circle: its centre is the centre spot; the heading from a line through it (the
          halfway line) or, without one, any;
        - a goal post: any post, at the measured distance, from any side, facing so that it is seen
          at the measured bearing;
        - a line segment: lying on any field line, anywhere along it, either way round;
        - nothing usable: anywhere.

        The kinds share the poses equally when several were seen.
        """
        if count <= 0:
            return np.zeros((0, 3))
        kinds = [kind for kind, seen in (("circle", lines.circle_seen), ("post", bool(posts.posts)),
                                         ("line", any(s.length >= 300.0 for s in lines.segments))) if seen]
        if not kinds:
            return self.uniform(rng, count)
        shares = np.bincount(rng.integers(0, len(kinds), count), minlength=len(kinds))
        make = {"circle": self._from_circle, "post": self._from_posts, "line": self._from_lines}
        return np.vstack([make[kind](rng, int(n), lines, posts) for kind, n in zip(kinds, shares) if n])

    def _from_lines(self, rng: np.random.Generator, count: int, lines: LinePercept, posts: GoalPostPercept) -> np.ndarray:
        segments = [s for s in lines.segments if s.length >= 300.0]
        seen = rng.integers(0, len(segments), count)  # each segment's middle and direction once, then the ones drawn
        middle = np.array([((s.x1 + s.x2) / 2, (s.y1 + s.y2) / 2) for s in segments])[seen]
        seen_angle = np.array([math.atan2(s.y2 - s.y1, s.x2 - s.x1) for s in segments])[seen]
        true = self.lines[rng.integers(0, len(self.lines), count)]
        along = rng.random(count)[:, None]
        point = true[:, :2] + along * (true[:, 2:] - true[:, :2])
        headings = np.arctan2(true[:, 3] - true[:, 1], true[:, 2] - true[:, 0]) - seen_angle + math.pi * rng.integers(0, 2, count)
        c, s = np.cos(headings), np.sin(headings)
        positions = point - np.column_stack([c * middle[:, 0] - s * middle[:, 1], s * middle[:, 0] + c * middle[:, 1]])
        return np.column_stack([positions, np.remainder(headings + math.pi, math.tau) - math.pi])

    def _from_circle(self, rng: np.random.Generator, count: int, lines: LinePercept, posts: GoalPostPercept) -> np.ndarray:
        centre = np.array([lines.circle_x, lines.circle_y])
        headings = rng.uniform(-math.pi, math.pi, count)
        through = [s for s in lines.segments if distance_to_line(centre, s) < 250.0]
        if through:
            segment = through[0]
            along = math.atan2(segment.y2 - segment.y1, segment.x2 - segment.x1)
            headings = math.pi / 2 - along + math.pi * rng.integers(0, 2, count) + rng.normal(0.0, 0.05, count)
        c, s = np.cos(headings), np.sin(headings)
        positions = -np.column_stack([c * centre[0] - s * centre[1], s * centre[0] + c * centre[1]])
        return np.column_stack([positions + rng.normal(0.0, 50.0, (count, 2)), np.remainder(headings + math.pi, math.tau) - math.pi])

    def _from_posts(self, rng: np.random.Generator, count: int, lines: LinePercept, posts: GoalPostPercept) -> np.ndarray:
        every = list(posts.posts)
        seen = rng.integers(0, len(every), count)  # each post's distance and bearing once, then the ones drawn
        distance = np.array([math.hypot(p.x, p.y) for p in every])[seen] * rng.normal(1.0, 0.05, count)
        bearing = np.array([math.atan2(p.y, p.x) for p in every])[seen]
        true = self.posts[rng.integers(0, len(self.posts), count)]
        around = rng.uniform(-math.pi, math.pi, count)
        positions = true + distance[:, None] * np.column_stack([np.cos(around), np.sin(around)])
        headings = np.remainder(around + math.pi - bearing + math.pi, math.tau) - math.pi
        on_field = (np.abs(positions[:, 0]) < self.half_x) & (np.abs(positions[:, 1]) < self.half_y)
        fresh = np.column_stack([positions, headings])[on_field]
        return np.vstack([fresh, self.uniform(rng, count - len(fresh))])


def distance_to_line(point: np.ndarray, segment: LineSegment) -> float:
    """mm from ``point`` to the infinite line through ``segment``."""
    a = np.array([segment.x1, segment.y1])
    d = np.array([segment.x2, segment.y2]) - a
    length = float(np.linalg.norm(d))
    if length < 1e-6:
        return float(np.linalg.norm(point - a))
    return abs(float(d[0] * (point - a)[1] - d[1] * (point - a)[0])) / length


def mirror(poses: np.ndarray, towards: tuple[float, float, float], far: float = math.inf) -> np.ndarray:
    """Each pose or its twin turned by 180 degrees about the centre spot (the field cannot tell them
    apart), whichever lies nearer to ``towards``; where both lie more than ``far`` mm from it (the robot
    was carried, as a referee does with a penalized robot), the one in the own half."""
    twin = np.column_stack([-poses[:, 0], -poses[:, 1], np.remainder(poses[:, 2], math.tau) - math.pi])  # rotation + 180 degrees
    own = np.hypot(poses[:, 0] - towards[0], poses[:, 1] - towards[1])
    other = np.hypot(twin[:, 0] - towards[0], twin[:, 1] - towards[1])
    take_twin = np.where(np.minimum(own, other) > far, twin[:, 0] < poses[:, 0], other < own)
    return np.where(take_twin[:, None], twin, poses)


FIELD_MODEL = FieldModel()
#: where a robot that has never been localized is: somewhere in its own half
OWN_HALF = (-field.LENGTH / 4, 0.0, 0.0)
