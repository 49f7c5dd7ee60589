"""SelfLocator: where the robot is on the field, by a particle filter over (x, y, rotation). The particle cloud's maths
(motion noise, resampling, the mean pose) is ``particle_filter``, what the percepts say of poses ``pose_measurements``."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from tafel.core import Module, bounded, provides, requires, uses
from tafel.debug import Canvas, DebugRequest, Plot
from tafel.modules.modeling.field_model import FIELD_MODEL, OWN_HALF
from tafel.modules.modeling.mirror_hypotheses import SideBelief, fold, pose_distance, twin
from tafel.modules.modeling.particle_filter import mean_pose, moved, near, on_field_prior, resampled, spread_round, walk
from tafel.modules.modeling.pose_measurements import (
    ball_against_team,
    contradictions,
    evidence_seen,
    log_likelihoods,
    team_ball_off,
    usable_percepts,
)
from tafel.representations.game import GameState
from tafel.representations.geometry import Pose2D
from tafel.representations.infrastructure import FrameInfo
from tafel.representations.modeling import KnownPose, RobotPose
from tafel.representations.motion_control import FallState, Odometry
from tafel.representations.perception import BallPercept, GoalPostPercept, LinePercept
from tafel.representations.team import TeamMates


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
    - When a penalty ends, the referee has carried the robot to a touchline of its own half (the rules:
      0.5 m outside it, level with the penalty mark): the particles start anew by those touchlines, facing
      the field.
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
        walk(self.particles, forward, left, turn, p, self.rng)

    def start_at(self, pose: KnownPose) -> None:
        """Every particle at a pose the robot was told, a little spread; trusted and valid at once."""
        told = np.array([pose.x, pose.y, pose.rotation])
        self.particles = spread_round(told, len(self.particles), self.rng)
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
        log_weight, measurements = log_likelihoods(self.particles, self.line_percept, self.goal_post_percept, p)
        if measurements == 0:
            return None
        fit = float(np.mean(np.exp(log_weight / measurements)))
        log_weight += on_field_prior(self.particles, p.outside_std)
        weights = np.exp(log_weight - log_weight.max())
        weights /= weights.sum()
        best = self.particles[int(np.argmax(weights))]
        self.particles = resampled(self.particles, weights, p, self.rng)
        reference = self.reference()
        self.particles = fold(self.particles, reference)  # both twins' particles in one cloud
        self.best = fold(best[None, :], reference)[0]
        return fit

    def reference(self) -> np.ndarray:
        """The pose the particles are folded towards: the estimate, or before one the own half's middle."""
        return self.estimate if self.estimate is not None else np.array(OWN_HALF)

    def reset_if_lost(self, fit: float) -> None:
        """Make part of the particles anew from the percepts while lost, or while the pose is not valid."""
        p = self.parameters
        self.slow += p.alpha_slow * (fit - self.slow) if self.slow else fit
        self.fast += p.alpha_fast * (fit - self.fast) if self.fast else fit
        self.fit.add(fit)
        lost = self.fast < p.lost_ratio * self.slow
        if not lost and not usable_percepts(self.line_percept, self.goal_post_percept):
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
        points (``pose_measurements.WATCH_LINES_OFF``) lie that far off every line, or the ball seen lies that far
        from the team's ball and from its mirror image (``contradictions``): the robot may have been carried where
        the particles still half fit. A frame that sees none of them leaves the count; one in which all agree
        starts it anew."""
        if self.estimate is None:
            return
        seen = ball_against_team(self.ball_percept, self.team_mates, self.parameters)
        ball_off = team_ball_off(Pose2D(*self.estimate), self.ball_percept, seen)
        verdicts = contradictions(self.estimate, self.line_percept, self.goal_post_percept, ball_off, self.parameters)
        if verdicts:
            self.contradicted = self.contradicted + 1 if any(verdicts) else 0

    # ---------------------------------------------------------------------------------- estimate
    def publish(self) -> None:
        p, pose = self.parameters, self.robot_pose
        # around the last estimate moved on, or around this frame's best particle if more particles are
        # there: one frame's best can be a lone particle when little was seen, but after a kidnap the new
        # place gathers the particles
        centres = [c for c in (self.estimate, self.best) if c is not None] or [self.particles.mean(axis=0)]
        around = max((near(self.particles, c) for c in centres), key=np.count_nonzero)
        cluster = self.particles[around] if around.sum() >= 3 else self.particles
        previous = self.estimate
        pose.x, pose.y, pose.rotation, pose.deviation, pose.rotation_deviation = mean_pose(cluster)
        self.estimate = np.array([pose.x, pose.y, pose.rotation])
        lost = bool(self.slow and self.fast < p.lost_ratio * self.slow)
        now = self.frame_info.time_s
        gathered = self.concentrated_since is not None
        keep = p.keep_share if gathered else 1.0  # gathered once, a frame that saw little does not undo it
        jumped = previous is not None and float(pose_distance(self.estimate[None, :], previous)[0]) > p.jump
        if jumped or not (around.mean() >= p.valid_share * keep and pose.deviation <= p.valid_deviation / keep and not lost):
            self.concentrated_since, self.evidence = None, set()
        elif self.concentrated_since is None:
            self.concentrated_since = now
        if self.concentrated_since is not None:
            self.decide_side(pose)
            self.evidence |= evidence_seen(self.line_percept, self.goal_post_percept, pose.rotation)
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
        seen = ball_against_team(self.ball_percept, self.team_mates, p)
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

