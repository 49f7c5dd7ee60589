"""StandMotion: bring the body from wherever it is into a stable stand, then hold it."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from tafel.core import Module, provides, requires
from tafel.representations.infrastructure import FrameInfo
from tafel.representations.motion import JOINT_COUNT, JOINT_INDEX, BodyJointTargets, JointSensorData

#: the stand pose (rad): slightly bent knees keep the centre of mass over the feet
STAND_POSE: dict[str, float] = {
    "LShoulderPitch": 1.50, "LShoulderRoll": 0.15, "LElbowYaw": -1.20, "LElbowRoll": -0.50, "LWristYaw": 0.0,
    "RShoulderPitch": 1.50, "RShoulderRoll": -0.15, "RElbowYaw": 1.20, "RElbowRoll": 0.50, "RWristYaw": 0.0,
    "LHipYawPitch": 0.0, "LHipRoll": 0.0, "LHipPitch": -0.45, "LKneePitch": 0.90, "LAnklePitch": -0.45, "LAnkleRoll": 0.0,
    "RHipRoll": 0.0, "RHipPitch": -0.45, "RKneePitch": 0.90, "RAnklePitch": -0.45, "RAnkleRoll": 0.0,
}


def stand_pose() -> np.ndarray:
    pose = np.zeros(JOINT_COUNT)
    for name, angle in STAND_POSE.items():
        pose[JOINT_INDEX[name]] = angle
    return pose


@requires(JointSensorData, FrameInfo)
@provides(BodyJointTargets)
class StandMotion(Module):
    """Interpolates from the measured joint positions to ``STAND_POSE`` with a cosine ramp, then holds."""

    joint_sensor_data: JointSensorData
    frame_info: FrameInfo
    body_joint_targets: BodyJointTargets

    @dataclass
    class Parameters:
        duration: float = 1.5
        """s from the start pose to the stand"""
        stiffness: float = 0.9
        """0..1 for all body joints"""

    parameters: Parameters

    def __init__(self) -> None:
        self.start_pose: np.ndarray | None = None
        self.start_ns = 0
        self.goal = stand_pose()

    def execute(self) -> None:
        now_ns = self.frame_info.time_ns
        if self.start_pose is None:
            self.start_pose = np.array(self.joint_sensor_data.position, dtype=float)
            self.start_ns = now_ns
        elapsed = (now_ns - self.start_ns) * 1e-9
        progress = min(1.0, elapsed / self.parameters.duration) if self.parameters.duration > 0 else 1.0
        blend = 0.5 - 0.5 * math.cos(math.pi * progress)
        self.body_joint_targets.position = self.start_pose + (self.goal - self.start_pose) * blend
        self.body_joint_targets.stiffness = np.full(JOINT_COUNT, self.parameters.stiffness)
