"""Where to walk so as not to walk into anything: around discs (robots, and the areas the rules keep a
team out of) on the way to a target. Shared by the behaviours; not a module.

Everything in the robot frame (mm): the robot at the origin. A disc is (x, y, radius).
"""

from __future__ import annotations

import math
from collections.abc import Sequence

Disc = tuple[float, float, float]
MAX_DETOURS = 4  # waypoints tried round one disc after another before the robot goes straight on


def outside(x: float, y: float, discs: Sequence[Disc], margin: float = 0.0) -> tuple[float, float]:
    """(x, y) moved radially out of every disc it lies in (each grown by ``margin``): where a target in a
    forbidden area goes instead. Discs are handled in turn; two overlapping ones may need a second call."""
    for cx, cy, radius in discs:
        reach = radius + margin
        dx, dy = x - cx, y - cy
        distance = math.hypot(dx, dy)
        if distance < reach:
            if distance < 1e-6:  # at the centre: out towards the robot (or backwards, if it is there too)
                dx, dy, distance = (-cx, -cy, math.hypot(cx, cy)) if math.hypot(cx, cy) > 1e-6 else (-1.0, 0.0, 1.0)
            x, y = cx + dx / distance * reach, cy + dy / distance * reach
    return x, y


def blocking(x: float, y: float, discs: Sequence[Disc]) -> tuple[float, Disc] | None:
    """The first disc the straight walk from the origin to (x, y) runs into, and how far along (0..1);
    discs that hold the origin or the target are left out (the robot is in one, or has to go in)."""
    length_sq = x * x + y * y
    first: tuple[float, Disc] | None = None
    for disc in discs:
        cx, cy, radius = disc
        if math.hypot(cx, cy) < radius or math.hypot(x - cx, y - cy) < radius or length_sq < 1e-9:
            continue
        t = max(0.0, min(1.0, (cx * x + cy * y) / length_sq))
        if math.hypot(t * x - cx, t * y - cy) < radius and (first is None or t < first[0]):
            first = (t, disc)
    return first


def waypoint(x: float, y: float, discs: Sequence[Disc], margin: float = 100.0) -> tuple[float, float]:
    """Where to walk first on the way to (x, y): the target itself when the straight way is free, else a
    point beside the first disc in the way, on the side the straight line passes it (``margin`` mm
    clear of it), checked in turn against the other discs."""
    target = (x, y)
    for _ in range(MAX_DETOURS):
        hit = blocking(*target, discs)
        if hit is None:
            return target
        t, (cx, cy, radius) = hit
        px, py = t * target[0] - cx, t * target[1] - cy  # from the centre to the line's nearest point
        side = math.hypot(px, py)
        if side < 1e-6:  # straight through the centre: pass on the left of the way
            length = math.hypot(*target)
            px, py, side = -target[1] / length, target[0] / length, 1.0
        target = (cx + px / side * (radius + margin), cy + py / side * (radius + margin))
    return target
