"""Which of two twins the robot is at: the SPL field looks the same turned by 180 degrees about the centre
spot, so every pose the lines and posts support has a twin they support as much. The ``SelfLocator``
tracks one of the two (its particles folded onto it, ``fold``) and keeps the other apart as the mirror
hypothesis; ``SideBelief`` decides between them on what the field cannot tell: where the rules place a
robot, the ball the team agrees on, and the history of the estimate."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from tafel.representations.geometry import Pose2D
from tafel.representations.team import TeamBall

ROTATION_MM = 1000.0  # mm a radian of heading counts as when poses are compared


def twin(poses: np.ndarray) -> np.ndarray:
    """Poses (... x 3: x, y, rotation) turned by 180 degrees about the centre spot."""
    out = np.array(poses, dtype=float, copy=True)
    out[..., :2] *= -1.0
    out[..., 2] = np.remainder(out[..., 2], math.tau) - math.pi  # rotation + 180 degrees, in [-pi, pi)
    return out


def pose_distance(poses: np.ndarray, reference: np.ndarray) -> np.ndarray:
    """mm between poses (N x 3) and one pose, a radian of heading counting ``ROTATION_MM``."""
    turn = np.abs(np.remainder(poses[:, 2] - reference[2] + math.pi, math.tau) - math.pi)
    return np.hypot(poses[:, 0] - reference[0], poses[:, 1] - reference[1]) + ROTATION_MM * turn


def fold(poses: np.ndarray, towards: np.ndarray) -> np.ndarray:
    """Each pose or its twin, whichever is nearer to ``towards`` (position and heading): the particles
    of both twins gather into one cloud, and which side it is on is ``SideBelief``'s question."""
    twins = twin(poses)
    nearer_twin = pose_distance(twins, towards) < pose_distance(poses, towards)
    return np.where(nearer_twin[:, None], twins, poses)


def relative(start: tuple[float, float, float], now: tuple[float, float, float]) -> tuple[float, float, float]:
    """The motion from odometry pose ``start`` to ``now`` in ``start``'s frame (forward, left, turn)."""
    forward, left, turn = Pose2D(*now).relative_to(Pose2D(*start))
    return forward, left, turn


def back(pose: np.ndarray, motion: tuple[float, float, float]) -> np.ndarray:
    """Where a robot now at field ``pose`` was before it made ``motion`` (from ``relative``)."""
    return np.array(tuple(Pose2D(*pose) * Pose2D(*motion).inverse()))


def robust(normalized: float) -> float:
    """Log-likelihood of a normalized error, flat beyond 2.5 standard deviations (one wrong report cannot
    decide alone)."""
    return -0.5 * min(normalized, 2.5) ** 2


@dataclass
class Placement:
    """The rules put the robot in its own half (x <= 0) when its odometry read ``odometry``; it has walked
    ``path`` mm since, so its place then, from a pose now, is known the less the farther it walked."""

    odometry: tuple[float, float, float]
    path: float = 0.0


class SideBelief:
    """Log-odds ``odds`` that the tracked estimate, not its twin, is where the robot is.

    - Placement: the rules put the robot in its own half at the start and on a touchline of its own half
      after a penalty. From a pose now and the odometry since, the place then follows; a twin that puts
      it beyond the halfway line broke the rule. The more it walked, the less sure that place is.
    - The team's ball: a ball seen now lies on the field where a teammate saw it, from one twin only
      (unless it lies near the centre spot).
    - History: the belief carries on while the estimate is tracked; it is cleared when the robot was
      carried elsewhere (``carried``), and a confident belief needs much evidence to turn.
    """

    def __init__(self) -> None:
        self.odds = 0.0
        self.placement: Placement | None = None
        self.message: tuple[int, int] = (0, -1)  # the team message whose ball was used last ...
        self.message_odds = 0.0  # ... and the log-odds it has given so far (for the estimate)
        self.placement_odds = 0.0  # the log-odds the placement has given so far (for the estimate)

    def place(self, odometry: tuple[float, float, float]) -> None:
        """The rules have just put the robot in its own half; what was believed before no longer counts."""
        self.odds, self.placement, self.placement_odds = 0.0, Placement(odometry), 0.0

    def carried(self, placed_since: bool = False) -> None:
        """Carried elsewhere, by nobody the rules name: the old side no longer holds, nor the placement,
        unless the robot has not been localized since it (``placed_since``: a first fix was wrong)."""
        self.odds, self.placement_odds = 0.0, 0.0
        if not placed_since:
            self.placement = None

    def told(self, cap: float) -> None:
        """Told the true pose (KnownPose): the tracked estimate is right."""
        self.odds, self.placement, self.placement_odds = cap, None, 0.0

    def walked(self, step: float) -> None:
        if self.placement is not None:
            self.placement.path += step

    def flip(self) -> None:
        """The twin is now the tracked estimate."""
        self.odds, self.message_odds, self.placement_odds = -self.odds, -self.message_odds, -self.placement_odds

    @staticmethod
    def stayed(estimate: np.ndarray, lost_from: np.ndarray, distance: float, rotation: float) -> str | None:
        """Found again at ``estimate`` after losing track at ``lost_from`` (moved by odometry since): "same"
        or "twin" for the one within ``distance`` mm and ``rotation`` rad of that place (the robot slipped
        or fell, it was not carried), None if neither is (carried elsewhere)."""
        both = {"same": estimate, "twin": twin(estimate)}
        name = min(both, key=lambda n: float(pose_distance(both[n][None, :], lost_from)[0]))
        pose = both[name]
        turned = abs(math.remainder(float(pose[2] - lost_from[2]), math.tau))
        return name if math.hypot(pose[0] - lost_from[0], pose[1] - lost_from[1]) <= distance and turned <= rotation else None

    def placement_evidence(self, estimate: np.ndarray, odometry: tuple[float, float, float], cap: float) -> float:
        """Log-likelihood ratio (estimate over twin) of the rules' placement in the own half: each twin
        traced back by the odometry to where it was placed; beyond the halfway line costs up to ``cap``."""
        if self.placement is None:
            return 0.0
        motion = relative(self.placement.odometry, odometry)
        std = 300.0 + 0.1 * self.placement.path  # odometry drifts by about a tenth of the way walked

        def fit(pose: np.ndarray) -> float:
            beyond = max(0.0, float(back(pose, motion)[0]))
            return -min(0.5 * (beyond / std) ** 2, cap)

        return fit(estimate) - fit(twin(estimate))

    def team_ball_evidence(self, estimate: np.ndarray, seen: tuple[float, float], team: tuple[float, float], std: float) -> float:
        """Log-likelihood ratio (estimate over twin) of a ball seen at ``seen`` (robot frame) when the team
        says it lies at ``team`` (field): from the twin the ball is at the point mirrored about the centre."""
        x, y = Pose2D(*estimate).to_global(*seen)
        return robust(math.hypot(x - team[0], y - team[1]) / std) - robust(math.hypot(-x - team[0], -y - team[1]) / std)

    def add_placement(self, estimate: np.ndarray, odometry: tuple[float, float, float], most: float, step: float, cap: float) -> None:
        """The placement's evidence, once: it is the same fact every frame, so the belief takes from it no
        more than it says at its clearest (a walk that blurs it later takes nothing back), ``step`` a frame."""
        says = self.placement_evidence(estimate, odometry, most)
        if says * self.placement_odds < 0.0 or abs(says) > abs(self.placement_odds):
            change = max(-step, min(step, says - self.placement_odds))
            self.add(change, cap)
            self.placement_odds += change

    def add(self, evidence: float, cap: float) -> None:
        self.odds = max(-cap, min(cap, self.odds + evidence))

    def add_team_ball(self, estimate: np.ndarray, seen: tuple[float, float], team: TeamBall, std: float, rate: float,
                      message_cap: float, cap: float) -> None:
        """``rate`` of the team ball's evidence this frame, at most ``message_cap`` from one message in all:
        the frames between two messages see the same ball, and one message alone must not turn a
        confident side."""
        if team.message != self.message:
            self.message, self.message_odds = team.message, 0.0
        said = rate * self.team_ball_evidence(estimate, seen, (team.x, team.y), std)
        given = max(-message_cap, min(message_cap, self.message_odds + said))
        self.add(given - self.message_odds, cap)
        self.message_odds = given
