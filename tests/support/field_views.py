"""Synthetic percepts of the field from a known pose: what perfect detectors would report, with noise.

Module tests of the localization feed these to ``SelfLocator`` through the mocked blackboard, so
that the filter is tested apart from the images.
"""

from __future__ import annotations

import functools
import math

import numpy as np

from tafel.representations import field
from tafel.representations.perception import GoalPost, GoalPostPercept, LinePercept, LineSegment

VIEW = math.radians(30.0)  # half the angle one camera image covers
REACH = 3500.0  # mm


def to_robot(pose: tuple[float, float, float], points: np.ndarray) -> np.ndarray:
    x, y, rotation = pose
    c, s = math.cos(rotation), math.sin(rotation)
    d = points - np.array([x, y])
    return np.column_stack([c * d[:, 0] + s * d[:, 1], -s * d[:, 0] + c * d[:, 1]])


def visible(points: np.ndarray, head: float = 0.0, reach: float = REACH) -> np.ndarray:
    """Which robot-frame points the robot sees with its head turned by ``head`` (rad)."""
    distance = np.hypot(points[:, 0], points[:, 1])
    bearing = np.abs(np.remainder(np.arctan2(points[:, 1], points[:, 0]) - head + math.pi, math.tau) - math.pi)
    return (distance > 200.0) & (distance < reach) & (bearing < VIEW)


@functools.cache
def marking_samples() -> tuple[np.ndarray, tuple[int, ...], tuple[bool, ...]]:
    """Points every 100 mm along every marking (field mm, all markings in one array), where each marking's points
    start (and the last one's end), and which markings are straight lines: the same every frame, so worked out once."""
    samples, starts, straight = [], [0], []
    lines = set(field.line_segments())
    for x1, y1, x2, y2 in field.all_markings():
        steps = max(2, int(math.hypot(x2 - x1, y2 - y1) / 100.0))
        along = np.linspace(0.0, 1.0, steps)[:, None]
        samples.append(np.array([x1, y1]) + along * np.array([x2 - x1, y2 - y1]))
        starts.append(starts[-1] + steps)
        straight.append((x1, y1, x2, y2) in lines)
    points = np.concatenate(samples)
    points.flags.writeable = False  # shared by every call
    return points, tuple(starts), tuple(straight)


def line_percept(pose: tuple[float, float, float], rng: np.random.Generator, noise: float = 20.0, head: float = 0.0) -> LinePercept:
    """Points every 100 mm along every marking the robot sees, with the segments they form."""
    percept = LinePercept(segments=[])
    samples, starts, straight = marking_samples()
    seen = to_robot(pose, samples)
    shown = visible(seen, head)
    for start, end, line in zip(starts, starts[1:], straight):
        part = seen[start:end][shown[start:end]]
        if len(part) >= 5 and line:
            percept.segments.append(LineSegment(*part[0], *part[-1]))
    all_points = seen[shown]
    percept.points = (all_points + rng.normal(0.0, noise, all_points.shape)).astype(np.float32)
    centre = to_robot(pose, np.zeros((1, 2)))
    if visible(centre, head)[0]:
        percept.circle_seen, percept.circle_x, percept.circle_y = True, float(centre[0, 0]), float(centre[0, 1])
    return percept


def post_percept(pose: tuple[float, float, float], head: float = 0.0) -> GoalPostPercept:
    seen = to_robot(pose, np.array(field.goal_post_positions()))
    return GoalPostPercept(posts=[GoalPost(float(x), float(y), "top") for x, y in seen[visible(seen, head, 6000.0)]])
