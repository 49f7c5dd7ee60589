"""SelfLocator: where the robot is on the field, by a particle filter over (x, y, rotation)."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from tafel.core import Module, bounded, provides, requires, uses
from tafel.debug import Canvas, DebugRequest, Plot
from tafel.modules.modeling.field_model import FIELD_MODEL, OWN_HALF
from tafel.modules.modeling.mirror_hypotheses import SideBelief, fold, pose_distance, twin
from tafel.representations import field
from tafel.representations.game import GameState
from tafel.representations.geometry import Pose2D
from tafel.representations.infrastructure import FrameInfo
from tafel.representations.modeling import KnownPose, RobotPose
from tafel.representations.motion_control import FallState, Odometry
from tafel.representations.perception import BallPercept, GoalPostPercept, LinePercept
from tafel.representations.team import TeamBall, TeamMates

KNOWN_POSE_STD, KNOWN_ROTATION_STD = 30.0, 0.03  # mm and rad: the particles' spread round a pose told (KnownPose)
WATCH_MIN_POINTS = 10  # line points a frame needs to say whether the lines fit the estimate ...
WATCH_LINES_OFF = 0.2  # ... the share of them beyond 2.5 standard deviations that contradicts it (a robot carried where
WATCH_LINES_ON = 0.1  # the old pose half fits: about a quarter), and the share at most that agrees (an accurate pose: 0)


def seen_from(poses: np.ndarray, points: np.ndarray) -> np.ndarray:
    """Robot-frame points (M x 2, mm) as seen from each of the field poses (N x 3: mm, mm, rad): N x M x 2
    field positions (mm)."""
    x, y, heading = (poses[:, i : i + 1] for i in range(3))
    c, s = np.cos(heading), np.sin(heading)
    return np.stack([x + c * points[:, 0] - s * points[:, 1], y + s * points[:, 0] + c * points[:, 1]], axis=-1)


@requires(Odometry, LinePercept, GoalPostPercept, FrameInfo)
@uses(FallState, GameState, KnownPose, BallPercept, TeamMates)
@provides(RobotPose)
class SelfLocator(Module):
    """Monte Carlo localization.

    - Motion: each particle moves by the odometry since the last frame, with noise that grows with
      the motion (and much more rotation noise after a fall).
    - Sensing: line points are weighed by their distance to the nearest painted line (a precomputed
      distance map), goal posts by their distance to the nearest post, the centre circle's centre by
      its distance to the centre spot. Noise grows with the distance of what was seen. Poses beyond
      the field's lines are unlikely (the referee takes such robots off), beyond the carpet more so.
    - The field looks the same turned by 180 degrees. The particles track one of two twins (each is
      folded onto the side nearer the estimate) and the other is kept apart as the mirror hypothesis;
      ``SideBelief`` decides between them: the rules' placement in the own half (at the start, after a
      penalty) traced back by odometry, the team's ball against the ball seen, and the history (the
      belief carries on while tracked, and a confident one turns only on much evidence). The pose is
      valid only once the side is decided; a robot carried elsewhere by nobody the rules name starts
      undecided, and says so (``valid`` false) rather than guess the twin.
    - Lost: when the measurements keep fitting much worse than they used to (the robot was carried
      or slipped), part of the particles are made anew from what is seen (sensor resetting): around
      a seen post at its measured distance, on the centre circle's position, or on a field line.
      ``RobotPose.lost`` says so.
    - When a penalty ends, the referee has carried the robot to a touchline of its own half: the
      particles start anew there, facing the field.
    - Told where it is (``KnownPose``, the simulator's ``sim:move_robot ... -reset on``): every particle
      starts there and the pose is valid at once. That is the only way out of the symmetric field's
      ambiguity for a robot carried into the other half, which the rules above put in its own half.
    """

    odometry: Odometry
    line_percept: LinePercept
    goal_post_percept: GoalPostPercept
    frame_info: FrameInfo
    fall_state: FallState
    game_state: GameState
    known_pose: KnownPose
    ball_percept: BallPercept
    team_mates: TeamMates
    robot_pose: RobotPose

    draw_particles = DebugRequest("every particle and the estimate on the field canvas")
    fit = Plot("how well the percepts fit the particles, a frame's mean weight")
    side_odds = Plot("log odds that the pose is the right one of the mirrored twins")

    @dataclass
    class Parameters:
        particles: int = bounded(20, 5000, 400)
        translation_noise: float = bounded(0.0, 1.0, 0.15)
        """share of the odometry's translation"""
        rotation_noise: float = bounded(0.0, 1.0, 0.15)
        """share of the odometry's rotation, plus a little per mm walked"""
        fallen_rotation_noise: float = bounded(0.0, 3.0, 0.6)
        """rad of rotation noise added when the robot has fallen"""
        point_std: float = bounded(10.0, 1000.0, 80.0)
        """mm: noise of a line point at the robot (grows by ``point_std_per_m``)"""
        point_std_per_m: float = bounded(0.0, 500.0, 50.0)
        """mm per metre of distance added to ``point_std``"""
        max_points: int = bounded(5, 500, 40)
        point_weight: float = bounded(0.01, 1.0, 0.12)
        """line points are not independent: each counts this much of a full measurement"""
        post_std: float = bounded(10.0, 2000.0, 150.0)
        post_std_per_m: float = bounded(0.0, 500.0, 60.0)
        circle_std: float = bounded(10.0, 2000.0, 200.0)
        alpha_slow: float = bounded(0.0, 1.0, 0.02)
        alpha_fast: float = bounded(0.0, 1.0, 0.25)
        """averaging rates of the measurement fit: a fast average far below the slow one means lost"""
        lost_ratio: float = bounded(0.0, 1.0, 0.45)
        reset_share: float = bounded(0.0, 1.0, 0.25)
        """share of the particles made anew per frame while lost"""
        side_decided: float = bounded(0.5, 20.0, 3.0)
        """log-odds of one twin over the other needed for a valid pose (3: about 95 %)"""
        side_cap: float = bounded(1.0, 50.0, 10.0)
        """largest log-odds the side belief holds: what evidence for the twin must overcome"""
        placement_cap: float = bounded(0.0, 50.0, 6.0)
        """log-odds against a twin that puts the robot's placement well beyond the halfway line (counted
        once, not every frame; ``placement_rate`` of it a frame)"""
        placement_rate: float = bounded(0.0, 1.0, 0.2)
        """share of ``placement_cap`` counted at most in one frame"""
        team_ball_std: float = bounded(10.0, 5000.0, 300.0)
        """mm: the team's ball against the ball seen (grows with distance and age, below)"""
        team_ball_std_per_m: float = bounded(0.0, 1000.0, 100.0)
        """mm per metre of the seen ball's distance added to ``team_ball_std``"""
        team_ball_std_per_s: float = bounded(0.0, 5000.0, 300.0)
        """mm per second of the team ball's age added to ``team_ball_std``"""
        team_ball_max_age: float = bounded(0.0, 30.0, 3.0)
        """s: older team balls are not used"""
        team_ball_rate: float = bounded(0.0, 1.0, 0.12)
        """share of the team ball's log-likelihood ratio counted per frame (frames see the same ball)"""
        team_message_cap: float = bounded(0.0, 50.0, 4.0)
        """log-odds one teammate's message adds at most: a confident side turns only
        on several messages that keep saying so"""
        continuity_distance: float = bounded(0.0, 5000.0, 1000.0)
        """mm: relocalized this near where it was lost (and within ``continuity_rotation``, unless it
        fell), the robot was not carried: the side belief carries on"""
        continuity_rotation: float = bounded(0.0, 3.2, 0.6)
        """rad: relocalized this near the rotation where it was lost (with ``continuity_distance``), the side belief carries on"""
        search_share: float = bounded(0.0, 1.0, 0.05)
        """share of the particles made anew per frame while the pose is not valid"""
        watch_share: float = bounded(0.0, 1.0, 0.1)
        """share of the particles made anew per frame while the pose is valid (mixture MCL), once the circle, a post or many line points have contradicted the
        estimate (beyond 2.5 standard deviations) in ``watch_after`` frames in a row: poses that explain this frame's percepts
        compete with the estimate, so a robot carried elsewhere is noticed (its new place grows among them)
        even where the other percepts still half fit the old one. Only from a seen post, circle or line, never
        anywhere. Not while nothing contradicts: at 0.02 in every frame an accurate pose (50 mm) lost its
        validity for 3 s in a default run (seeds 0 and 1, at 6.7 s)"""
        watch_after: int = bounded(1, 1000, 5)
        """frames in a row whose circle, posts or lines contradict the estimate before the watch starts (frames
        that see none of them count neither way, one that agrees starts the count anew)"""
        jump: float = bounded(0.0, 5000.0, 500.0)
        """mm (a radian counting 1000 mm): the estimate moved this far from the last one (moved by
        odometry) in a frame, the particles found another place: the pose is confirmed anew"""
        keep_share: float = bounded(0.0, 1.0, 0.7)
        """once gathered, the particles count as gathered while this share of ``valid_share`` stays near
        the estimate (and its spread within 1 / ``keep_share`` of ``valid_deviation``): a frame that saw
        little does not undo the confirmation"""
        outside_std: float = bounded(10.0, 5000.0, 300.0)
        """mm beyond the field's lines at which a pose is one standard deviation unlikely"""
        valid_deviation: float = bounded(10.0, 5000.0, 350.0)
        """mm: the pose is valid while the particles around the estimate are this close together (with ``valid_share`` and ``confirm_after``)"""
        valid_share: float = bounded(0.1, 1.0, 0.7)
        """share of all particles that must lie around the estimate for a valid pose"""
        confirm_after: float = bounded(0.0, 10.0, 1.0)
        """s the particles must stay gathered before the pose is valid, in which the circle, a post, or lines both along and across the
        field were seen (one straight line fits many places on the field)"""
        roughening: float = bounded(0.0, 200.0, 15.0)
        """mm of noise added to resampled particles, against their collapse onto a few"""
        roughening_rotation: float = bounded(0.0, 1.0, 0.15)
        """rad of noise added to resampled particles' rotation"""

    parameters: Parameters

    def __init__(self) -> None:
        self.rng = np.random.default_rng(0)  # fixed: replaying a log localizes the same way
        self.particles = np.zeros((0, 3))
        self.last_odometry: tuple[float, float, float] | None = None
        self.slow = self.fast = 0.0
        self.trusted: tuple[float, float, float] | None = None  # the last valid estimate, for continuity
        self.was_upright = True
        self.best: np.ndarray | None = None  # this frame's best-weighted particle, None if nothing was seen
        self.estimate: np.ndarray | None = None  # the last published pose, moved by odometry since
        self.concentrated_since: float | None = None  # s since when the particles agree on one pose
        self.evidence: set[str] = set()  # what was seen since: one line alone fits many places
        self.was_penalized = False
        self.known_serial = 0  # the last KnownPose taken
        self.side = SideBelief()
        self.anchor: np.ndarray | None = None  # the estimate the side belief is about, moved by odometry: carried since?
        self.fell_at = -math.inf  # s of the last fall: after one the heading may be anything, the place not
        self.contradicted = 0  # frames in a row whose circle or posts disagreed with the estimate

    def execute(self) -> None:
        odometry = (self.odometry.x, self.odometry.y, self.odometry.rotation)
        if len(self.particles) != self.parameters.particles:
            self.particles = FIELD_MODEL.own_half(self.rng, self.parameters.particles)
            self.side.place(odometry)  # the robot enters the field in its own half
        penalized = self.game_state.penalized
        if self.was_penalized and not penalized:
            self.particles = FIELD_MODEL.penalty_return(self.rng, self.parameters.particles)
            self.trusted = self.estimate = self.concentrated_since = self.anchor = None
            self.side.place(odometry)  # the referee put it on a touchline of its own half
        self.was_penalized = penalized
        self.predict()
        if self.known_pose.serial != self.known_serial:
            self.known_serial = self.known_pose.serial
            self.start_at(self.known_pose)
        upright = self.fall_state.upright
        if upright and self.was_upright:  # percepts of a lying robot come through a wrong camera matrix
            self.count_contradictions()
            fits = self.weigh()
            if fits is not None:
                self.reset_if_lost(fits)
        self.was_upright = upright
        self.publish()

    # ------------------------------------------------------------------------------------ motion
    def predict(self) -> None:
        p, odometry = self.parameters, self.odometry
        now = (odometry.x, odometry.y, odometry.rotation)
        previous, self.last_odometry = self.last_odometry, now
        if not self.fall_state.upright and self.was_upright:
            self.particles[:, 2] += self.rng.normal(0.0, p.fallen_rotation_noise, len(self.particles))
            self.fell_at = self.frame_info.time_s
        self.best = None
        if previous is None:
            return
        forward, left, turn = Pose2D(*now).relative_to(Pose2D(*previous))  # the step in the previous robot frame
        if self.estimate is not None:
            self.estimate = moved(self.estimate, forward, left, turn)
        if self.anchor is not None:
            self.anchor = moved(self.anchor, forward, left, turn)
        self.side.walked(math.hypot(forward, left))
        n = len(self.particles)
        step = math.hypot(forward, left)
        forwards = forward + self.rng.normal(0.0, p.translation_noise * step + 1.0, n)  # each particle's step
        lefts = left + self.rng.normal(0.0, p.translation_noise * step + 1.0, n)
        turns = turn + self.rng.normal(0.0, p.rotation_noise * abs(turn) + 0.0002 * step + 0.002, n)
        heading = self.particles[:, 2]
        self.particles[:, 0] += np.cos(heading) * forwards - np.sin(heading) * lefts
        self.particles[:, 1] += np.sin(heading) * forwards + np.cos(heading) * lefts
        self.particles[:, 2] = np.remainder(heading + turns + math.pi, math.tau) - math.pi

    def start_at(self, pose: KnownPose) -> None:
        """Every particle at a pose the robot was told, a little spread; trusted and valid at once."""
        n = len(self.particles)
        told = np.array([pose.x, pose.y, pose.rotation])
        self.particles = told + self.rng.normal(0.0, [KNOWN_POSE_STD, KNOWN_POSE_STD, KNOWN_ROTATION_STD], (n, 3))
        self.particles[:, 2] = np.remainder(self.particles[:, 2] + math.pi, math.tau) - math.pi
        self.trusted, self.estimate, self.best = (pose.x, pose.y, pose.rotation), told, None
        self.slow = self.fast = 0.0  # the measurements' fit is learnt anew at this place
        self.concentrated_since, self.evidence = self.frame_info.time_s - self.parameters.confirm_after, {"told"}
        self.side.told(self.parameters.side_cap)
        self.anchor = told.copy()

    # ----------------------------------------------------------------------------------- sensing
    def weigh(self) -> float | None:
        """Weigh and resample the particles by this frame's percepts; the mean fit per measurement
        (0..1), or None if nothing was seen."""
        p = self.parameters
        log_weight = np.zeros(len(self.particles))
        measurements = 0.0
        points = self.line_points()
        if len(points):
            if len(points) > p.max_points:
                points = points[np.linspace(0, len(points) - 1, p.max_points).astype(int)]
            std = self.point_std(points)
            distance = FIELD_MODEL.line_distance_seen(self.particles, points)  # line_distance(self.to_field(points))'s
            log_weight += p.point_weight * robust(distance / std).sum(axis=1)
            measurements += p.point_weight * len(points)
        posts = [(post.x, post.y) for post in self.goal_post_percept.posts if math.isfinite(post.x) and math.isfinite(post.y)]
        if posts:  # every post from every particle at once; each post's term added in turn, as one by one
            seen = np.array(posts)
            distances = FIELD_MODEL.post_distance(self.to_field(seen).reshape(-1, 2)).reshape(len(self.particles), len(posts))
            for k, (x, y) in enumerate(posts):
                log_weight += robust(distances[:, k] / self.post_std(x, y))
            measurements += len(posts)
        if self.line_percept.circle_seen and math.isfinite(self.line_percept.circle_x) and math.isfinite(self.line_percept.circle_y):
            centre = self.to_field(np.array([[self.line_percept.circle_x, self.line_percept.circle_y]]))[:, 0]
            log_weight += robust(np.linalg.norm(centre, axis=1) / p.circle_std)
            measurements += 1
        if measurements == 0:
            return None
        fit = float(np.mean(np.exp(log_weight / measurements)))
        log_weight += self.on_field_prior()
        weights = np.exp(log_weight - log_weight.max())
        weights /= weights.sum()
        best = self.particles[int(np.argmax(weights))]
        if 1.0 / np.sum(weights**2) < 0.5 * len(weights):
            self.particles = self.particles[low_variance_indices(weights, self.rng)]
            n = len(self.particles)
            self.particles[:, :2] += self.rng.normal(0.0, p.roughening, (n, 2))
            self.particles[:, 2] += self.rng.normal(0.0, p.roughening_rotation, n)
        reference = self.reference()
        self.particles = fold(self.particles, reference)  # both twins' particles in one cloud
        self.best = fold(best[None, :], reference)[0]
        return fit

    def reference(self) -> np.ndarray:
        """The pose the particles are folded towards: the estimate, or before one the own half's middle."""
        return self.estimate if self.estimate is not None else np.array(OWN_HALF)

    def on_field_prior(self) -> np.ndarray:
        """Log-prior of each particle's place: a robot far beyond the lines is taken off by the referee, and
        one beyond the carpet stands in the wall; so poses out there need much more evidence."""
        outside = np.maximum(np.abs(self.particles[:, 0]) - field.LENGTH / 2, 0.0) + np.maximum(np.abs(self.particles[:, 1]) - field.WIDTH / 2, 0.0)
        return -0.5 * (outside / self.parameters.outside_std) ** 2

    def to_field(self, points: np.ndarray) -> np.ndarray:
        """Robot-frame points (M x 2) as seen from every particle: (N x M x 2) field positions."""
        return seen_from(self.particles, points)

    def line_points(self) -> np.ndarray:
        """This frame's line points (M x 2, robot mm), without the ones no camera sees (not finite, over 20 m)."""
        points = np.asarray(self.line_percept.points, dtype=float).reshape(-1, 2)
        return points[np.isfinite(points).all(axis=1) & (np.abs(points) < 20000.0).all(axis=1)]

    def point_std(self, points: np.ndarray) -> np.ndarray:
        """mm: each line point's noise, growing with its distance."""
        return self.parameters.point_std + self.parameters.point_std_per_m * np.linalg.norm(points, axis=1) / 1000.0

    def post_std(self, x: float, y: float) -> float:
        """mm: a goal post's noise at (x, y) (robot mm), growing with its distance."""
        return self.parameters.post_std + self.parameters.post_std_per_m * math.hypot(x, y) / 1000.0

    def reset_if_lost(self, fit: float) -> None:
        """Make part of the particles anew from the percepts while lost, or while the pose is not valid."""
        p = self.parameters
        self.slow += p.alpha_slow * (fit - self.slow) if self.slow else fit
        self.fast += p.alpha_fast * (fit - self.fast) if self.fast else fit
        self.fit.add(fit)
        lost = self.fast < p.lost_ratio * self.slow
        if not lost and not self.usable_percepts():
            return  # guesses anywhere only while lost: elsewhere they spread a gathered cloud in frames that saw little
        # a few fresh particles a frame keep every pose that fits what is seen alive, and while the pose is
        # valid they watch for a carried robot: where they keep fitting better, they win the resampling
        watching = self.contradicted >= p.watch_after
        share = p.reset_share if lost else p.search_share if not self.robot_pose.valid else p.watch_share if watching else 0.0
        count = int(share * len(self.particles))
        fresh = FIELD_MODEL.poses_from_percepts(self.rng, count, self.line_percept, self.goal_post_percept)
        fresh = fold(fresh, self.reference())
        self.particles[self.rng.choice(len(self.particles), len(fresh), replace=False)] = fresh

    def count_contradictions(self) -> None:
        """Count the frames in a row in which the centre circle or a goal post, seen from the estimate (moved by
        odometry), lies beyond 2.5 standard deviations of the circle's or the nearest post's place, many line
        points (``WATCH_LINES_OFF``) lie that far off every line, or the ball seen lies that far from the team's
        ball and from its mirror image: the robot may have been carried where the particles still half fit. A
        frame that sees none of them leaves the count; one in which all agree starts it anew."""
        p = self.parameters
        if self.estimate is None:
            return
        pose, verdicts = Pose2D(*self.estimate), []
        lines = self.line_percept
        if lines.circle_seen and math.isfinite(lines.circle_x) and math.isfinite(lines.circle_y):
            verdicts.append(math.hypot(*pose.to_global(lines.circle_x, lines.circle_y)) / p.circle_std >= 2.5)
        for post in self.goal_post_percept.posts:
            if math.isfinite(post.x) and math.isfinite(post.y):
                place = np.array([pose.to_global(post.x, post.y)])
                verdicts.append(float(FIELD_MODEL.post_distance(place)[0]) / self.post_std(post.x, post.y) >= 2.5)
        points = self.line_points()
        if len(points) >= WATCH_MIN_POINTS:
            seen = seen_from(np.array([self.estimate]), points)
            off = float(np.mean(FIELD_MODEL.line_distance(seen)[0] / self.point_std(points) >= 2.5))
            if off >= WATCH_LINES_OFF or off <= WATCH_LINES_ON:  # in between, lines say nothing either way
                verdicts.append(off >= WATCH_LINES_OFF)
        ball_off = self.team_ball_off(pose)
        if ball_off is not None and (ball_off[0] < 2.5 or min(ball_off) >= 2.5):  # near the mirror image: the side belief's matter
            verdicts.append(min(ball_off) >= 2.5)
        if verdicts:
            self.contradicted = self.contradicted + 1 if any(verdicts) else 0

    def team_ball_off(self, pose: Pose2D) -> tuple[float, float] | None:
        """The ball seen this frame, placed on the field from ``pose``, against the team's ball and its mirror image
        (the twin's view): the distances in standard deviations (as the side belief weighs them); None without
        either ball. Far from both, the pose is wrong, not mirrored: a robot carried where the lines it looks at
        (next to the ball) half fit the old place."""
        seen = self.ball_against_team()
        if seen is None:
            return None
        team, std = seen
        x, y = pose.to_global(self.ball_percept.x, self.ball_percept.y)
        return math.hypot(x - team.x, y - team.y) / std, math.hypot(x + team.x, y + team.y) / std

    def ball_against_team(self) -> tuple[TeamBall, float] | None:
        """The team's ball and the standard deviation (mm) of where the ball seen this frame may lie against it
        (its own distance's error and the team ball's age); None without either ball."""
        p, ball = self.parameters, self.ball_percept
        team = self.team_mates.freshest_ball(p.team_ball_max_age)
        if team is None or not (ball.seen and math.isfinite(ball.x) and math.isfinite(ball.y)):
            return None
        return team, p.team_ball_std + p.team_ball_std_per_m * math.hypot(ball.x, ball.y) / 1000.0 + p.team_ball_std_per_s * team.age

    def usable_percepts(self) -> bool:
        """Whether this frame saw something fresh poses can be made from: the circle, a post, a line segment."""
        return bool(self.line_percept.circle_seen or self.goal_post_percept.posts
                    or any(s.length >= 300.0 for s in self.line_percept.segments))

    # ---------------------------------------------------------------------------------- estimate
    def publish(self) -> None:
        p, pose = self.parameters, self.robot_pose
        # around the last estimate moved on, or around this frame's best particle if more particles are
        # there: one frame's best can be a lone particle when little was seen, but after a kidnap the new
        # place gathers the particles
        centres = [c for c in (self.estimate, self.best) if c is not None] or [self.particles.mean(axis=0)]
        near = max((self.near(c) for c in centres), key=np.count_nonzero)
        cluster = self.particles[near] if near.sum() >= 3 else self.particles
        previous = self.estimate
        pose.x, pose.y = float(cluster[:, 0].mean()), float(cluster[:, 1].mean())
        pose.rotation = float(math.atan2(np.sin(cluster[:, 2]).mean(), np.cos(cluster[:, 2]).mean()))
        spread = np.hypot(cluster[:, 0] - pose.x, cluster[:, 1] - pose.y)
        pose.deviation = float(math.sqrt(np.mean(spread**2)))
        self.estimate = np.array([pose.x, pose.y, pose.rotation])
        pose.rotation_deviation = float(math.sqrt(max(0.0, -2.0 * math.log(max(1e-9, math.hypot(np.sin(cluster[:, 2]).mean(), np.cos(cluster[:, 2]).mean()))))))
        lost = bool(self.slow and self.fast < p.lost_ratio * self.slow)
        now = self.frame_info.time_s
        gathered = self.concentrated_since is not None
        keep = p.keep_share if gathered else 1.0  # gathered once, a frame that saw little does not undo it
        jumped = previous is not None and float(pose_distance(self.estimate[None, :], previous)[0]) > p.jump
        if jumped or not (near.mean() >= p.valid_share * keep and pose.deviation <= p.valid_deviation / keep and not lost):
            self.concentrated_since, self.evidence = None, set()
        elif self.concentrated_since is None:
            self.concentrated_since = now
        if self.concentrated_since is not None:
            self.decide_side(pose)
            self.evidence |= self.evidence_seen(pose.rotation)
        pose.valid = (self.concentrated_since is not None and now - self.concentrated_since >= p.confirm_after
                      and bool(self.evidence & {"circle", "post", "told"} or {"along", "across"} <= self.evidence)
                      and self.side.odds >= p.side_decided)
        pose.mirror_probability = 1.0 / (1.0 + math.exp(self.side.odds))
        self.side_odds.add(self.side.odds)
        pose.lost = lost or (self.trusted is not None and not pose.valid)
        if pose.valid:
            self.trusted = (pose.x, pose.y, pose.rotation)
        if self.draw_particles:
            canvas = self.draw_particles.canvas(Canvas.FIELD)
            for x, y, heading in self.particles[:: max(1, len(self.particles) // 100)]:
                canvas.line(x, y, x + 120 * math.cos(heading), y + 120 * math.sin(heading), color="gray")
            canvas.robot_pose(pose.x, pose.y, pose.rotation, color="blue" if pose.valid else "red", width=2)

    def decide_side(self, pose: RobotPose) -> None:
        """With the particles gathered on one pose: was the robot carried there from where they last
        gathered (then the side is open again), or did it slip or fall; what the placement and the
        team's ball say of the twins; turn to the twin when the evidence favours it."""
        p, side = self.parameters, self.side
        if self.estimate is None:  # the caller publishes a pose first
            return
        if self.anchor is not None:
            fell = self.frame_info.time_s - self.fell_at < 10.0
            stayed = side.stayed(self.estimate, self.anchor, p.continuity_distance, math.inf if fell else p.continuity_rotation)
            if stayed is None:
                side.carried(placed_since=self.trusted is None)
                self.anchor = None
            elif stayed == "twin":  # the old place, the particles folded the other way: the belief is about the
                self.turn_to_twin(pose)  # old place (the anchor), which is tracked again; it must not flip
        odometry = (self.odometry.x, self.odometry.y, self.odometry.rotation)
        side.add_placement(self.estimate, odometry, p.placement_cap, p.placement_rate * p.placement_cap, p.side_cap)
        seen = self.ball_against_team()
        if seen is not None:
            side.add_team_ball(self.estimate, (self.ball_percept.x, self.ball_percept.y), seen[0], seen[1], p.team_ball_rate,
                               p.team_message_cap, p.side_cap)
        if side.odds < 0.0:
            self.turn_to_twin(pose)
            side.flip()
            if self.anchor is not None:  # the belief follows the turn, and so does the place it is about
                self.anchor = twin(self.anchor)
        if side.odds >= p.side_decided:  # a decided side is about this estimate from now on
            self.anchor = self.estimate.copy()

    def turn_to_twin(self, pose: RobotPose) -> None:
        """Track the twin: every particle, the estimate and the pose turned about the centre spot."""
        if self.estimate is None:  # only after a pose was published (decide_side)
            return
        self.particles = twin(self.particles)
        self.estimate = twin(self.estimate)
        if self.best is not None:
            self.best = twin(self.best)
        pose.x, pose.y, pose.rotation = float(self.estimate[0]), float(self.estimate[1]), float(self.estimate[2])

    def near(self, centre: np.ndarray) -> np.ndarray:
        """Which particles are within 600 mm and 0.6 rad of ``centre``."""
        return (np.hypot(self.particles[:, 0] - centre[0], self.particles[:, 1] - centre[1]) < 600.0) & (
            np.abs(np.remainder(self.particles[:, 2] - centre[2] + math.pi, math.tau) - math.pi) < 0.6)

    def evidence_seen(self, rotation: float) -> set[str]:
        """What this frame saw that pins a pose down: the circle, a post, lines along or across the field."""
        seen = {"circle"} if self.line_percept.circle_seen else set()
        if self.goal_post_percept.posts:
            seen.add("post")
        for segment in self.line_percept.segments:
            if segment.length >= 300.0:
                angle = abs(math.remainder(math.atan2(segment.y2 - segment.y1, segment.x2 - segment.x1) + rotation, math.pi))
                seen.add("along" if angle < 0.35 else "across" if angle > math.pi / 2 - 0.35 else "slanted")
        return seen


def moved(pose: np.ndarray, forward: float, left: float, turn: float) -> np.ndarray:
    """A field pose (x, y, rotation) after a step given in its own frame."""
    return np.array(tuple(Pose2D(*pose) * Pose2D(forward, left, turn)))


def robust(normalized: np.ndarray) -> np.ndarray:
    """Log-likelihood of normalized errors, Gaussian near zero and flat beyond 2.5 standard deviations,
    so that one wrong percept cannot wipe out the right particles."""
    log = np.minimum(normalized, 2.5)  # -0.5 * min(...) ** 2, in place for arrays: the particles' largest
    if not isinstance(log, np.ndarray):
        return -0.5 * log**2
    np.square(log, out=log)
    log *= -0.5
    return log


def low_variance_indices(weights: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    """Indices of a low-variance (systematic) resampling of normalized ``weights``."""
    n = len(weights)
    positions = (rng.random() + np.arange(n)) / n
    return np.minimum(np.searchsorted(np.cumsum(weights), positions), n - 1)
