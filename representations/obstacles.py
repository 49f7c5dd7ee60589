"""Other robots near this one, to walk around: what was seen (``RobotsPercept``) and what is known
(``Obstacles``, from what was seen and what the teammates said). Robot frame, mm."""

from __future__ import annotations

import enum
import math
from collections.abc import Sequence
from dataclasses import dataclass

from tafel.core import bounded, representation

ROBOT_RADIUS = 150.0  # mm: a NAO's footprint, arms in, seen from above


class ObstacleKind(enum.Enum):
    robot = 0
    """seen, of a team not known"""
    teammate = 1
    """where a teammate said it was"""


@dataclass
class SeenRobot:
    """A robot seen this frame: its centre on the ground (mm, robot frame)."""

    x: float = 0.0
    y: float = 0.0


@representation
class RobotsPercept:
    """Robots seen this frame: by sonar, in the images, or (``tafel match --cameras off``) from the
    world's ground truth within the robot's view."""

    robots: list[SeenRobot]


@dataclass
class Obstacle:
    """Something to walk around: its centre (mm, robot frame), its radius (mm: the robot's and the
    uncertainty of where it is), what it is, and how old the news is (s)."""

    x: float = 0.0
    y: float = 0.0
    radius: float = ROBOT_RADIUS
    kind: ObstacleKind = ObstacleKind.robot
    age: float = 0.0


@representation
class Obstacles:
    """Every robot this one knows to be near (robot frame), nearest first."""

    obstacles: list[Obstacle]
    faint: list[Obstacle]
    """robots remembered beside or behind (where they cannot be seen again) for longer than the obstacles keep
    them: where one may still stand, not walked round but not walked into faster than the rules' pushing"""
    clearance: float = bounded(0.0, 2000.0, 0.0)
    """mm between this robot's centre and the nearest obstacle's edge (0: none near or touching)"""


def same_robots(places: Sequence[tuple[float, float]], seen: Sequence[tuple[float, float]], within: float) -> set[int]:
    """Which of the robots ``seen`` are the robots said to be at ``places`` (say, where teammates reported
    themselves; one frame, mm): for each place in turn the nearest seen robot not yet taken, if nearer than
    ``within`` mm. Each place is one robot: another beside it (an opponent in a duel with it) stays apart."""
    taken: set[int] = set()
    for px, py in places:
        distance, nearest = min(((math.hypot(sx - px, sy - py), k) for k, (sx, sy) in enumerate(seen) if k not in taken),
                                default=(math.inf, -1))
        if distance < within:
            taken.add(nearest)
    return taken
