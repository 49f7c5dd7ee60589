"""KalmanBallModeler forgets an unseen ball sooner while the robot's pose is lost (it may have been carried,
which odometry does not see), so the striker turns to look for it; through the mocked blackboard."""

from __future__ import annotations

import pytest

from tafel.core.testing import ModuleHarness
from tafel.modules.modeling.kalman_ball_modeler import KalmanBallModeler
from tafel.representations.infrastructure import FrameInfo
from tafel.representations.modeling import BallModel, RobotPose
from tafel.representations.perception import BallPercept

FRAME_NS = 33_333_333


def valid_for(pose: RobotPose) -> float:
    """s for which a ball seen once, then never again, stays valid while the robot's pose is ``pose``."""
    harness = ModuleHarness(KalmanBallModeler, BallPercept(seen=True, x=1000.0, y=200.0), pose, FrameInfo(frame_number=0, time_ns=0))
    harness.execute()
    harness.set(BallPercept(seen=False))
    last_valid = 0
    for i in range(1, 200):
        harness.set(FrameInfo(frame_number=i, time_ns=i * FRAME_NS))
        if harness.execute()[BallModel].valid:
            last_valid = i
    return last_valid * FRAME_NS * 1e-9


def test_an_unseen_ball_is_forgotten_sooner_while_the_pose_is_lost() -> None:
    p = KalmanBallModeler.Parameters()
    assert valid_for(RobotPose(valid=True)) == pytest.approx(p.forget_after, abs=0.04)
    assert valid_for(RobotPose(valid=False, lost=True)) == pytest.approx(p.forget_after_lost, abs=0.04)
    assert p.forget_after_lost < p.forget_after
