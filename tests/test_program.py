"""Planning a program: module names from configuration, hand-overs, pruning, lockstep timing."""

from __future__ import annotations

from typing import ClassVar

import pytest

from tafel.core import ConflictingProvidersError, MissingProviderError, Module, UnknownModuleError, provides, requires
from tafel.core.framework.config import ConfigError
from tafel.core.runtime import Limits, LockstepRuntime
from tafel.core.runtime.platform import Platform
from tafel.core.runtime.program import plan_program
from tafel.representations.behavior import HeadMotionRequest
from tafel.representations.infrastructure import CognitionStatus, FrameInfo
from tafel.representations.motion import BodyJointTargets, HeadJointTargets, JointCommand, JointSensorData
from tafel.representations.perception import BallPercept
from tafel.tools.launch.program import discover_modules

discover_modules()


class CameraOnlyPlatform(Platform):
    name = "camera-only-test"
    provides: ClassVar = {"cognition": (FrameInfo, BallPercept)}
    consumes: ClassVar = {}


class FullTestPlatform(Platform):
    name = "full-test"
    provides: ClassVar = {"cognition": (FrameInfo, BallPercept), "motion": (FrameInfo, JointSensorData)}
    consumes: ClassVar = {"motion": (JointCommand,)}

    def __init__(self, options=None) -> None:
        super().__init__(options)
        self.sensed: list[tuple[str, int, int]] = []

    def sense(self, context, blackboard, frame_number, time_ns) -> None:
        self.sensed.append((context, frame_number, time_ns))
        blackboard.set(FrameInfo(frame_number=frame_number, time_ns=time_ns))


@requires(BodyJointTargets, HeadJointTargets)
@provides(JointCommand)
class TpCombinator(Module):
    """The body's targets with the head's: the smallest motion pipeline, for tests of the program's plan."""

    def execute(self) -> None:
        self.joint_command.position = self.body_joint_targets.position.copy()


CONFIG = {
    "cognition": {"modules": ["KalmanBallModeler", "SimpleBallModeler", "LookAtBallBehavior"],
                  "providers": {"BallModel": "KalmanBallModeler"}},
    "motion": {"modules": ["StandMotion", "HeadMotion", "tests.test_program:TpCombinator"]},
}


def test_hand_overs_are_found_automatically() -> None:
    plans = plan_program(CONFIG, FullTestPlatform)
    assert plans["motion"].handover_in == [HeadMotionRequest]
    assert plans["cognition"].handover_out == [HeadMotionRequest]
    assert plans["cognition"].handover_in == [] and plans["motion"].handover_out == []
    assert CognitionStatus in plans["motion"].external
    assert plans["motion"].pruned == {} and plans["cognition"].pruned == {}


def test_a_platform_without_joints_prunes_motion_and_reports_why() -> None:
    plans = plan_program(CONFIG, CameraOnlyPlatform)
    assert plans["motion"].pruned == {
        "StandMotion": ["JointSensorData", "FrameInfo"],
        "HeadMotion": ["JointSensorData", "FrameInfo"],
        "TpCombinator": ["BodyJointTargets", "HeadJointTargets"],
    }
    assert not plans["motion"].runs and plans["cognition"].runs
    assert plans["cognition"].handover_out == []


def test_strict_turns_pruning_into_an_error() -> None:
    with pytest.raises(MissingProviderError, match="cannot feed these modules .*motion: StandMotion needs JointSensorData"):
        plan_program(CONFIG, CameraOnlyPlatform, strict=True)


def test_unknown_module_in_configuration_names_the_closest() -> None:
    config = {"cognition": {"modules": ["KalmanBallModeller"]}}
    with pytest.raises(UnknownModuleError, match="did you mean 'KalmanBallModeler'"):
        plan_program(config, FullTestPlatform)
    with pytest.raises(UnknownModuleError, match="unknown module 'Nope'"):
        plan_program({"motion": {"modules": ["HeadMotion"], "disabled": ["Nope"]}}, FullTestPlatform)


def test_a_representation_provided_in_both_contexts_is_an_error() -> None:
    config = {"cognition": {"modules": ["SimpleBallModeler"]}, "motion": {"modules": ["KalmanBallModeler"]}}
    with pytest.raises(ConflictingProvidersError, match="BallModel is provided in both contexts"):
        plan_program(config, FullTestPlatform)


def test_invalid_rates_are_rejected() -> None:
    with pytest.raises(ConfigError, match="cognition_hz must be positive"):
        plan_program({"runtime": {"cognition_hz": 0}}, FullTestPlatform)


def test_lockstep_gives_three_cognition_frames_per_ten_motion_frames() -> None:
    platform = FullTestPlatform()
    runtime = LockstepRuntime(plan_program(CONFIG, FullTestPlatform), platform)
    stats = runtime.run(Limits(frames=1000, speed=None))
    assert stats["motion"].frames == 1000 and stats["cognition"].frames == 300
    cognition_times = [t for c, _, t in platform.sensed if c == "cognition"]
    # cognition frame k runs on the first motion tick at or after k / 30 s
    expected = [-(-k * 10**9 // 30 // 10_000_000) * 10_000_000 for k in range(300)]
    assert cognition_times == expected
    motion_frames = [f for c, f, _ in platform.sensed if c == "motion"]
    assert motion_frames == list(range(1, 1001))


def test_lockstep_hands_over_the_newest_complete_value() -> None:
    @requires(FrameInfo)
    @provides(HeadMotionRequest)
    class StampRequest(Module):
        def execute(self) -> None:
            self.head_motion_request.yaw = float(self.frame_info.frame_number)
            self.head_motion_request.pitch = -float(self.frame_info.frame_number)

    seen: list[tuple[float, float]] = []

    @requires(HeadMotionRequest)
    class ReadRequest(Module):
        def execute(self) -> None:
            seen.append((self.head_motion_request.yaw, self.head_motion_request.pitch))

    from tafel.core.runtime.program import ContextPlan

    plans = {
        "cognition": ContextPlan("cognition", 30.0, [StampRequest], {}, [], {}, [FrameInfo], [], handover_out=[HeadMotionRequest]),
        "motion": ContextPlan("motion", 100.0, [ReadRequest], {}, [], {}, [FrameInfo], [], handover_in=[HeadMotionRequest]),
    }
    LockstepRuntime(plans, FullTestPlatform()).run(Limits(frames=100, speed=None))
    assert all(yaw == -pitch for yaw, pitch in seen)
    assert seen[0] == (0.0, 0.0)  # motion runs first on a shared tick: nothing handed over yet
    assert seen[4] == (1.0, -1.0) and seen[-1] == (30.0, -30.0)
