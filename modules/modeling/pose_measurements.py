"""What this frame's percepts say of the SelfLocator's poses: how likely each particle makes the line points, goal
posts and the centre circle (``log_likelihoods``), whether they contradict the estimate (``contradictions``), the
team's ball against the ball seen, and what was seen that pins a pose down."""

from __future__ import annotations

import math
from typing import Protocol

import numpy as np

from tafel.modules.modeling.field_model import FIELD_MODEL
from tafel.modules.modeling.particle_filter import seen_from
from tafel.representations.geometry import Pose2D
from tafel.representations.perception import BallPercept, GoalPostPercept, LinePercept
from tafel.representations.team import TeamBall, TeamMates


class MeasurementParameters(Protocol):
    """What these functions read of SelfLocator.Parameters."""

    circle_std: float
    max_points: int
    point_std: float  # mm
    point_std_per_m: float  # mm per metre
    point_weight: float
    post_std: float
    post_std_per_m: float
    team_ball_max_age: float  # s
    team_ball_std: float  # mm
    team_ball_std_per_m: float  # mm per metre
    team_ball_std_per_s: float  # mm per second


WATCH_MIN_POINTS = 10  # line points a frame needs to say whether the lines fit the estimate ...
WATCH_LINES_OFF = 0.2  # ... the share of them beyond 2.5 standard deviations that contradicts it (a robot carried where
WATCH_LINES_ON = 0.1  # the old pose half fits: about a quarter), and the share at most that agrees (an accurate pose: 0)


def log_likelihoods(particles: np.ndarray, lines: LinePercept, posts: GoalPostPercept, p: MeasurementParameters
                    ) -> tuple[np.ndarray, float]:
    """Each particle's log-likelihood of this frame's percepts (line points, goal posts, the centre circle's centre),
    and how many full measurements they count as (0: nothing was seen)."""
    log_weight = np.zeros(len(particles))
    measurements = 0.0
    points = line_points(lines)
    if len(points):
        if len(points) > p.max_points:
            points = points[np.linspace(0, len(points) - 1, p.max_points).astype(int)]
        std = point_std(points, p)
        distance = FIELD_MODEL.line_distance_seen(particles, points)  # line_distance(seen_from(particles, points))'s
        log_weight += p.point_weight * robust(distance / std).sum(axis=1)
        measurements += p.point_weight * len(points)
    feet = [(post.x, post.y) for post in posts.posts if math.isfinite(post.x) and math.isfinite(post.y)]
    if feet:  # every post from every particle at once; each post's term added in turn, as one by one
        seen = np.array(feet)
        distances = FIELD_MODEL.post_distance(seen_from(particles, seen).reshape(-1, 2)).reshape(len(particles), len(feet))
        for k, (x, y) in enumerate(feet):
            log_weight += robust(distances[:, k] / post_std(x, y, p))
        measurements += len(feet)
    if lines.circle_seen and math.isfinite(lines.circle_x) and math.isfinite(lines.circle_y):
        centre = seen_from(particles, np.array([[lines.circle_x, lines.circle_y]]))[:, 0]
        log_weight += robust(np.linalg.norm(centre, axis=1) / p.circle_std)
        measurements += 1
    return log_weight, measurements


def robust(normalized: np.ndarray) -> np.ndarray:
    """Log-likelihood of normalized errors, Gaussian near zero and flat beyond 2.5 standard deviations,
    so that one wrong percept cannot wipe out the right particles."""
    log = np.minimum(normalized, 2.5)  # -0.5 * min(...) ** 2, in place for arrays: the particles' largest
    if not isinstance(log, np.ndarray):
        return -0.5 * log**2
    np.square(log, out=log)
    log *= -0.5
    return log


def line_points(lines: LinePercept) -> np.ndarray:
    """This frame's line points (M x 2, robot mm), without the ones no camera sees (not finite, over 20 m)."""
    points = np.asarray(lines.points, dtype=float).reshape(-1, 2)
    return points[np.isfinite(points).all(axis=1) & (np.abs(points) < 20000.0).all(axis=1)]


def point_std(points: np.ndarray, p: MeasurementParameters) -> np.ndarray:
    """mm: each line point's noise, growing with its distance."""
    return p.point_std + p.point_std_per_m * np.linalg.norm(points, axis=1) / 1000.0


def post_std(x: float, y: float, p: MeasurementParameters) -> float:
    """mm: a goal post's noise at (x, y) (robot mm), growing with its distance."""
    return p.post_std + p.post_std_per_m * math.hypot(x, y) / 1000.0


def contradictions(estimate: np.ndarray, lines: LinePercept, posts: GoalPostPercept, ball_off: tuple[float, float] | None,
                   p: MeasurementParameters) -> list[bool]:
    """For the centre circle, each goal post, the line points (``WATCH_MIN_POINTS`` at least) and the ball seen
    (``ball_off``: ``team_ball_off``), seen from the ``estimate``: whether it contradicts the estimate (lies beyond 2.5
    standard deviations of the circle's or the nearest post's place; ``WATCH_LINES_OFF`` of the points that far off
    every line; the ball that far from the team's ball and from its mirror image). What says nothing either way (the
    share of line points between ``WATCH_LINES_ON`` and ``WATCH_LINES_OFF``, a ball near the mirror image, which is
    the side belief's matter) is left out."""
    pose, verdicts = Pose2D(*estimate), []
    if lines.circle_seen and math.isfinite(lines.circle_x) and math.isfinite(lines.circle_y):
        verdicts.append(math.hypot(*pose.to_global(lines.circle_x, lines.circle_y)) / p.circle_std >= 2.5)
    for post in posts.posts:
        if math.isfinite(post.x) and math.isfinite(post.y):
            place = np.array([pose.to_global(post.x, post.y)])
            verdicts.append(float(FIELD_MODEL.post_distance(place)[0]) / post_std(post.x, post.y, p) >= 2.5)
    points = line_points(lines)
    if len(points) >= WATCH_MIN_POINTS:
        seen = seen_from(np.array([estimate]), points)
        off = float(np.mean(FIELD_MODEL.line_distance(seen)[0] / point_std(points, p) >= 2.5))
        if off >= WATCH_LINES_OFF or off <= WATCH_LINES_ON:  # in between, lines say nothing either way
            verdicts.append(off >= WATCH_LINES_OFF)
    if ball_off is not None and (ball_off[0] < 2.5 or min(ball_off) >= 2.5):  # near the mirror image: the side belief's matter
        verdicts.append(min(ball_off) >= 2.5)
    return verdicts


def team_ball_off(pose: Pose2D, ball: BallPercept, seen: tuple[TeamBall, float] | None) -> tuple[float, float] | None:
    """The ball seen this frame, placed on the field from ``pose``, against the team's ball and its mirror image
    (the twin's view): the distances in standard deviations (as the side belief weighs them); None without
    either ball (``seen``: ``ball_against_team``). Far from both, the pose is wrong, not mirrored: a robot carried
    where the lines it looks at (next to the ball) half fit the old place."""
    if seen is None:
        return None
    team, std = seen
    x, y = pose.to_global(ball.x, ball.y)
    return math.hypot(x - team.x, y - team.y) / std, math.hypot(x + team.x, y + team.y) / std


def ball_against_team(ball: BallPercept, team_mates: TeamMates, p: MeasurementParameters) -> tuple[TeamBall, float] | None:
    """The team's ball and the standard deviation (mm) of where the ball seen this frame may lie against it
    (its own distance's error and the team ball's age); None without either ball."""
    team = team_mates.freshest_ball(p.team_ball_max_age)
    if team is None or not (ball.seen and math.isfinite(ball.x) and math.isfinite(ball.y)):
        return None
    return team, p.team_ball_std + p.team_ball_std_per_m * math.hypot(ball.x, ball.y) / 1000.0 + p.team_ball_std_per_s * team.age


def usable_percepts(lines: LinePercept, posts: GoalPostPercept) -> bool:
    """Whether this frame saw something fresh poses can be made from: the circle, a post, a line segment."""
    return bool(lines.circle_seen or posts.posts or any(s.length >= 300.0 for s in lines.segments))


def evidence_seen(lines: LinePercept, posts: GoalPostPercept, rotation: float) -> set[str]:
    """What this frame saw that pins a pose down: the circle, a post, lines along or across the field (seen from a
    robot turned by ``rotation``)."""
    seen = {"circle"} if lines.circle_seen else set()
    if posts.posts:
        seen.add("post")
    for segment in lines.segments:
        if segment.length >= 300.0:
            angle = abs(math.remainder(math.atan2(segment.y2 - segment.y1, segment.x2 - segment.x1) + rotation, math.pi))
            seen.add("along" if angle < 0.35 else "across" if angle > math.pi / 2 - 0.35 else "slanted")
    return seen
