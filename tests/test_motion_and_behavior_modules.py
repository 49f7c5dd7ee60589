"""Motion and behaviour modules through the mocked blackboard."""

from __future__ import annotations

import math

import numpy as np
import pytest

from tafel.core.testing import ModuleHarness
from tafel.modules.behavior.look_at_ball_behavior import LookAtBallBehavior
from tafel.modules.motion.head_motion import HeadMotion
from tafel.modules.motion.motion_combinator import MotionCombinator
from tafel.modules.motion.stand_motion import StandMotion, stand_pose
from tafel.representations.behavior import HeadMotionRequest
from tafel.representations.infrastructure import CognitionStatus, FrameInfo
from tafel.representations.modeling import BallModel, RobotPose
from tafel.representations.motion import (
    HEAD_PITCH,
    HEAD_YAW,
    JOINT_COUNT,
    BodyJointTargets,
    HeadJointTargets,
    JointCommand,
    JointSensorData,
)

TICK_NS = 10_000_000


def tick(i: int) -> FrameInfo:
    return FrameInfo(frame_number=i, time_ns=i * TICK_NS)


def test_look_at_a_valid_ball() -> None:
    bb = ModuleHarness(LookAtBallBehavior, BallModel(valid=True, x=1500.0, y=500.0)).execute()
    request = bb[HeadMotionRequest]
    assert request.yaw == pytest.approx(math.atan2(500.0, 1500.0))
    assert 0.0 < request.pitch < math.radians(29.5)


@pytest.mark.parametrize("pose_valid", [True, False])
def test_search_sweeps_while_the_ball_is_unknown(pose_valid: bool) -> None:
    """The sweep reaches ``search_amplitude``; while the pose is not valid, ``search_amplitude_lost`` (wider, to
    show the field round the robot), which the head's yaw limit (2.0857 rad) allows."""
    harness = ModuleHarness(LookAtBallBehavior, BallModel(valid=False), RobotPose(valid=pose_valid))
    yaws = []
    for i in range(0, 900, 10):
        harness.set(FrameInfo(frame_number=i, time_ns=i * TICK_NS))
        yaws.append(harness.execute()[HeadMotionRequest].yaw)
    p = harness.module.parameters
    amplitude = p.search_amplitude if pose_valid else p.search_amplitude_lost
    assert max(yaws) == pytest.approx(amplitude, abs=0.05) and min(yaws) == pytest.approx(-amplitude, abs=0.05)


def test_head_motion_starts_at_the_measured_position_and_limits_speed() -> None:
    position = np.zeros(JOINT_COUNT)
    position[HEAD_YAW] = 0.3
    harness = ModuleHarness(HeadMotion, JointSensorData(position=position), HeadMotionRequest(yaw=-1.0, pitch=0.2, max_speed=2.0), tick(0))
    targets = harness.execute()[HeadJointTargets]
    assert targets.yaw == pytest.approx(0.3 - 2.0 * 0.01)  # first step from the measured yaw
    previous = targets.yaw
    for i in range(1, 200):
        harness.set(tick(i))
        harness.execute()
        assert abs(harness[HeadJointTargets].yaw - previous) <= 2.0 * 0.01 + 1e-12
        previous = harness[HeadJointTargets].yaw
    assert harness[HeadJointTargets].yaw == pytest.approx(-1.0) and harness[HeadJointTargets].pitch == pytest.approx(0.2)


def test_head_motion_clamps_to_the_joint_limits() -> None:
    harness = ModuleHarness(HeadMotion, HeadMotionRequest(yaw=5.0, pitch=-2.0, max_speed=100.0))
    for i in range(300):
        harness.set(tick(i))
        harness.execute()
    assert harness[HeadJointTargets].yaw == pytest.approx(math.radians(119.5))
    assert harness[HeadJointTargets].pitch == pytest.approx(math.radians(-38.5))


def test_head_motion_falls_back_to_the_safe_position_without_cognition() -> None:
    harness = ModuleHarness(HeadMotion, HeadMotionRequest(yaw=1.0, pitch=0.3, max_speed=4.0))
    for i in range(100):
        harness.set(tick(i))
        harness.execute()
    assert harness[HeadJointTargets].yaw == pytest.approx(1.0)
    harness.set(CognitionStatus(alive=False))
    for i in range(100, 400):
        harness.set(tick(i))
        harness.execute()
    assert harness[HeadJointTargets].yaw == pytest.approx(0.0) and harness[HeadJointTargets].pitch == pytest.approx(0.0)


def test_stand_motion_ramps_from_the_current_pose_to_the_stand() -> None:
    start = np.full(JOINT_COUNT, 0.2)
    harness = ModuleHarness(StandMotion, JointSensorData(position=start), tick(0))
    first = harness.execute()[BodyJointTargets].position.copy()
    assert np.allclose(first, start)
    duration_ticks = int(harness.module.parameters.duration / 0.01)
    for i in range(1, duration_ticks + 50):
        harness.set(tick(i))
        harness.execute()
    assert np.allclose(harness[BodyJointTargets].position, stand_pose())
    assert np.all(harness[BodyJointTargets].stiffness == harness.module.parameters.stiffness)


def test_motion_combinator_takes_the_head_from_the_head_motion() -> None:
    body = BodyJointTargets(position=np.arange(JOINT_COUNT, dtype=float), stiffness=np.full(JOINT_COUNT, 0.9))
    bb = ModuleHarness(MotionCombinator, body, HeadJointTargets(yaw=0.5, pitch=-0.2, stiffness=0.6)).execute()
    command = bb[JointCommand]
    assert command.position[HEAD_YAW] == 0.5 and command.position[HEAD_PITCH] == -0.2
    assert command.position[5] == 5.0 and command.stiffness[HEAD_YAW] == 0.6 and command.stiffness[5] == 0.9
