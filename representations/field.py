"""The RoboCup SPL field in numbers (mm, field frame: origin at the centre spot, x towards the
opponent goal, y left). Shared by modules and the simulated worlds."""

from __future__ import annotations

import math

LENGTH = 9000.0
WIDTH = 6000.0
LINE_WIDTH = 50.0
BORDER_STRIP = 700.0
CENTER_CIRCLE_DIAMETER = 1500.0
PENALTY_AREA_LENGTH = 1650.0
PENALTY_AREA_WIDTH = 4000.0
GOAL_AREA_LENGTH = 600.0
GOAL_AREA_WIDTH = 2200.0
PENALTY_MARK_DISTANCE = 1300.0
GOAL_INNER_WIDTH = 1500.0
GOAL_POST_DIAMETER = 100.0
GOAL_HEIGHT = 800.0
GOAL_DEPTH = 500.0
BALL_RADIUS = 50.0
BALL_MASS = 0.044  # kg
MARK_SIZE = 100.0  # the penalty marks and the centre mark are crosses this long and LINE_WIDTH wide


def line_segments() -> list[tuple[float, float, float, float]]:
    """The field's straight lines as (x1, y1, x2, y2) in mm, centre lines of the painted lines."""
    half_x, half_y = LENGTH / 2, WIDTH / 2
    segments = [(-half_x, -half_y, half_x, -half_y), (-half_x, half_y, half_x, half_y),
                (-half_x, -half_y, -half_x, half_y), (half_x, -half_y, half_x, half_y), (0.0, -half_y, 0.0, half_y)]
    for sign in (-1.0, 1.0):
        for depth, width in ((PENALTY_AREA_LENGTH, PENALTY_AREA_WIDTH), (GOAL_AREA_LENGTH, GOAL_AREA_WIDTH)):
            x_inner, y = sign * (half_x - depth), width / 2
            segments += [(sign * half_x, -y, x_inner, -y), (sign * half_x, y, x_inner, y), (x_inner, -y, x_inner, y)]
    return segments


def mark_centres() -> list[tuple[float, float]]:
    """The centre mark and both penalty marks (mm)."""
    mark = LENGTH / 2 - PENALTY_MARK_DISTANCE
    return [(0.0, 0.0), (-mark, 0.0), (mark, 0.0)]


def goal_post_positions() -> list[tuple[float, float]]:
    """The centres of the four goal posts (mm): opponent left, opponent right, own left, own right."""
    x = LENGTH / 2 + GOAL_POST_DIAMETER / 2
    y = (GOAL_INNER_WIDTH + GOAL_POST_DIAMETER) / 2
    return [(x, y), (x, -y), (-x, y), (-x, -y)]


def goal_of(x_mm: float, y_mm: float) -> int:
    """Where a ball at (x, y) is: 1 wholly over the opponent goal line between the posts (a goal for
    the team attacking +x), -1 the same at the own goal, 0 anywhere else."""
    if abs(x_mm) > LENGTH / 2 + BALL_RADIUS and abs(y_mm) < GOAL_INNER_WIDTH / 2:
        return 1 if x_mm > 0 else -1
    return 0


def mark_segments() -> list[tuple[float, float, float, float]]:
    """Both strokes of every mark's cross as (x1, y1, x2, y2) in mm."""
    half = MARK_SIZE / 2
    return [s for x, y in mark_centres() for s in ((x - half, y, x + half, y), (x, y - half, x, y + half))]


def circle_segments(steps: int = 32) -> list[tuple[float, float, float, float]]:
    """The centre circle as ``steps`` chords (mm)."""
    radius = CENTER_CIRCLE_DIAMETER / 2
    corners = [(radius * math.cos(2 * math.pi * i / steps), radius * math.sin(2 * math.pi * i / steps)) for i in range(steps + 1)]
    return [(*a, *b) for a, b in zip(corners, corners[1:])]


def all_markings() -> list[tuple[float, float, float, float]]:
    """Everything painted on the field, as segments (mm): lines, the circle's chords and the marks."""
    return line_segments() + circle_segments() + mark_segments()
