"""KalmanBallModeler: position and velocity of the ball from noisy percepts."""

from __future__ import annotations

import math
from dataclasses import dataclass

from tafel.core import Module, provides, requires, uses
from tafel.debug import ModifyParameters
from tafel.representations.geometry import Pose2D
from tafel.representations.infrastructure import FrameInfo
from tafel.representations.modeling import BallModel, RobotPose
from tafel.representations.motion_control import Odometry
from tafel.representations.perception import BallPercept

#: the filter's parameters tried live (modify values KalmanBallModeler:NAME)
TUNED = ("acceleration_noise", "measurement_std", "measurement_std_per_m", "friction", "restart_gate", "forget_after")


@dataclass
class AxisFilter:
    """A constant-velocity Kalman filter along one axis: position p (mm), velocity v (mm/s) and their
    covariance. The ball model is separable (same motion and noise along x and y, no coupling), so two
    of these are exactly one 4-state filter, at a fraction of the cost."""

    p: float
    v: float
    pp: float  # var(p)
    pv: float  # cov(p, v)
    vv: float  # var(v)

    def predict(self, dt: float, decay: float, q: float) -> None:
        """x' = F x with F = [[1, dt], [0, decay]]; P' = F P F^T + Q (white-noise acceleration)."""
        pp, pv, vv = self.pp, self.pv, self.vv
        self.p += dt * self.v
        self.v *= decay
        self.pp = pp + 2 * dt * pv + dt * dt * vv + q * dt**4 / 4
        self.pv = decay * (pv + dt * vv) + q * dt**3 / 2
        self.vv = decay * decay * vv + q * dt * dt

    def moved(self, p: float, v: float, pp: float, vv: float) -> None:
        """Take a new position and velocity (and their variances) after the frame turned under them."""
        self.p, self.v, self.pp, self.vv = p, v, pp, vv

    def innovation(self, measured: float, r: float) -> tuple[float, float]:
        """(measured - predicted position, its variance)."""
        return measured - self.p, self.pp + r

    def update(self, residual: float, s: float) -> None:
        gain_p, gain_v = self.pp / s, self.pv / s
        self.p += gain_p * residual
        self.v += gain_v * residual
        pp, pv, vv = self.pp, self.pv, self.vv
        self.pp = (1 - gain_p) * pp
        self.pv = (1 - gain_p) * pv
        self.vv = vv - gain_v * pv


@requires(BallPercept, FrameInfo)
@uses(Odometry, RobotPose)
@provides(BallModel)
class KalmanBallModeler(Module):
    """A constant-velocity Kalman filter with rolling friction over the state (x, y, vx, vy), in the
    robot frame.

    - The robot's own motion (``Odometry`` since the last frame) moves the ball the other way, so the
      model stays right while the robot walks and turns without seeing it.
    - Measurement noise grows with distance, because the ground position of a far ball is less certain.
    - A percept far outside the predicted uncertainty is an outlier and ignored; only several in a row
      that agree with each other (the ball was really moved) restart the filter there.
    - While the robot's pose is lost (``RobotPose.lost``: it may have been carried, which odometry does
      not see) an unseen ball is forgotten sooner, so the robot turns to look for it.
    """

    ball_percept: BallPercept
    frame_info: FrameInfo
    odometry: Odometry
    robot_pose: RobotPose
    ball_model: BallModel

    tuning = ModifyParameters(TUNED, "tried live: modify:set KalmanBallModeler:NAME")

    @dataclass
    class Parameters:
        acceleration_noise: float = 1500.0
        """mm/s^2, standard deviation of unmodelled acceleration"""
        measurement_std: float = 30.0
        """mm, position noise of a percept at the robot"""
        measurement_std_per_m: float = 60.0
        """mm of additional noise per metre of distance"""
        friction: float = 0.5
        """1/s, exponential decay rate of the ball's velocity"""
        initial_velocity_std: float = 500.0
        """mm/s, uncertainty of the velocity when the ball is first seen"""
        restart_gate: float = 40.0
        """squared Mahalanobis distance above which a percept is an outlier"""
        restart_after: int = 3
        """outliers in a row, each within ``outlier_agreement`` of the last, that restart the filter"""
        outlier_agreement: float = 400.0
        """mm"""
        forget_after: float = 3.0
        """s without a percept after which the model is no longer valid"""
        forget_after_lost: float = 1.0
        """s without a percept after which the model is no longer valid while the robot's pose is lost"""
        nominal_dt: float = 1.0 / 30.0
        """s, step used when the frame clock does not advance"""

    parameters: Parameters

    def __init__(self) -> None:
        self.axes: tuple[AxisFilter, AxisFilter] | None = None
        self.last_time_ns: int | None = None
        self.last_seen_ns: int | None = None
        self.last_odometry: tuple[float, float, float] | None = None
        self.outliers: list[tuple[float, float]] = []  # recent outliers in a row, in this frame's coordinates
        self.tuned = self.parameters  # this frame's parameters, with the modify values pinned by a debug client

    def execute(self) -> None:
        self.tuned = p = self.tuning.apply(self.parameters)
        now_ns = self.frame_info.time_ns
        dt = p.nominal_dt
        if self.last_time_ns is not None and now_ns > self.last_time_ns:
            dt = (now_ns - self.last_time_ns) * 1e-9
        self.last_time_ns = now_ns
        self.follow_robot()
        if self.axes is not None:
            decay, q = math.exp(-p.friction * dt), p.acceleration_noise**2
            for axis in self.axes:
                axis.predict(dt, decay, q)
        percept = self.ball_percept
        if percept.seen:
            self.update(percept.x, percept.y)
            self.last_seen_ns = now_ns
        self.publish(now_ns, percept.seen)

    def follow_robot(self) -> None:
        """Move the model by the inverse of the robot's motion since the last frame."""
        odometry = self.odometry
        now = (odometry.x, odometry.y, odometry.rotation)
        previous, self.last_odometry = self.last_odometry, now
        if previous is None or self.axes is None:
            return
        forward, left, turn = Pose2D(*now).relative_to(Pose2D(*previous))
        c, s = math.cos(turn), math.sin(turn)
        ax, ay = self.axes
        x, y = ax.p - forward, ay.p - left
        # the axes turn by -turn; their variances mix (the filter keeps no x-y covariance: per frame the
        # turn is small and the two variances nearly equal, so little is lost)
        new_x = (c * x + s * y, c * ax.v + s * ay.v, c * c * ax.pp + s * s * ay.pp, c * c * ax.vv + s * s * ay.vv)
        new_y = (-s * x + c * y, -s * ax.v + c * ay.v, s * s * ax.pp + c * c * ay.pp, s * s * ax.vv + c * c * ay.vv)
        ax.moved(*new_x)
        ay.moved(*new_y)
        self.outliers = [(c * ox + s * oy - forward, -s * ox + c * oy - left) for ox, oy in self.outliers]

    def update(self, x: float, y: float) -> None:
        p = self.tuned
        std = p.measurement_std + p.measurement_std_per_m * math.hypot(x, y) / 1000.0
        r = std * std
        if self.axes is not None:
            innovations = [axis.innovation(measured, r) for axis, measured in zip(self.axes, (x, y))]
            distance = sum(residual * residual / s for residual, s in innovations)
            if distance <= p.restart_gate:
                self.outliers = []
                for axis, (residual, s) in zip(self.axes, innovations):
                    axis.update(residual, s)
                return
            if self.outliers and math.dist(self.outliers[-1], (x, y)) > p.outlier_agreement:
                self.outliers = []
            self.outliers.append((x, y))
            if len(self.outliers) < p.restart_after:
                return  # a single wrong percept (a false detection, a wrong camera matrix) changes nothing
        self.outliers = []
        v = p.initial_velocity_std**2
        self.axes = (AxisFilter(x, 0.0, r, 0.0, v), AxisFilter(y, 0.0, r, 0.0, v))

    def publish(self, now_ns: int, seen: bool) -> None:
        model = self.ball_model
        model.seen = seen
        if self.axes is None or self.last_seen_ns is None:
            model.valid = False
            return
        ax, ay = self.axes
        model.x, model.y, model.vx, model.vy = ax.p, ay.p, ax.v, ay.v
        model.position_std = math.sqrt(max(0.0, (ax.pp + ay.pp) / 2))
        model.time_since_seen = max(0.0, (now_ns - self.last_seen_ns) * 1e-9)
        forget = self.tuned.forget_after_lost if self.robot_pose.lost else self.tuned.forget_after
        model.valid = model.time_since_seen <= forget
