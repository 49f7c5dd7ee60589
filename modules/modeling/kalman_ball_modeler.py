"""KalmanBallModeler: position and velocity of the ball from noisy percepts."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from core import Module, provides, requires
from representations.infrastructure import FrameInfo
from representations.modeling import BallModel
from representations.perception import BallPercept

_H = np.array([[1.0, 0.0, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0]])


@requires(BallPercept, FrameInfo)
@provides(BallModel)
class KalmanBallModeler(Module):
    """A constant-velocity Kalman filter with rolling friction over the state (x, y, vx, vy).

    Measurement noise grows with distance, because the ground position of a far ball is less certain.
    A percept far outside the predicted uncertainty (the ball was moved, or the model was wrong)
    restarts the filter at the percept instead of dragging the estimate across the field.
    """

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
        """squared Mahalanobis distance above which a percept restarts the filter"""
        forget_after: float = 3.0
        """s without a percept after which the model is no longer valid"""
        nominal_dt: float = 1.0 / 30.0
        """s, step used when the frame clock does not advance"""

    def __init__(self) -> None:
        self.state: np.ndarray | None = None
        self.covariance = np.zeros((4, 4))
        self.last_time_ns: int | None = None
        self.last_seen_ns: int | None = None

    def execute(self) -> None:
        now_ns = self.frame_info.time_ns
        dt = self.parameters.nominal_dt
        if self.last_time_ns is not None and now_ns > self.last_time_ns:
            dt = (now_ns - self.last_time_ns) * 1e-9
        self.last_time_ns = now_ns
        if self.state is not None:
            self.predict(dt)
        percept = self.ball_percept
        if percept.seen:
            self.update(percept.x, percept.y)
            self.last_seen_ns = now_ns
        self.publish(now_ns, percept.seen)

    def predict(self, dt: float) -> None:
        p = self.parameters
        decay = math.exp(-p.friction * dt)
        transition = np.array([[1, 0, dt, 0], [0, 1, 0, dt], [0, 0, decay, 0], [0, 0, 0, decay]], dtype=float)
        q = p.acceleration_noise**2
        axis = np.array([[dt**4 / 4, dt**3 / 2], [dt**3 / 2, dt**2]]) * q
        noise = np.zeros((4, 4))
        noise[np.ix_([0, 2], [0, 2])] = axis
        noise[np.ix_([1, 3], [1, 3])] = axis
        self.state = transition @ self.state
        self.covariance = transition @ self.covariance @ transition.T + noise

    def update(self, x: float, y: float) -> None:
        p = self.parameters
        std = p.measurement_std + p.measurement_std_per_m * math.hypot(x, y) / 1000.0
        noise = np.eye(2) * std**2
        measurement = np.array([x, y])
        if self.state is not None:
            innovation = measurement - _H @ self.state
            innovation_cov = _H @ self.covariance @ _H.T + noise
            distance = float(innovation @ np.linalg.solve(innovation_cov, innovation))
            if distance <= p.restart_gate:
                gain = self.covariance @ _H.T @ np.linalg.inv(innovation_cov)
                self.state = self.state + gain @ innovation
                self.covariance = (np.eye(4) - gain @ _H) @ self.covariance
                return
        self.state = np.array([x, y, 0.0, 0.0])
        self.covariance = np.diag([std**2, std**2, p.initial_velocity_std**2, p.initial_velocity_std**2])

    def publish(self, now_ns: int, seen: bool) -> None:
        model = self.ball_model
        model.seen = seen
        if self.state is None or self.last_seen_ns is None:
            model.valid = False
            return
        model.x, model.y, model.vx, model.vy = (float(v) for v in self.state)
        model.position_std = math.sqrt(max(0.0, (self.covariance[0, 0] + self.covariance[1, 1]) / 2))
        model.time_since_seen = max(0.0, (now_ns - self.last_seen_ns) * 1e-9)
        model.valid = model.time_since_seen <= self.parameters.forget_after
