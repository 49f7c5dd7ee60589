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


@pytest.mark.parametrize(("key", "value", "shown"), [("cognition_hz", 0, "0"), ("motion_hz", -5.0, "-5"),
                                                     ("motion_hz", 1e9, "1e+09"), ("cognition_hz", "30", "'30'")])
def test_invalid_rates_are_rejected(key: str, value: object, shown: str) -> None:
    # 1e9 Hz and "30" were taken before (only rates at or below 0 were refused)
    with pytest.raises(ConfigError) as error:
        plan_program({"runtime": {key: value}}, FullTestPlatform)
    assert str(error.value) == f"runtime.{key} takes a finite number of Hz above 0 and at most 1000, got {shown}"


def test_parameters_that_are_no_tables_say_what_would_be_right() -> None:
    with pytest.raises(ConfigError, match=r"^parameters takes a table of module tables .*, got 3$"):
        plan_program({"parameters": 3}, FullTestPlatform)


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


class SilentTestPlatform(Platform):
    """Provides joints and ball percepts but writes nothing, not even the frame clock."""

    name = "silent-test"
    provides: ClassVar = {"cognition": (BallPercept,), "motion": (JointSensorData,)}
    consumes: ClassVar = {}


class OwnTimeTestPlatform(SilentTestPlatform):
    """Gives each frame a time of its own (a robot's clock), still without writing FrameInfo."""

    name = "own-time-test"

    def __init__(self, options=None) -> None:
        super().__init__(options)
        self.sensed = {"cognition": 0, "motion": 0}

    def sense(self, context, blackboard, frame_number, time_ns) -> None:
        self.sensed[context] += 1

    def frame_time_ns(self, context: str) -> int | None:
        return 5_000_000_000 + 1000 * self.sensed[context] + (1 if context == "cognition" else 0)


CLOCKS_SEEN: list[tuple[str, int, int]] = []


@requires(FrameInfo)
class TpMotionClock(Module):
    """Notes the frame clock motion sees (a module of the runtime's tests)."""

    def execute(self) -> None:
        CLOCKS_SEEN.append(("motion", self.frame_info.frame_number, self.frame_info.time_ns))


@requires(FrameInfo)
class TpCognitionClock(Module):
    """Notes the frame clock cognition sees."""

    def execute(self) -> None:
        CLOCKS_SEEN.append(("cognition", self.frame_info.frame_number, self.frame_info.time_ns))


CLOCK_CONFIG = {"cognition": {"modules": ["tests.test_program:TpCognitionClock"]},
                "motion": {"modules": ["tests.test_program:TpMotionClock"]}}


def test_the_runtime_provides_frame_info_in_every_context_it_runs() -> None:
    plans = plan_program(CLOCK_CONFIG, SilentTestPlatform)
    for plan in plans.values():
        assert FrameInfo not in plan.platform_provides and FrameInfo in plan.runtime_provides
        assert FrameInfo in plan.external and plan.pruned == {}
    assert plans["motion"].runtime_provides == [FrameInfo, CognitionStatus]
    class CognitionOnly(SilentTestPlatform):
        provides: ClassVar = {"cognition": (BallPercept,)}

    for platform in (CognitionOnly, CameraOnlyPlatform):  # the second lists FrameInfo as platforms did before
        only_cognition = plan_program(CLOCK_CONFIG, platform)
        assert only_cognition["cognition"].platform_provides == [BallPercept]
        assert not only_cognition["motion"].runs and FrameInfo not in only_cognition["motion"].runtime_provides
        # motion does not run, so nothing writes its clock: pruned quietly, as for a sensor this platform lacks
        assert only_cognition["motion"].pruned == {"TpMotionClock": ["FrameInfo"]}


def test_the_runtime_writes_frame_info_for_a_platform_that_writes_nothing() -> None:
    CLOCKS_SEEN.clear()
    LockstepRuntime(plan_program(CLOCK_CONFIG, SilentTestPlatform), SilentTestPlatform()).run(Limits(frames=10, speed=None))
    motion = [(number, time_ns) for context, number, time_ns in CLOCKS_SEEN if context == "motion"]
    cognition = [(number, time_ns) for context, number, time_ns in CLOCKS_SEEN if context == "cognition"]
    assert motion == [(k, (k - 1) * 10_000_000) for k in range(1, 11)]  # 100 Hz from 0
    assert cognition == [(1, 0), (2, 40_000_000), (3, 70_000_000)]  # 30 Hz on the motion ticks


def test_frame_info_takes_the_time_the_platform_gives() -> None:
    CLOCKS_SEEN.clear()
    platform = OwnTimeTestPlatform()
    LockstepRuntime(plan_program(CLOCK_CONFIG, platform), platform).run(Limits(frames=4, speed=None))
    motion = [(number, time_ns) for context, number, time_ns in CLOCKS_SEEN if context == "motion"]
    cognition = [(number, time_ns) for context, number, time_ns in CLOCKS_SEEN if context == "cognition"]
    assert motion == [(k, 5_000_000_000 + 1000 * k) for k in range(1, 5)]  # the runtime's count, the platform's time
    assert cognition == [(1, 5_000_001_001)]  # 4 motion ticks hold one cognition frame


def test_a_platform_that_feeds_a_context_only_the_frame_clock_runs_it() -> None:
    class ClockOnly(SilentTestPlatform):
        provides: ClassVar = {"cognition": (BallPercept,), "motion": ()}

    CLOCKS_SEEN.clear()
    plans = plan_program(CLOCK_CONFIG, ClockOnly)
    assert plans["motion"].runs and plans["motion"].pruned == {}
    LockstepRuntime(plans, ClockOnly()).run(Limits(frames=3, speed=None))
    assert [(c, n) for c, n, _ in CLOCKS_SEEN if c == "motion"] == [("motion", 1), ("motion", 2), ("motion", 3)]


def test_a_topic_records_one_contexts_representation_and_a_misspelt_context_is_an_error() -> None:
    from tafel.core.logs.recording import select

    plans = plan_program(CONFIG, FullTestPlatform)
    topics = {s.topic for s in select(plans, ["motion/FrameInfo", "cognition/BallModel"], include_sensors=False)}
    assert topics == {"motion/FrameInfo", "cognition/BallModel"}
    assert {s.topic for s in select(plans, ["FrameInfo"], include_sensors=False)} == {"motion/FrameInfo", "cognition/FrameInfo"}
    with pytest.raises(UnknownModuleError) as error:  # before: "no context has it", as if the name were misspelt
        select(plans, ["Motion/FrameInfo"])
    assert str(error.value) == "'Motion/FrameInfo': the context before / takes cognition or motion, got 'Motion'"
    with pytest.raises(UnknownModuleError, match=r"^cannot record 'motion/BallModel': BallModel is in cognition, not in motion$"):
        select(plans, ["motion/BallModel"])
    with pytest.raises(UnknownModuleError, match="the context before / takes cognition or motion, got 'vision'"):
        select(plans, ["vision/BallModel"], strict=False)  # configuration's names too: a wrong context is no missing name


def test_recorded_topics_in_configuration_are_checked_for_their_context() -> None:
    from tafel.core.framework.config import check_config

    check_config({"recording": {"representations": ["motion/FrameInfo"]}}, representations=["FrameInfo"])
    with pytest.raises(ConfigError) as error:
        check_config({"recording": {"representations": ["Motion/FrameInfo"]}}, representations=["FrameInfo"])
    assert str(error.value) == "recording.representations: 'Motion/FrameInfo': the context before / takes cognition or motion, got 'Motion'"
