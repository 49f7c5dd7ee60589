"""The world of a simulated match: one MuJoCo model with every robot and the ball, stepped in lockstep.

``tafel match`` owns it; each robot's program runs in a process of its own on the ``match`` platform
(``match_robot.py``), which sends its joint commands here every motion tick and gets its sensors back
(``Snapshot``). The physics is the one-robot platform's (``MujocoRobot``), so a robot walks in a match
as it does alone. Robots collide with each other and the world, never with themselves.

World coordinates are the field frame of the first team (it attacks +x). The second team's robots
see the field turned by 180 degrees (``Side``), so that for every program its own goal is at -x.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from tafel.platforms.field_world import SceneLook
from tafel.platforms.mujoco_sim import MujocoBall, MujocoRobot, TorqueLimits, mujoco
from tafel.platforms.robot_model import STANDING_HEIGHT, mjcf, mjcf_assets, robot_prefix
from tafel.platforms.simulated import TIMESTEP
from tafel.representations.motion import JOINT_COUNT

TICK_NS = 10_000_000  # the motion rate's period: the world and every program step together by this


@dataclass(frozen=True)
class Side:
    """How a team's field frame lies in the world: ``sign`` +1 for the team attacking +x, -1 for the other."""

    sign: float = 1.0

    def to_team(self, x: float, y: float, heading: float = 0.0) -> tuple[float, float, float]:
        """A world pose (mm, mm, rad) in the team's field frame."""
        if self.sign > 0:
            return x, y, heading
        return -x, -y, math.remainder(heading + math.pi, math.tau)

    def to_world(self, x: float, y: float, heading: float = 0.0) -> tuple[float, float, float]:
        return self.to_team(x, y, heading)  # turning by 180 degrees is its own inverse


@dataclass
class Snapshot:
    """What one robot's sensors measure at a tick, without noise (its platform adds the noise), and the
    whole world's positions (``qpos``) for rendering its cameras."""

    time_ns: int
    joints: np.ndarray
    torques: np.ndarray
    accelerometer: np.ndarray
    gyroscope: np.ndarray
    fsr: np.ndarray
    torso_position: np.ndarray
    torso_rotation: np.ndarray
    ball: tuple[float, float]
    qpos: np.ndarray | None
    robots: tuple[tuple[float, float], ...] = ()
    """every robot's torso on the ground (world mm), for ground-truth perception of the others"""


class MatchWorld:
    """The MuJoCo world of a match: ``robots`` start at the given world places (mm). ``look`` and
    ``shadows``: the realistic hall of ``tafel match --realism`` (one hall for every robot; none of it
    collides), which the robots' renderers build from ``xml`` and ``look``."""

    def __init__(self, places: list[tuple[float, float]], ball_color: str = "spl", offscreen: tuple[int, int] = (640, 480),
                 look: SceneLook | None = None, shadows: bool = False) -> None:
        self.xml = mjcf(offscreen=offscreen, timestep=TIMESTEP, ball_color=ball_color, robots=[(x / 1000.0, y / 1000.0) for x, y in places],
                        look=look, shadows=shadows)
        self.ball_color, self.look = ball_color, look
        self.model = mujoco.MjModel.from_xml_string(self.xml, mjcf_assets(ball_color, look))
        self.data = mujoco.MjData(self.model)
        self.robots = [MujocoRobot(self.model, robot_prefix(k, len(places))) for k in range(len(places))]
        self.torque_limits = TorqueLimits(self.model, self.robots)
        self.ball = MujocoBall(self.model)
        self.time_ns = 0
        mujoco.mj_forward(self.model, self.data)

    # --------------------------------------------------------------------------------- stepping
    def drive(self, index: int, targets: np.ndarray, stiffness: np.ndarray) -> None:
        targets, stiffness = np.asarray(targets, dtype=float), np.asarray(stiffness, dtype=float)
        if targets.shape != (JOINT_COUNT,) or stiffness.shape != (JOINT_COUNT,):
            raise ValueError(f"robot {index}: joint commands need {JOINT_COUNT} targets and stiffnesses")
        self.robots[index].drive(self.data, targets, stiffness)

    def step_to(self, time_ns: int) -> None:
        steps = int(round((time_ns - self.time_ns) * 1e-9 / TIMESTEP))
        for _ in range(max(0, steps)):
            self.torque_limits.apply(self.data)
            mujoco.mj_step(self.model, self.data)
        self.time_ns = time_ns

    def snapshot(self, index: int, with_world: bool) -> Snapshot:
        robot, data = self.robots[index], self.data
        accelerometer, gyroscope = robot.imu(data)
        position, rotation = robot.torso_pose(data)
        return Snapshot(time_ns=self.time_ns, joints=robot.joint_angles(data), torques=robot.joint_torques(data),
                        accelerometer=accelerometer, gyroscope=gyroscope, fsr=robot.foot_forces(data), torso_position=position,
                        torso_rotation=rotation, ball=self.ball_position(), qpos=data.qpos.copy() if with_world else None,
                        robots=tuple(self.robot_pose(k)[:2] for k in range(len(self.robots))))

    # ----------------------------------------------------------------------------- where things are
    def robot_pose(self, index: int) -> tuple[float, float, float]:
        """The torso on the field: world mm, mm and rad."""
        position, rotation = self.robots[index].torso_pose(self.data)
        return float(position[0]) * 1000.0, float(position[1]) * 1000.0, math.atan2(rotation[1, 0], rotation[0, 0])

    def robot_velocity(self, index: int) -> tuple[float, float]:
        """The torso's speed over the ground: world mm/s."""
        v = self.robots[index].root_qvel
        return float(self.data.qvel[v]) * 1000.0, float(self.data.qvel[v + 1]) * 1000.0

    def ball_position(self) -> tuple[float, float]:
        return self.ball.position(self.data)

    def move_ball(self, x_mm: float, y_mm: float) -> None:
        self.ball.place(self.data, x_mm, y_mm)

    def move_robot(self, index: int, x_mm: float, y_mm: float, heading: float) -> None:
        """Put a robot standing at a world pose, as a referee does; its joints keep their angles."""
        self.robots[index].place(self.data, np.array([x_mm / 1000.0, y_mm / 1000.0, STANDING_HEIGHT + 0.002]),
                    np.array([math.cos(heading / 2), 0.0, 0.0, math.sin(heading / 2)]))
        mujoco.mj_forward(self.model, self.data)
