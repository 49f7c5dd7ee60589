"""Which way to turn while searching the ball: towards where it probably is.

A striker that always turned left found a ball behind its right shoulder only after most of a full turn.
``SearchTurn`` turns towards the side from which the likely place comes into the head's reach sooner:

- the team's ball (``TeamMates.freshest_ball``) seen from the pose, while the pose is valid (an unsure
  robot cannot tell the ball's place from its mirror image: ``LookAtBallBehavior`` looks at both, within
  the head's reach);
- else the last seen ball, unless the robot lost track of its pose since (it may have been carried);
- else the way of the last search (left at first).

A place that came within the head's reach without the ball being found no longer counts in this search:
the turn goes on the same way rather than back.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from tafel.representations.modeling import BallModel, RobotPose
from tafel.representations.team import TeamBall


def turn_to_see(bearing: float, side: float, reach: float) -> float:
    """rad the body must turn towards ``side`` (+1 left, -1 right) until a place at ``bearing`` (rad,
    robot frame) is within ``reach`` rad of straight ahead, where the head can look at it."""
    bearing = math.remainder(bearing, math.tau)
    if abs(bearing) <= reach:
        return 0.0
    return abs(bearing) - reach if bearing * side > 0.0 else math.tau - abs(bearing) - reach


@dataclass
class SearchTurn:
    """The turning direction of a ball search, kept between frames: ``side`` +1 (left) or -1 (right)."""

    reach: float = 2.0
    """rad: a place this far to either side the head looks at without the body's turn"""
    max_range: float = 6000.0
    """mm: team balls farther away are not looked for by turning"""
    side: float = 1.0
    searching: bool = False
    looked: bool = False
    """whether the team's ball has been within reach in this search (and was not found there)"""

    def direction(self, ball: BallModel, pose: RobotPose, team: TeamBall | None) -> float:
        """+1 (turn left) or -1 (turn right) for this frame of a search; call ``found`` when the ball is."""
        starting, self.searching = not self.searching, True
        if starting:
            self.looked = False
        bearing = self.team_bearing(pose, team)
        if bearing is not None and not self.looked:
            left, right = turn_to_see(bearing, 1.0, self.reach), turn_to_see(bearing, -1.0, self.reach)
            if left == 0.0:  # within reach: the head looks there; no ball there, the turn goes on as it was
                self.looked = True
            else:
                self.side = 1.0 if left < right else -1.0
        elif starting and bearing is None:
            seen_once = ball.time_since_seen > 0.0 and math.isfinite(ball.x) and math.isfinite(ball.y)
            if seen_once and not pose.lost:
                self.side = 1.0 if math.atan2(ball.y, ball.x) >= 0.0 else -1.0
        return self.side

    def found(self) -> None:
        """The ball is known again: the next search starts anew."""
        self.searching = False

    def team_bearing(self, pose: RobotPose, team: TeamBall | None) -> float | None:
        """rad to the team's ball seen from a valid pose; None without either."""
        if team is None or not pose.valid:
            return None
        x, y = pose.to_robot(team.x, team.y)
        return math.atan2(y, x) if 0.0 < math.hypot(x, y) <= self.max_range else None
