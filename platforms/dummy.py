"""The dummy platform: a deterministic clock and synthetic sensors, no physics.

For running and testing the runtime and the module graph without a simulator. Joints follow the last
joint command like ideal position servos with a time constant; the ball rolls on a fixed circle in
front of the robot and is seen while it is within the head's field of view, with reproducible noise.
"""

from __future__ import annotations

import argparse
import math
from collections.abc import Mapping
from typing import Any, ClassVar

import numpy as np

from tafel.core.framework.manager import Blackboard
from tafel.core.runtime.platform import Platform, seed_number
from tafel.platforms.network import NETWORK_INPUTS, NETWORK_OUTPUTS, NetworkedPlatform
from tafel.representations.modeling import RobotPose
from tafel.representations.motion import HEAD_YAW, JOINT_COUNT, FsrData, InertialSensorData, JointCommand, JointSensorData, TouchSensorData
from tafel.representations.perception import BallPercept

GRAVITY = 9.81


class DummyPlatform(NetworkedPlatform, Platform):
    name = "dummy"
    description = "deterministic clock, synthetic joints, IMU, ball percepts and pose, no physics"
    clock = "simulated"
    default_network = "simulated"  # equal runs stay equal: no other program on the machine is heard
    provides: ClassVar[Mapping[str, tuple[type, ...]]] = {
        "motion": (JointSensorData, InertialSensorData, FsrData, TouchSensorData),
        "cognition": (BallPercept, RobotPose, *NETWORK_INPUTS),
    }
    consumes: ClassVar[Mapping[str, tuple[type, ...]]] = {"motion": (JointCommand,), "cognition": NETWORK_OUTPUTS}

    #: s, time constant of the ideal joint servos
    SERVO_TIME_CONSTANT = 0.05
    #: rad, half the horizontal field of view in which the ball counts as seen
    HALF_FIELD_OF_VIEW = math.radians(28.0)
    #: mm, mm, rad on the field: in its own half, facing the opponent goal
    POSE = (-1500.0, 0.0, 0.0)

    def __init__(self, options: Mapping[str, Any] | None = None) -> None:
        super().__init__(options)
        self.seed = int(self.options.get("seed", 0))
        self.rng = np.random.default_rng(self.seed)
        self.joints = np.zeros(JOINT_COUNT)
        self.command = np.zeros(JOINT_COUNT)
        self.stiffness = np.zeros(JOINT_COUNT)
        self.time_ns = 0
        self.simulates_joints = False
        self.commands_received = 0

    @classmethod
    def add_arguments(cls, parser: argparse.ArgumentParser) -> None:
        parser.add_argument("--seed", type=seed_number, default=0, help="dummy: seed of the synthetic sensor noise")

    def start(self, contexts: frozenset[str]) -> None:
        self.simulates_joints = "motion" in contexts
        if "cognition" in contexts:
            self.network.open()

    def stop(self) -> None:
        self.network.close()

    def commands(self) -> Mapping[str, tuple[str, Any]]:
        return self.network.commands()

    def advance(self, time_ns: int) -> None:
        dt = max(0, time_ns - self.time_ns) * 1e-9
        self.time_ns = time_ns
        follow = 1.0 - math.exp(-dt / self.SERVO_TIME_CONSTANT) if dt > 0 else 0.0
        self.joints += (self.command - self.joints) * follow * (self.stiffness > 0)

    def ball_position(self, time_ns: int) -> tuple[float, float]:
        """The true ball position (mm, robot frame) at a time."""
        t = time_ns * 1e-9
        return 1500.0 + 500.0 * math.cos(0.5 * t), 800.0 * math.sin(0.5 * t)

    def sense(self, context: str, blackboard: Blackboard, frame_number: int, time_ns: int) -> None:
        if not self.simulates_joints:
            self.advance(time_ns)  # concurrent runtime: no one else moves the clock
        if context == "motion":
            joints = blackboard[JointSensorData]
            joints.position = self.joints.copy()
            joints.stiffness = self.stiffness.copy()
            inertial = blackboard[InertialSensorData]
            inertial.accelerometer = np.array([0.0, 0.0, GRAVITY])
            inertial.gyroscope = np.zeros(3)
            inertial.angles = np.zeros(2)
            blackboard[FsrData].pressure = np.full(8, 5.36 / 8)
            blackboard.set(TouchSensorData())
        elif context == "cognition":
            x, y = self.ball_position(time_ns)
            head_yaw = self.joints[HEAD_YAW] if self.simulates_joints else math.atan2(y, x)
            percept = blackboard[BallPercept]
            percept.seen = abs(math.atan2(y, x) - head_yaw) < self.HALF_FIELD_OF_VIEW
            noise = self.rng.normal(0.0, 20.0, 2)
            percept.x, percept.y = (float(x + noise[0]), float(y + noise[1])) if percept.seen else (0.0, 0.0)
            percept.camera = "top" if percept.seen else ""
            pose = blackboard[RobotPose]  # the robot never moves: it stands where the simulators start it
            pose.valid, pose.lost, pose.deviation, pose.rotation_deviation = True, False, 0.0, 0.0
            pose.x, pose.y, pose.rotation = self.POSE
            self.network.receive(blackboard, time_ns)

    def act(self, context: str, blackboard: Blackboard) -> None:
        if context == "cognition":
            self.network.send(blackboard)
        if context == "motion":
            command = blackboard[JointCommand]
            self.command = np.asarray(command.position, dtype=float).copy()
            self.stiffness = np.asarray(command.stiffness, dtype=float).copy()
            self.commands_received += 1
