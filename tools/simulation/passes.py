"""Completed passes and own goals in a simulated match, from the world's ground truth (``tafel match``).

A robot touches the ball while it is the robot nearest the ball and its torso is within ``touch_mm`` of
it (as the referee judges touches). A pass is completed when the ball, last touched by one robot, is
next touched by a teammate, having travelled at least ``min_travel_mm`` (straight, from where the kicker
last touched it to where the teammate first does) in PLAYING, with no opponent's touch in between and
without the referee placing it meanwhile (a set play, a goal, a state other than PLAYING: the chain
starts anew). An own goal is a goal whose last touch was by a robot of the team that conceded it, unless
the ball was already on its way into that goal when that robot's touch began (faster than
``deflection_mm_s`` towards it): a save that failed, or a deflection, counts for the shooter.

Not a module: ``Match`` feeds it every tick (``observe``) and tells it the goals (``goal``).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field

#: mm the ball may move in one tick without being placed: a kicked ball makes at most ~60 mm in 10 ms
PLACED_JUMP_MM = 300.0
#: ticks over which the ball's velocity before a touch is measured
VELOCITY_TICKS = 10


@dataclass
class Pass:
    """One completed pass: when (s) it reached the teammate, the team's index (0, 1), the robots' indices,
    and how far the ball went (mm)."""

    time_s: float
    team: int
    kicker: int
    receiver: int
    distance_mm: float


@dataclass
class PassCounter:
    """Counts completed passes per team from the ball's and the robots' ground truth, tick by tick."""

    teams: Sequence[int]
    """each robot's team index (0 or 1), by robot index"""
    touch_mm: float = 250.0
    """mm from a robot's torso (on the ground) to the ball's centre within which it touches the ball"""
    min_travel_mm: float = 1000.0
    """mm the ball travels at least from the kicker's last touch to the teammate's first for a pass"""
    own_goal_x: Sequence[float] = (-1.0, 1.0)
    """the sign of x of each team's own goal (world): the first team attacks +x"""
    deflection_mm_s: float = 300.0
    """mm/s towards its own goal the ball came at a defender's touch for a goal after it to be the shooter's"""
    passes: list[Pass] = field(default_factory=list)
    own_goals: list[int] = field(default_factory=lambda: [0, 0])
    """own goals per team index: goals the team conceded from its own robot's last touch"""
    last_toucher: int | None = None
    """the robot index that touched the ball last in this chain (None: nobody since it was placed)"""
    released_at: tuple[float, float] = (0.0, 0.0)
    """mm: the ball at the last toucher's last touch"""
    ball: tuple[float, float] | None = None
    incoming_vx: float = 0.0
    """mm/s along x the ball came at as the last toucher's touch began"""
    track: list[tuple[float, float, float]] = field(default_factory=list)
    """the last ticks' (s, x, y) of the ball, for its velocity"""

    def observe(self, now: float, ball: tuple[float, float], robots: Sequence[tuple[float, float] | None], playing: bool) -> Pass | None:
        """One tick: the ball (world mm), each robot's torso on the ground (world mm; None: off the field,
        penalized), whether the game is in PLAYING. Returns the pass completed in this tick, if any."""
        previous, self.ball = self.ball, ball
        if not playing or (previous is not None and math.dist(previous, ball) > PLACED_JUMP_MM):
            self.last_toucher, self.track = None, []  # the referee placed the ball, or play stopped
            return None
        self.track = [*self.track[-VELOCITY_TICKS:], (now, *ball)]
        near = [(math.dist(ball, robot), index) for index, robot in enumerate(robots) if robot is not None]
        distance, toucher = min(near, default=(math.inf, -1))
        if distance >= self.touch_mm:
            return None
        completed = None
        kicker = self.last_toucher
        if toucher != kicker:  # a touch begins: how the ball came
            t0, x0, _ = self.track[0]
            self.incoming_vx = (ball[0] - x0) / (now - t0) if now > t0 else 0.0
        if kicker is not None and kicker != toucher and self.teams[kicker] == self.teams[toucher]:
            travelled = math.dist(self.released_at, ball)
            if travelled >= self.min_travel_mm:
                completed = Pass(now, self.teams[toucher], kicker, toucher, travelled)
                self.passes.append(completed)
        self.last_toucher, self.released_at = toucher, ball
        return completed

    def goal(self, conceding_team: int) -> bool:
        """A goal against ``conceding_team`` (index) was scored: whether it is an own goal (counted)."""
        saving = self.incoming_vx * self.own_goal_x[conceding_team] > self.deflection_mm_s  # already on its way in
        own = self.last_toucher is not None and self.teams[self.last_toucher] == conceding_team and not saving
        if own:
            self.own_goals[conceding_team] += 1
        self.last_toucher = None
        return own

    def count(self, team: int) -> int:
        """Completed passes of a team (index)."""
        return sum(p.team == team for p in self.passes)
