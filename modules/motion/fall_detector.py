"""FallDetector: upright, staggering, falling (and which way), lying (on which side), from the IMU."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from tafel.core import Module, bounded, provides, requires, uses
from tafel.representations.infrastructure import FrameInfo
from tafel.representations.motion import InertialSensorData
from tafel.representations.motion_control import FallDirection, FallPhase, FallState, KeyframeOutput, MotionSelection, MotionType


@requires(InertialSensorData, FrameInfo)
@uses(MotionSelection, KeyframeOutput)
@provides(FallState)
class FallDetector(Module):
    """Classifies the torso's tilt (roll, pitch from the IMU's own fusion) and its rate.

    Falling is reported early, from the tilt and how fast it grows, so that the protective motion comes
    before the impact. Lying needs the tilt to stay large and the body still for ``settle`` seconds.
    While the get-up motion plays, the state is ``getting_up`` whatever the tilt.
    """

    inertial_sensor_data: InertialSensorData
    frame_info: FrameInfo
    motion_selection: MotionSelection
    keyframe_output: KeyframeOutput
    fall_state: FallState

    @dataclass
    class Parameters:
        stagger_angle: float = bounded(0.05, 1.0, 0.3)
        """rad of tilt from which the robot staggers"""
        fall_angle: float = bounded(0.1, 1.4, 0.55)
        """rad of tilt from which it falls (or less, when the tilt grows fast)"""
        fall_rate: float = bounded(0.1, 10.0, 1.2)
        """rad/s of tilt rate that makes half the fall angle a fall"""
        lying_angle: float = bounded(0.5, 1.57, 1.0)
        """rad of tilt of a lying robot"""
        settle: float = bounded(0.0, 3.0, 0.4)
        """s a lying robot must be still"""

    parameters: Parameters

    def __init__(self) -> None:
        self.still_since: int | None = None
        self.phase_since = 0

    def execute(self) -> None:
        p, state, imu = self.parameters, self.fall_state, self.inertial_sensor_data
        now = self.frame_info.time_ns
        roll, pitch = float(imu.angles[0]), float(imu.angles[1])
        rate = math.hypot(float(imu.gyroscope[0]), float(imu.gyroscope[1]))
        tilt = max(abs(roll), abs(pitch))
        previous = state.phase
        if self.motion_selection.active is MotionType.getup and not self.keyframe_output.done:
            phase, direction = FallPhase.getting_up, state.direction
        elif tilt >= p.lying_angle and rate < 0.5:
            self.still_since = now if self.still_since is None else self.still_since
            settled = (now - self.still_since) * 1e-9 >= p.settle
            direction = _direction(roll, pitch, imu.accelerometer)
            lying = {FallDirection.front: FallPhase.lying_front, FallDirection.back: FallPhase.lying_back}.get(
                direction, FallPhase.lying_side)
            phase = lying if settled else FallPhase.falling
        elif tilt >= p.fall_angle or (tilt >= p.fall_angle / 2 and rate >= p.fall_rate and _growing(roll, pitch, imu)):
            phase, direction = FallPhase.falling, _direction(roll, pitch, imu.accelerometer)
        elif tilt >= p.stagger_angle:
            phase, direction = FallPhase.staggering, _direction(roll, pitch, imu.accelerometer)
        else:
            phase, direction = FallPhase.upright, FallDirection.none
        if tilt < p.lying_angle or rate >= 0.5:
            self.still_since = None
        if phase is not previous:
            self.phase_since = now
        state.phase, state.direction = phase, direction
        state.duration = max(0.0, (now - self.phase_since) * 1e-9)


def _direction(roll: float, pitch: float, accelerometer: np.ndarray) -> FallDirection:
    """Which way the torso leans: forward lean is positive pitch, leaning left negative roll (the robot
    turns about +x to the right).

    Near lying, roll and pitch lose their meaning (at a pitch of 90 degrees the roll is anything), so
    there the accelerometer decides, when it measures about gravity: the torso's x axis pointing down
    (face down) reads negative, its y axis pointing down (lying on the left) negative.
    """
    ax, ay, az = (float(v) for v in accelerometer[:3])
    if max(abs(roll), abs(pitch)) > 1.0 and 5.0 < math.sqrt(ax * ax + ay * ay + az * az) < 15.0:
        if abs(ax) >= abs(ay):
            return FallDirection.front if ax < 0 else FallDirection.back
        return FallDirection.left if ay < 0 else FallDirection.right
    if abs(pitch) >= abs(roll):
        return FallDirection.front if pitch > 0 else FallDirection.back
    return FallDirection.right if roll > 0 else FallDirection.left


def _growing(roll: float, pitch: float, imu: InertialSensorData) -> bool:
    """The tilt grows: the rate about an axis has the sign of the tilt about it."""
    return roll * float(imu.gyroscope[0]) > 0 or pitch * float(imu.gyroscope[1]) > 0
