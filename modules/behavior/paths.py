"""Where to walk so as not to walk into anything: around discs (robots, and the areas the rules keep a
team out of) on the way to a target. Shared by the behaviours; not a module.

Everything in the robot frame (mm): the robot at the origin. A disc is (x, y, radius).

The way round a disc follows the tangent from the robot to the disc grown by a margin, on the side the
straight line passes it (a disc dead ahead: the side asked for, else the right, so that two robots
walking at each other both step aside the same way round). A robot already within the grown disc and
heading further in steps out sideways instead of walking on, even when its target lies in that disc too
(two robots' discs overlap, and moving the target out of one put it into the other).
"""

from __future__ import annotations

import math
from collections.abc import Sequence

Disc = tuple[float, float, float]
MAX_DETOURS = 4  # waypoints tried round one disc after another before the robot goes straight on
MIN_STEP = 300.0  # mm: a detour's waypoint is at least this far, so that the walk does not slow down at it
TANGENT_SLACK = 0.05  # rad beyond the exact tangent: the way to the waypoint clears the grown disc
DEAD_AHEAD = 0.3  # share of the grown radius: a disc whose centre lies this near the way is "ahead" (the side asked for)
RIGHT, LEFT = -1, 1
OUTSIDE_PASSES = 4  # rounds of ``outside`` over the discs: one moved out of a disc into an overlapping one is moved again


def outside(x: float, y: float, discs: Sequence[Disc], margin: float = 0.0) -> tuple[float, float]:
    """(x, y) moved radially out of every disc it lies in (each grown by ``margin``): where a target in a
    forbidden area goes instead. Discs are handled in turn, and again while a move put it into another
    (at most ``OUTSIDE_PASSES`` rounds: closed in by discs, it stays where the last round put it)."""
    for _ in range(OUTSIDE_PASSES):
        moved = False
        for cx, cy, radius in discs:
            reach = radius + margin
            dx, dy = x - cx, y - cy
            distance = math.hypot(dx, dy)
            if distance < reach - 1e-6:
                if distance < 1e-6:  # at the centre: out towards the robot (or backwards, if it is there too)
                    dx, dy, distance = (-cx, -cy, math.hypot(cx, cy)) if math.hypot(cx, cy) > 1e-6 else (-1.0, 0.0, 1.0)
                x, y, moved = cx + dx / distance * reach, cy + dy / distance * reach, True
        if not moved:
            break
    return x, y


def hit(x: float, y: float, cx: float, cy: float, reach: float) -> float | None:
    """Where along (0..1) the straight way from the origin to (x, y) comes nearest (cx, cy), if that is
    within ``reach`` of it; None if the way keeps out. From within the disc: 0 when the way leads further
    in, None when it leads out."""
    if math.hypot(cx, cy) < reach:
        return 0.0 if cx * x + cy * y > 0.0 else None
    t = max(0.0, min(1.0, (cx * x + cy * y) / max(x * x + y * y, 1e-9)))
    return t if math.hypot(t * x - cx, t * y - cy) < reach else None


def blocking(x: float, y: float, discs: Sequence[Disc], margin: float = 0.0) -> tuple[float, Disc] | None:
    """The first disc (grown by ``margin``) the straight walk from the origin to (x, y) runs into, and how
    far along (0..1). A disc that holds the target but not the robot is left out (the robot has to go in);
    one that holds the robot blocks at 0 when the way leads further in, and is left out when it leads out."""
    length_sq = x * x + y * y
    first: tuple[float, Disc] | None = None
    if length_sq < 1e-9:
        return None
    for disc in discs:
        cx, cy, radius = disc
        reach = radius + margin
        if math.hypot(x - cx, y - cy) < reach and math.hypot(cx, cy) >= reach:
            continue
        t = hit(x, y, cx, cy, reach)
        if t is not None and (first is None or t < first[0]):
            first = (t, disc)
    return first


def side_of(x: float, y: float, disc: Disc, reach: float, prefer: int = 0) -> int:
    """The side (``LEFT`` or ``RIGHT``) to pass ``disc`` on the way to (x, y): away from its centre; when
    the centre lies nearly on the way (``DEAD_AHEAD``), ``prefer`` (or the right, if none)."""
    cx, cy, _ = disc
    length = max(math.hypot(x, y), 1e-9)
    cross = (x * cy - y * cx) / length  # mm the centre lies left of the way
    if abs(cross) < DEAD_AHEAD * reach:
        return prefer if prefer in (LEFT, RIGHT) else RIGHT
    return RIGHT if cross > 0 else LEFT


def around(disc: Disc, reach: float, side: int) -> tuple[float, float]:
    """A waypoint past ``disc`` (grown to ``reach``) on ``side``: on the tangent from the robot, or, from
    within it, sideways and outwards (the deeper in, the more outwards)."""
    cx, cy, _ = disc
    distance, bearing = math.hypot(cx, cy), math.atan2(cy, cx)
    if distance > reach:
        direction = bearing + side * (math.asin(reach / distance) + TANGENT_SLACK)
        length = max(math.sqrt(distance * distance - reach * reach), MIN_STEP)
    else:
        depth = (reach - distance) / reach
        direction = bearing + side * (math.pi / 2 + TANGENT_SLACK + depth * math.pi / 4)
        length = MIN_STEP
    return length * math.cos(direction), length * math.sin(direction)


def free_direction(x: float, y: float, discs: Sequence[Disc], margin: float, prefer: int = 0) -> tuple[float, float, int]:
    """A waypoint ``MIN_STEP`` mm away in the direction nearest that of (x, y) whose way runs into no disc
    (grown by ``margin``; one that holds the robot: not further in), the side asked for first at equal
    angles; the origin (stand) when every direction is closed. Also the side it turned to (0: none)."""
    bearing, first = math.atan2(y, x), prefer if prefer in (LEFT, RIGHT) else RIGHT
    for step in range(61):  # 3-degree steps round to the back
        for side in ((first, -first) if step else (0,)):
            direction = bearing + side * math.radians(3.0 * step)
            way = (MIN_STEP * math.cos(direction), MIN_STEP * math.sin(direction))
            if clear(*way, discs, margin):
                return way[0], way[1], side
    return 0.0, 0.0, 0


def clear(x: float, y: float, discs: Sequence[Disc], margin: float) -> bool:
    """Whether the straight way from the origin to (x, y) keeps out of every disc (grown by ``margin``),
    the end included; a disc that holds the robot: the way does not lead further in."""
    return all(hit(x, y, cx, cy, radius + margin) is None for cx, cy, radius in discs)


def detour(x: float, y: float, discs: Sequence[Disc], margin: float = 100.0, prefer: int = 0) -> tuple[float, float, int]:
    """Where to walk first on the way to (x, y), and the side of the first disc passed (0: none): the
    target itself when the straight way is free of every disc grown by ``margin``, else a waypoint round
    the first disc in the way (``around``), checked in turn against the others. Within a disc and heading
    further in, or still blocked after ``MAX_DETOURS``: the free direction nearest the target's
    (``free_direction``)."""
    target, first_side = (x, y), 0
    for _ in range(MAX_DETOURS):
        hit = blocking(*target, discs, margin)
        if hit is None:
            return target[0], target[1], first_side
        _, disc = hit
        reach = disc[2] + margin
        side = side_of(*target, disc, reach, prefer if first_side == 0 else first_side)
        if math.hypot(disc[0], disc[1]) < reach:  # within it: out of every disc that holds the robot at once
            break
        first_side = first_side or side
        target = around(disc, reach, side)
    else:
        if blocking(*target, discs, margin) is None:
            return target[0], target[1], first_side
    way_x, way_y, turned = free_direction(x, y, discs, margin, first_side or prefer or side)
    return way_x, way_y, first_side or turned


def waypoint(x: float, y: float, discs: Sequence[Disc], margin: float = 100.0) -> tuple[float, float]:
    """Where to walk first on the way to (x, y) (``detour`` without a side asked for)."""
    way_x, way_y, _ = detour(x, y, discs, margin)
    return way_x, way_y
