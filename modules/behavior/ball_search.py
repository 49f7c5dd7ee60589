"""Which way to turn while searching the ball: towards where it probably is.

A striker that always turned left found a ball behind its right shoulder only after most of a full turn.
``SearchTurn`` turns towards the side from which the likely place comes into the head's reach sooner:

- the team's ball (``TeamMates.freshest_ball``) seen from the pose, while the pose is valid;
- while it is not but the particles have gathered (``RobotPose.deviation`` within ``unsure_deviation``: a
  robot carried elsewhere knows its place up to the field's mirror image), both places the team's ball may
  lie at: seen from the estimate and from its twin. Each is as likely, so the turn goes the way that brings
  the two (those beyond the head's reach) into reach after the least turning in sum (``LookAtBallBehavior``
  looks at those within reach meanwhile). Turning always left, a robot carried with the ball behind its
  right shoulder found it only after most of a full turn (kidnappings anywhere: the slowest recoveries);
- else the last seen ball, unless the robot lost track of its pose since (it may have been carried);
- else the way of the last search (left at first).

A place that came within the head's reach without the ball being found no longer counts in this search:
the turn goes on the same way rather than back; unless the pose jumped since (``jump``: the particles found
another place, from which the places lie elsewhere).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

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

    reach: float = 1.5
    """rad: a place this far to either side the head looks at without the body's turn (the head turns to 2.09, but
    at the edge, with the body turning away, a place passes out of view before the head gets there)"""
    max_range: float = 6000.0
    """mm: team balls farther away are not looked for by turning"""
    unsure_deviation: float = 400.0
    """mm: a pose not valid whose particles have gathered this close turns by both places of the team's ball"""
    side: float = 1.0
    searching: bool = False
    looked: set[int] = field(default_factory=set)
    """which places of the team's ball (0: seen from the estimate, 1: from its twin) have been within reach in
    this search (and the ball was not found there)"""
    jump: float = 500.0
    """mm (a radian counting 1000 mm): the pose moved this far in a frame (the particles found another place):
    places looked at from the old one count no more"""
    last_pose: tuple[float, float, float] | None = None

    def direction(self, ball: BallModel, pose: RobotPose, team: TeamBall | None) -> float:
        """+1 (turn left) or -1 (turn right) for this frame of a search; call ``found`` when the ball is."""
        starting, self.searching = not self.searching, True
        moved = self.last_pose is not None and (math.hypot(pose.x - self.last_pose[0], pose.y - self.last_pose[1])
                                                + 1000.0 * abs(math.remainder(pose.rotation - self.last_pose[2], math.tau))) > self.jump
        self.last_pose = (pose.x, pose.y, pose.rotation)
        if starting or moved:
            self.looked = set()
        places = self.team_bearings(pose, team)
        for place, bearing in places.items():
            if abs(math.remainder(bearing, math.tau)) <= self.reach:  # the head looks there; no ball there, it no longer counts
                self.looked.add(place)
        ahead = [bearing for place, bearing in places.items() if place not in self.looked]
        if ahead:
            left = sum(turn_to_see(bearing, 1.0, self.reach) for bearing in ahead)
            right = sum(turn_to_see(bearing, -1.0, self.reach) for bearing in ahead)
            self.side = 1.0 if left < right else -1.0
        elif starting and not places:
            seen_once = ball.time_since_seen > 0.0 and math.isfinite(ball.x) and math.isfinite(ball.y)
            if seen_once and not pose.lost:
                self.side = 1.0 if math.atan2(ball.y, ball.x) >= 0.0 else -1.0
        return self.side

    def found(self) -> None:
        """The ball is known again: the next search starts anew."""
        self.searching = False

    def team_bearings(self, pose: RobotPose, team: TeamBall | None) -> dict[int, float]:
        """rad to the team's ball within ``max_range``: seen from a valid pose (place 0), or from a gathered pose
        not valid (0) and from its twin (1: where the ball's mirror image lies seen from the estimate); none
        without a team's ball or with the particles spread."""
        if team is None or not (pose.valid or pose.deviation <= self.unsure_deviation):
            return {}
        balls = [(team.x, team.y)] if pose.valid else [(team.x, team.y), (-team.x, -team.y)]
        places = {}
        for place, (bx, by) in enumerate(balls):
            x, y = pose.to_robot(bx, by)
            if 0.0 < math.hypot(x, y) <= self.max_range:
                places[place] = math.atan2(y, x)
        return places
