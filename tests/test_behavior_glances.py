"""LookAtBallBehavior's glances for the localization, through the mocked blackboard."""

from __future__ import annotations

import math

from tafel.core.testing import ModuleHarness
from tafel.modules.behavior.look_at_ball_behavior import LookAtBallBehavior
from tafel.representations.behavior import HeadMotionRequest
from tafel.representations.infrastructure import FrameInfo
from tafel.representations.modeling import BallModel, RobotPose

FRAME_NS = 33_333_333


def yaws(ball: BallModel, pose: RobotPose, seconds: float) -> list[float]:
    """The requested head yaw of every frame for ``seconds``."""
    harness = ModuleHarness(LookAtBallBehavior, ball, pose)
    out = []
    for i in range(1, int(seconds * 30) + 1):
        harness.set(FrameInfo(frame_number=i, time_ns=i * FRAME_NS))
        out.append(harness.execute()[HeadMotionRequest].yaw)
    return out


def glances(values: list[float], ball_yaw: float) -> int:
    """How many glances: each goes left, then right, then back, so count the swings to the left."""
    away = [v - ball_yaw > 0.5 for v in values]
    return sum(1 for a, b in zip(away, away[1:]) if b and not a)


def test_it_glances_round_now_and_then_and_more_often_when_the_pose_is_not_valid() -> None:
    ball = BallModel(valid=True, seen=True, x=2000.0, y=0.0)
    p = LookAtBallBehavior.Parameters()
    sure = yaws(ball, RobotPose(valid=True), 30.0)
    unsure = yaws(ball, RobotPose(valid=False, lost=True), 30.0)
    expected_sure = 30.0 / (p.glance_interval + p.glance_duration)
    expected_unsure = 30.0 / (p.glance_interval_lost + p.glance_duration)
    assert abs(glances(sure, 0.0) - expected_sure) <= 1.5
    assert abs(glances(unsure, 0.0) - expected_unsure) <= 1.5
    assert max(map(abs, sure)) <= p.glance_amplitude + 1e-9  # glances stay within reach
    assert sum(abs(v) < 1e-9 for v in sure) > 0.6 * len(sure)  # most of the time: on the ball


def test_it_never_looks_away_from_a_near_ball_while_its_pose_is_valid() -> None:
    """A near ball stays in view while the pose is valid; an unsure robot (carried next to the ball) glances
    anyway: it must see the field before it kicks."""
    ball = BallModel(valid=True, seen=True, x=400.0, y=300.0)
    values = yaws(ball, RobotPose(valid=True), 20.0)
    assert all(v == values[0] for v in values) and values[0] == math.atan2(300.0, 400.0)
    p = LookAtBallBehavior.Parameters()
    unsure = yaws(ball, RobotPose(valid=False, lost=True), 20.0)
    right = [v < -0.5 for v in unsure]  # the ball is on the left: count the glances' swings to the right
    swings = sum(1 for a, b in zip(right, right[1:]) if b and not a)
    assert abs(swings - 20.0 / (p.glance_interval_lost + p.glance_duration)) <= 1.5
