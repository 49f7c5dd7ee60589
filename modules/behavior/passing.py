"""Where the player with the ball kicks it: a shot through the goal's most open lane, or a pass to a
teammate better placed to score. Field frame, mm (the opponent goal at +x); shared by the behaviours that
kick (``SoccerBehavior``); not a module.

The pass rule: the player with the ball passes to a teammate when all of these hold (else it shoots):

1. the teammate is better placed to score: at least ``pass_gain`` mm nearer the opponent goal's centre than
   the ball; or, when every lane of the own shot is blocked, it has an open shot itself (a lane to the goal
   mouth clear by ``lane_width``, from within ``shot_range`` of the goal) and is at most ``-blocked_gain`` mm
   farther from the goal than the ball (in a 2v2 the opponent striker holds back 0.65 m before the ball, on its
   way to the goal, and the supporter, 45 degrees off that way, could not be 1 m nearer within the field; by
   the opponent goal the supporter waits 1.2 m before the goal line, often a little farther from the goal than
   a ball the keeper blocks: the pass back to its open shot is the better chance);
2. it is within a kick's reach: ``pass_min`` to ``pass_max`` mm from the ball;
3. it is open: no opponent within ``pass_open`` mm of it;
4. the lane is clear: no opponent within ``lane_width`` mm of the ball's way to it;
5. the own shot is worse: the goal is farther than ``shot_range`` mm from the ball, or every lane to the
   goal mouth has an opponent within ``lane_width`` mm.

Of the teammates that qualify, the one nearest the opponent goal gets the ball. The strength follows the
distance (``pass_kick``): the short walk kick up to ``pass_short_max``, the long one up to ``pass_long_max``,
beyond it the keyframe kick (the strongest).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

from tafel.core import bounded
from tafel.representations import field as pitch
from tafel.representations.motion_control import WalkKick

Point = tuple[float, float]
#: the opponent goal's centre on its line (field mm)
GOAL = (pitch.LENGTH / 2, 0.0)


@dataclass
class PassParameters:
    pass_gain: float = bounded(0.0, 5000.0, 1000.0)
    """mm a teammate must be nearer the opponent goal than the ball to be passed to"""
    pass_min: float = bounded(0.0, 5000.0, 1000.0)
    """mm from the ball a pass goes at least (nearer, the teammate can take the ball itself)"""
    pass_max: float = bounded(500.0, 9000.0, 3500.0)
    """mm from the ball a pass goes at most"""
    pass_open: float = bounded(0.0, 3000.0, 700.0)
    """mm around the teammate free of opponents"""
    lane_width: float = bounded(0.0, 1500.0, 400.0)
    """mm either side of the ball's way (to the teammate or the goal) free of opponents"""
    shot_range: float = bounded(0.0, 9000.0, 3000.0)
    """mm from the ball to the goal within which an open shot is taken rather than a pass"""
    pass_short_max: float = bounded(0.0, 5000.0, 1400.0)
    """mm up to which a pass is the short walk kick (it rolls about 1 m in MuJoCo)"""
    pass_long_max: float = bounded(0.0, 9000.0, 2600.0)
    """mm up to which a pass is the long walk kick (about 2 m); beyond, the keyframe kick (2.2 to 3.1 m)"""
    pass_lead: float = bounded(0.0, 1000.0, 200.0)
    """mm ahead of the teammate (towards the opponent goal) the pass is aimed"""
    shot_aims: int = bounded(1, 9, 5)
    """points across the goal mouth a shot may aim at (the most open is taken)"""
    blocked_gain: float = bounded(-5000.0, 5000.0, -1000.0)
    """mm a teammate with an open shot must be nearer the opponent goal than the ball to be passed to when the own
    shot is blocked (negative: it may be that much farther)"""


def lane_clearance(start: Point, end: Point, others: Sequence[Point]) -> float:
    """mm from the segment ``start``-``end`` to the nearest of ``others`` (inf: none); a robot behind the
    start (the kicker's own side) does not count."""
    sx, sy = start
    dx, dy = end[0] - sx, end[1] - sy
    ahead = [(ox - sx, oy - sy) for ox, oy in others if (ox - sx) * dx + (oy - sy) * dy > 0.0]
    return min((segment_distance((dx, dy), other) for other in ahead), default=math.inf)


def segment_distance(end: Point, point: Point) -> float:
    """mm from ``point`` to the segment from the origin to ``end`` (same frame, mm)."""
    length2 = end[0] ** 2 + end[1] ** 2
    t = max(0.0, min(1.0, (point[0] * end[0] + point[1] * end[1]) / length2)) if length2 > 0.0 else 0.0
    return math.hypot(point[0] - t * end[0], point[1] - t * end[1])


def best_shot(ball: Point, opponents: Sequence[Point], p: PassParameters) -> tuple[Point, float]:
    """The point across the goal mouth (``shot_aims`` of them, a post's width inside the posts) with the
    most open lane from the ball, and that lane's clearance (mm); of equally open ones, the nearest the
    centre."""
    inside = pitch.GOAL_INNER_WIDTH / 2 - 250.0
    count = max(1, int(p.shot_aims))
    aims = [(GOAL[0], 0.0)] if count == 1 else [(GOAL[0], -inside + 2 * inside * k / (count - 1)) for k in range(count)]
    scored = [(min(lane_clearance(ball, aim, opponents), 5000.0), -abs(aim[1]), aim) for aim in aims]
    clearance, _, aim = max(scored)
    return aim, clearance


def open_shot(place: Point, opponents: Sequence[Point], p: PassParameters) -> bool:
    """Whether a robot at ``place`` (field mm) has an open shot: within ``shot_range`` of the goal and a lane to
    the goal mouth clear by ``lane_width``."""
    return math.dist(place, GOAL) <= p.shot_range and best_shot(place, opponents, p)[1] >= p.lane_width


def choose_pass(ball: Point, mates: Sequence[Point], opponents: Sequence[Point], p: PassParameters) -> Point | None:
    """Where to pass by the rule above (field mm: ``pass_lead`` ahead of the chosen teammate), or None: shoot."""
    _, shot_clearance = best_shot(ball, opponents, p)
    if math.dist(ball, GOAL) <= p.shot_range and shot_clearance >= p.lane_width:
        return None  # an open shot from near enough
    ball_to_goal = math.dist(ball, GOAL)
    blocked = shot_clearance < p.lane_width
    best: tuple[float, Point] | None = None
    for mate in mates:
        to_goal = math.dist(mate, GOAL)
        distance = math.dist(ball, mate)
        if not p.pass_min <= distance <= p.pass_max:
            continue
        if to_goal > ball_to_goal - p.pass_gain and not (blocked and to_goal <= ball_to_goal - p.blocked_gain and open_shot(mate, opponents, p)):
            continue
        if any(math.dist(mate, o) < p.pass_open for o in opponents) or lane_clearance(ball, mate, opponents) < p.lane_width:
            continue
        if best is None or to_goal < best[0]:
            best = (to_goal, mate)
    if best is None:
        return None
    mate = best[1]
    gx, gy = GOAL[0] - mate[0], GOAL[1] - mate[1]
    norm = max(math.hypot(gx, gy), 1.0)
    return mate[0] + gx / norm * p.pass_lead, mate[1] + gy / norm * p.pass_lead


def pass_kick(distance: float, p: PassParameters) -> WalkKick:
    """The kick for a pass of ``distance`` mm: the short walk kick up to ``pass_short_max``, the long one up
    to ``pass_long_max``; beyond, ``WalkKick.none``: the keyframe kick."""
    if distance <= p.pass_short_max:
        return WalkKick.short
    return WalkKick.long if distance <= p.pass_long_max else WalkKick.none
