"""Getting up, watched by simulator ground truth: for the get-up tests and ``benchmarks/walking.py``."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from tafel.representations.motion_control import FallState, MotionRequest, MotionType
from tests.support.driven import Driven

#: s a get-up must keep the robot upright after it stands, to count
STAYS_UP_S = 2.0
#: s from being laid down within which the robot must stand, or it did not get up
WITHIN_S = 15.0
#: while walking before being laid down: forward and turning a little, so that each moment lies differently
WALKING = MotionRequest(motion=MotionType.walk, walk_x=150.0, walk_rotation=0.3)
#: the striker searching for the ball: turning in place
TURNING = MotionRequest(motion=MotionType.walk, walk_rotation=0.6)
STANDING = MotionRequest(motion=MotionType.stand)


@dataclass
class GetUp:
    """What one get-up did (ground truth)."""

    up_s: float | None  # s from being laid down to standing (upright at standing height, FallState upright too)
    stayed_up: bool  # still upright STAYS_UP_S later

    @property
    def succeeded(self) -> bool:
        return self.up_s is not None and self.stayed_up


def get_up(engine: str, side: str, seed: int, walk_s: float, before: MotionRequest = WALKING,
           after: MotionRequest = STANDING, overrides: list[str] | None = None) -> GetUp:
    """``before`` for ``walk_s`` s, then laid down on ``side`` (front, back) where the robot is, and ``after``
    requested from then on (the selector gets the robot up first); ``overrides`` as ``tafel run --set``."""
    driven = Driven(engine, seed=seed, overrides=overrides)
    try:
        driven.request = before
        if walk_s > 0:
            driven.run(walk_s)
        driven.request = after
        platform = driven.sim.platform
        x, y, heading = platform.robot_pose()
        platform.move_robot(x, y, heading, side)
        for step in range(1, int(WITHIN_S / 0.01) + 1):
            driven.run(0.01)
            if platform.posture() == "upright" and platform.torso_height() > 280 and driven.motion[FallState].upright:
                for _ in range(int(STAYS_UP_S / 0.05)):
                    driven.run(0.05)
                    if platform.posture() != "upright":
                        return GetUp(step * 0.01, False)
                return GetUp(step * 0.01, True)
        return GetUp(None, False)
    finally:
        driven.close()


def seeded_walk_s(seed: int) -> float:
    """How long the robot walks before it is laid down, by seed (0 to 1 s: a different lying pose each)."""
    return float(np.random.default_rng(seed).uniform(0.0, 1.0))
