"""A simulation whose motion gets a ``MotionRequest`` every frame, watched by ground truth: for tests and
benchmarks of the walk, kicks, get-ups and pushes."""

from __future__ import annotations

import math

from tafel.representations.motion_control import MotionRequest, MotionType
from tests.support.simulation import Simulation


class Driven:
    """A simulation whose motion context gets ``request`` every frame (as ``motion:*`` would set it),
    counting falls (ground truth: the torso no longer upright) and the heading turned (unwrapped)."""

    def __init__(self, engine: str, cameras: bool = False, seed: int = 0, start: str = "0,0,0", ball: str = "4000,2800",
                 overrides: list[str] | None = None) -> None:
        self.sim = Simulation(engine, overrides=overrides, cameras="on" if cameras else "off", ball=ball, seed=str(seed), start=start)
        self.request = MotionRequest(motion=MotionType.stand)
        self.motion = self.sim.blackboard("motion")
        self.sim.runtime.runners["motion"].manager.before_frame.append(lambda: self.motion.set(self.request))
        self.turned = 0.0
        self.last_heading = self.sim.platform.robot_pose()[2]
        self.lying = False
        self.falls = 0
        self.sim.run(2.0, self.watch)

    def watch(self, sim: Simulation) -> None:
        heading = sim.platform.robot_pose()[2]
        self.turned += math.remainder(heading - self.last_heading, math.tau)
        self.last_heading = heading
        lying = sim.platform.posture() != "upright"
        if lying and not self.lying:
            self.falls += 1
        self.lying = lying

    def run(self, seconds: float) -> None:
        self.sim.run(seconds, self.watch)

    def push(self, fx: float, fy: float) -> None:
        """``sim:push``: the torso pushed for 0.1 s with (fx, fy) N in the field frame."""
        self.sim.platform.commands()["sim:push"][1]({"x": fx, "y": fy})

    def push_from(self, side: str, force: float) -> None:
        """A push of ``force`` N from ``side`` of the robot (front, back, left, right): from the front pushes
        it backwards."""
        fx, fy = PUSH_FROM[side]
        _, _, heading = self.sim.platform.robot_pose()
        c, s = math.cos(heading), math.sin(heading)
        self.push(force * (c * fx - s * fy), force * (s * fx + c * fy))

    def close(self) -> None:
        self.sim.close()


#: where a push comes from -> its direction in the robot frame
PUSH_FROM = {"front": (-1.0, 0.0), "back": (1.0, 0.0), "left": (0.0, -1.0), "right": (0.0, 1.0)}
