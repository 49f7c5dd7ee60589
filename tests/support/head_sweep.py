"""A head that sweeps quickly across the ball, and the error of the ball's ground position meanwhile.

Shared by the camera-latency test and ``benchmarks/camera_latency.py``.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass

import numpy as np

from tafel.core import Module, provides, requires
from tafel.representations.behavior import HeadMotionRequest
from tafel.representations.infrastructure import FrameInfo
from tafel.representations.motion import HEAD_YAW, JointSensorData
from tafel.representations.perception import BallPercept
from tests.support.simulation import PERCEPTION, Simulation

BALL = (1200.0, 0.0)  # mm on the field; the robot stands at the centre facing +x


@requires(FrameInfo)
@provides(HeadMotionRequest)
class HeadSweep(Module):
    """Turns the head from side to side at ``speed`` (rad/s), looking down at ``pitch``."""

    @dataclass
    class Parameters:
        amplitude: float = 0.6
        speed: float = 2.5
        pitch: float = 0.3

    def execute(self) -> None:
        p = self.parameters
        period = 4 * p.amplitude / p.speed
        phase = (self.frame_info.time_s % period) / period
        self.head_motion_request.yaw = p.amplitude if phase < 0.5 else -p.amplitude
        self.head_motion_request.pitch = p.pitch
        self.head_motion_request.max_speed = p.speed


def sweep_errors(engine: str, latency_ms: float, aligned: bool, seconds: float = 6.0, speed: float = 2.5, seed: int = 0) -> list[float]:
    """Relative errors (share of the true distance) of every ball percept while the head turns fast."""
    modules = json.dumps([*PERCEPTION, "tests.support.head_sweep:HeadSweep", "tests.support.motion_requests:ConstantMotionRequest"])
    sim = Simulation(engine, overrides=[f"cognition.modules={modules}", f"parameters.HeadSweep.speed={speed}",
                                        f"parameters.BallLocator.time_aligned={'true' if aligned else 'false'}"],
                     ball=f"{BALL[0]},{BALL[1]}", camera_latency_ms=latency_ms, seed=seed, ball_color="orange")
    errors: list[float] = []
    last_frame = [0]
    try:
        sim.run(1.5)  # stand up first

        def measure(s: Simulation) -> None:
            cognition = s.blackboard("cognition")
            frame = s.runtime.runners["cognition"].frames
            percept = cognition[BallPercept]
            yaw = float(s.blackboard("motion")[JointSensorData].position[HEAD_YAW])
            head_speed, measure.last_yaw = abs(yaw - measure.last_yaw) / 0.01, yaw
            if frame == last_frame[0] or not percept.seen or head_speed < 0.5 * speed:
                return
            last_frame[0] = frame
            tx, ty = s.platform.ball_in_robot_frame()
            errors.append(math.hypot(percept.x - tx, percept.y - ty) / math.hypot(tx, ty))

        measure.last_yaw = 0.0  # type: ignore[attr-defined]
        sim.run(seconds, measure)
    finally:
        sim.close()
    return errors


def summary(errors: list[float]) -> dict[str, float]:
    values = np.asarray(errors) if errors else np.asarray([math.nan])
    return {"percepts": len(errors), "mean": float(values.mean()), "p95": float(np.percentile(values, 95)), "max": float(values.max())}
