"""The ``match`` platform: one robot of a simulated match, in a process of its own.

``tafel match`` starts one program per robot on this platform. Every motion tick it sends its joint
commands to the match's world (``match_world.py``) and waits for its sensors of the next tick: the
world, and with it every robot, moves in lockstep, so a match with a seed comes out the same.

- Sensors, noise, the chest button and the network are those of every simulated robot
  (``SimulatedRobotPlatform``); the field is seen in the team's own frame (its goal at -x).
- With cameras, each robot renders its own images from the world's positions (a copy of the world's
  model in its process), so rendering is spread over the cores.
- ``--realism LEVEL`` (``tafel match --realism``) runs each robot's images through its camera pipeline,
  seeded by its own ``--seed``; the hall (clutter, carpet, shadows) is the world's, one for every robot.
- ``--cameras off`` gives the program perception from ground truth instead: ``BallPercept`` (the ball
  while it is within the top camera's view and 6 m, with noise) and ``RobotPose`` (the truth, with
  noise); the image modules are then left out. Matches run faster so, and test the play, not the eyes.

Team messages and GameController packets are read right after the world's tick arrives: all that was
sent during the last tick is there then, on loopback, so what a program hears does not depend on how
the processes happened to be scheduled.
"""

from __future__ import annotations

import argparse
import math
import os
from collections.abc import Mapping
from multiprocessing.connection import Client, Connection
from typing import Any

import numpy as np

from tafel.core.framework.manager import Blackboard
from tafel.core.runtime.platform import EndOfData, PlatformError, PlatformOptionError
from tafel.platforms.match_world import Side, Snapshot
from tafel.platforms.mujoco_sim import MujocoCameras, MujocoRobot, mujoco
from tafel.platforms.network import NETWORK_INPUTS, NETWORK_OUTPUTS
from tafel.platforms.robot_model import mjcf_assets, robot_prefix
from tafel.platforms.simulated import SimulatedRobotPlatform
from tafel.representations.geometry import Pose2D
from tafel.representations.modeling import RobotPose
from tafel.representations.motion import HEAD_YAW, JOINT_COUNT, FsrData, InertialSensorData, JointCommand, JointSensorData, TouchSensorData
from tafel.representations.nao import HORIZONTAL_FOV
from tafel.representations.obstacles import RobotsPercept, SeenRobot
from tafel.representations.perception import BallPercept, CameraImageBottom, CameraImageTop

AUTHKEY_ENV = "TAFEL_MATCH_KEY"  # the world's connection key, given to each robot's process by tafel match
MAX_SEEN_DISTANCE = 6000.0  # mm: the ground-truth perception sees the ball this far
ROBOT_SEEN_DISTANCE, ROBOT_SEEN_ANGLE = 3000.0, math.radians(100.0)  # mm, rad: and other robots this near, this far round


class MatchRobotPlatform(SimulatedRobotPlatform):
    name = "match"
    engine = "MuJoCo (a match's world)"
    description = "one robot of a simulated match: its world runs in tafel match, in lockstep with every robot"
    default_network = "udp"  # the robots and the referee are processes of their own, on loopback ports of their own

    def __init__(self, options: Mapping[str, Any] | None = None) -> None:
        super().__init__(options)
        address = str(self.options.get("world") or "")
        host, _, port = address.rpartition(":")
        if not host or not port.isdigit():
            raise PlatformOptionError(f"--world takes the HOST:PORT tafel match prints, got {address!r}; start robots with tafel match")
        self.address = (host, int(port))
        self.index = int(self.options.get("index") or 0)
        self.side = Side(-1.0 if str(self.options.get("side") or "+x") == "-x" else 1.0)
        cognition = (CameraImageTop, CameraImageBottom) if self.cameras else (BallPercept, RobotPose, RobotsPercept)
        self.provides = {"motion": (JointSensorData, InertialSensorData, FsrData, TouchSensorData),  # type: ignore[misc]
                         "cognition": (*cognition, *NETWORK_INPUTS)}
        self.consumes = {"motion": (JointCommand,), "cognition": NETWORK_OUTPUTS}  # type: ignore[misc]
        self.connection: Connection | None = None
        self.snapshot: Snapshot | None = None
        self.command = (np.zeros(JOINT_COUNT), np.zeros(JOINT_COUNT))
        self.model: Any = None
        self.renderers: MujocoCameras | None = None

    @classmethod
    def add_arguments(cls, parser: argparse.ArgumentParser) -> None:
        super().add_arguments(parser)
        parser.add_argument("--world", help="match: the world's HOST:PORT (tafel match gives it)")
        parser.add_argument("--index", type=int, default=0, help="match: this robot's number in the world")
        parser.add_argument("--side", choices=["+x", "-x"], default="+x", help="match: the direction this robot's team attacks in the world")

    # ------------------------------------------------------------------------------ platform
    def start(self, contexts: frozenset[str]) -> None:
        key = os.environ.get(AUTHKEY_ENV, "").encode()
        try:
            self.connection = Client(self.address, authkey=key)
            self.connection.send(("hello", self.index, self.cameras and "cognition" in contexts))
            _, xml, ball_color, robots, look = self.connection.recv()
        except (OSError, EOFError, ValueError) as exc:
            raise PlatformError(f"cannot join the match's world at {self.address[0]}:{self.address[1]} ({exc}); "
                                "robots of a match are started by tafel match") from None
        if self.cameras and "cognition" in contexts:
            # the world's hall (tafel match --realism): every robot sees the same one, whatever its own seed
            self.scene_look = look
            self.model = mujoco.MjModel.from_xml_string(xml, mjcf_assets(ball_color, look))
            self.data = mujoco.MjData(self.model)
            self.robot = MujocoRobot(self.model, robot_prefix(self.index, robots))
            # as the MuJoCo platform renders with --realism; off renders as it always did (MuJoCo's own flags)
            self.renderers = MujocoCameras(self.model, self.robot, self.sizes, self.shadows if self.realism_level is not None else None)
        if "cognition" in contexts:
            self.network.open()

    def stop(self) -> None:
        super().stop()
        if self.renderers is not None:
            self.renderers.close()
            self.renderers = None
        if self.connection is not None:
            self.connection.close()
            self.connection = None

    def advance(self, time_ns: int) -> None:
        """Hand the last joint commands to the world and wait for the tick at ``time_ns``."""
        assert self.connection is not None, "advance before start"
        try:
            self.connection.send(("step", time_ns, *self.command))
            message = self.connection.recv()
        except (OSError, EOFError):
            raise EndOfData("the match's world is gone") from None
        if message[0] == "end":
            raise EndOfData(message[1])
        self.snapshot = message[1]
        self.time_ns = time_ns
        self.network.collect(time_ns)

    def sense(self, context: str, blackboard: Blackboard, frame_number: int, time_ns: int) -> None:
        super().sense(context, blackboard, frame_number, time_ns)
        if context == "cognition" and not self.cameras:
            self.perceive(blackboard)

    def perceive(self, blackboard: Blackboard) -> None:
        """Ground-truth perception for ``--cameras off``: the pose, and the ball while the head looks at it."""
        x, y, heading = self.robot_pose()
        pose = blackboard[RobotPose]
        noise = self.rng.normal(0.0, [20.0, 20.0, 0.01])
        pose.valid, pose.lost, pose.deviation, pose.rotation_deviation = True, False, 30.0, 0.02
        pose.x, pose.y, pose.rotation = x + noise[0], y + noise[1], math.remainder(heading + noise[2], math.tau)
        bx, by = self.ball_in_robot_frame()
        distance, bearing = math.hypot(bx, by), math.atan2(by, bx)
        head_yaw = float(self.snapshot.joints[HEAD_YAW]) if self.snapshot is not None else 0.0
        percept = blackboard[BallPercept]
        percept.seen = distance < MAX_SEEN_DISTANCE and abs(math.remainder(bearing - head_yaw, math.tau)) < HORIZONTAL_FOV / 2
        spread = 10.0 + 0.02 * distance
        percept.x, percept.y = ((bx + self.rng.normal(0.0, spread), by + self.rng.normal(0.0, spread)) if percept.seen else (0.0, 0.0))
        percept.camera = "top" if percept.seen else ""
        blackboard[RobotsPercept].robots = self.robots_near(x, y, heading)

    def robots_near(self, x: float, y: float, heading: float) -> list[SeenRobot]:
        """The other robots within ``ROBOT_SEEN_DISTANCE`` and ``ROBOT_SEEN_ANGLE`` of the torso's heading
        (what sonar and cameras would tell), robot frame mm, without noise beyond the pose's."""
        seen, here = [], Pose2D(x, y, heading)
        for index, world in enumerate(self.snapshot.robots if self.snapshot is not None else ()):
            if index == self.index:
                continue
            ox, oy, _ = self.side.to_team(*world)
            rx, ry = here.to_local(ox, oy)
            if math.hypot(rx, ry) < ROBOT_SEEN_DISTANCE and abs(math.atan2(ry, rx)) < ROBOT_SEEN_ANGLE:
                seen.append(SeenRobot(rx, ry))
        return seen

    # ----------------------------------------------------------------- what the engine answers
    def joint_angles(self) -> np.ndarray:
        return self.snapshot.joints.copy()

    def joint_torques(self) -> np.ndarray:
        return self.snapshot.torques.copy()

    def imu(self) -> tuple[np.ndarray, np.ndarray]:
        return self.snapshot.accelerometer.copy(), self.snapshot.gyroscope.copy()

    def foot_forces(self) -> np.ndarray:
        return self.snapshot.fsr.copy()

    def torso_pose(self) -> tuple[np.ndarray, np.ndarray]:
        return self.snapshot.torso_position.copy(), self.snapshot.torso_rotation.copy()

    def robot_pose(self) -> tuple[float, float, float]:
        """The torso on the field, in the team's frame (its own goal at -x)."""
        position, matrix = self.torso_pose()
        return self.side.to_team(float(position[0]) * 1000.0, float(position[1]) * 1000.0, math.atan2(matrix[1, 0], matrix[0, 0]))

    def ball_position(self) -> tuple[float, float]:
        x, y, _ = self.side.to_team(*self.snapshot.ball)
        return x, y

    def render(self, camera: str) -> np.ndarray:
        if self.snapshot is None or self.snapshot.qpos is None or self.renderers is None:
            width, height = self.sizes[camera]
            return np.zeros((height, width, 3), np.uint8)
        self.data.qpos[:] = self.snapshot.qpos
        mujoco.mj_kinematics(self.model, self.data)
        mujoco.mj_camlight(self.model, self.data)
        return self.renderers.render(self.data, camera)

    def camera_rotation(self, camera: str) -> np.ndarray | None:
        """The camera's orientation at the last rendered tick (``--realism``'s motion blur); None without cameras."""
        return self.robot.camera_rotation(self.data, camera) if self.model is not None else None

    def drive(self, targets: np.ndarray, stiffness: np.ndarray) -> None:
        self.command = (np.asarray(targets, dtype=float).copy(), np.asarray(stiffness, dtype=float).copy())

    # ------------------------------------------------------------------------ debug commands
    def commands(self) -> Mapping[str, tuple[str, Any]]:
        """The network's and the chest button; the referee alone moves robots and the ball in a match."""
        every = super().commands()
        return {name: every[name] for name in every if name in ("network:status", "sim:button", "sim:status")}
