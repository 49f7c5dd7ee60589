"""The module-testing tools themselves: clock, sequences, history, access, assert_close, strategies, isolation."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from tafel.core import Module, bounded, provides, representation, requires, uses
from tafel.core.framework.representation import fields_of
from tafel.core.testing import ModuleHarness, assert_close, differences, replay_module, strategy_for
from tafel.debug import Canvas, DebugRequest, ModifyValue, Plot
from tafel.modules.modeling.kalman_ball_modeler import KalmanBallModeler
from tafel.modules.modeling.simple_ball_modeler import SimpleBallModeler
from tafel.modules.motion.head_motion import HeadMotion
from tafel.modules.perception.ball_locator import BallLocator
from tafel.representations.infrastructure import FrameInfo
from tafel.representations.modeling import RobotPose
from tafel.representations.motion_control import Odometry
from tafel.representations.perception import BallPercept
from tests.test_cli_runtime import REPO, tafel


@representation
class MtSpeed:
    """A speed in mm/s, and a distance that cannot be negative."""

    value: float = 0.0
    distance: float = bounded(0.0, 9000.0)
    counts: np.ndarray = bounded(0.0, 1.0, array_shape=(3,))
    steps: int = bounded(-5, 5)


@representation
class MtPosition:
    x: float = 0.0  # mm
    time_s: float = 0.0


@representation
class MtUnread:
    value: float = 0.0


@requires(MtSpeed, FrameInfo)
@uses(MtUnread)
@provides(MtPosition)
class MtIntegrator(Module):
    """x += speed * dt, with dt from the frame clock: a module that needs time to pass."""

    def __init__(self) -> None:
        self.last_ns: int | None = None

    def execute(self) -> None:
        now = self.frame_info.time_ns
        if self.last_ns is not None:
            self.mt_position.x += self.mt_speed.value * (now - self.last_ns) * 1e-9
        self.last_ns = now
        self.mt_position.time_s = now * 1e-9


def test_the_harness_owns_the_clock() -> None:
    harness = ModuleHarness(MtIntegrator, MtSpeed(value=300.0))
    assert harness.rate_hz == 30.0 and harness.context == "cognition"
    harness.execute(frames=31)  # 30 periods of 1/30 s
    assert_close(harness[MtPosition].x, 300.0, rel=1e-6)
    assert harness[FrameInfo].frame_number == 31
    harness.advance(2.0)  # the frames that fit into two seconds
    assert harness.frame_number == 91
    assert_close(harness[MtPosition].time_s, 3.0, rel=1e-6)
    assert_close(harness[MtPosition].x, 900.0, rel=1e-6)


def test_a_motion_rate_and_an_explicit_frame_info_take_over_the_clock() -> None:
    harness = ModuleHarness(MtIntegrator, MtSpeed(value=100.0), context="motion")
    assert harness.period_ns == 10_000_000
    harness.execute(frames=101)
    assert_close(harness[MtPosition].x, 100.0, rel=1e-6)
    harness.set(FrameInfo(frame_number=500, time_ns=2_000_000_000))  # a test may set the time itself
    harness.execute()
    assert harness.frame_number == 500 and harness.time_ns == 2_000_000_000
    harness.execute()
    assert harness.time_ns == 2_010_000_000  # and the clock goes on from there


def test_a_harness_context_that_is_no_context_is_an_error_not_30_hz() -> None:
    from tafel.core.framework.values import ValueCheckError

    with pytest.raises(ValueCheckError, match=r"^context takes cognition or motion, got 'Motion'$"):
        ModuleHarness(MtIntegrator, context="Motion")  # ran at cognition's 30 Hz before


def test_sequences_feed_one_value_per_frame_and_the_history_keeps_every_output() -> None:
    harness = ModuleHarness(MtIntegrator)
    harness.feed({MtSpeed: [MtSpeed(value=v) for v in (0.0, 30.0, 60.0, 90.0)]})
    harness.execute()  # all that was fed
    xs = [p.x for p in harness.history(MtPosition)]
    assert_close(xs, [0.0, 1.0, 3.0, 6.0], rel=1e-6)
    with pytest.raises(IndexError, match="the fed sequence of MtSpeed ran out after 4 frames"):
        harness.execute(frames=1)
    with pytest.raises(KeyError, match="does not provide MtSpeed"):
        harness.history(MtSpeed)


def test_setting_a_fed_representation_ends_its_feed_and_the_value_holds() -> None:
    harness = ModuleHarness(MtIntegrator)
    harness.feed({MtSpeed: [MtSpeed(value=30.0)] * 2})
    harness.execute()
    harness.set(MtSpeed(value=0.0))  # the test takes the input over: no "ran out" from here on
    harness.execute(frames=3)
    assert_close([p.x for p in harness.history(MtPosition)], [0.0, 1.0, 1.0, 1.0, 1.0], rel=1e-6)  # it stopped at the set 0
    assert harness.fed_frames_left == 0


def test_sequences_of_different_lengths_or_types_are_errors_naming_the_representation() -> None:
    harness = ModuleHarness(MtIntegrator)
    with pytest.raises(ValueError, match="MtSpeed: 2, MtUnread: 3"):
        harness.feed({MtSpeed: [MtSpeed()] * 2, MtUnread: [MtUnread()] * 3})
    with pytest.raises(TypeError, match="element 1 for MtSpeed is a MtUnread"):
        harness.feed({MtSpeed: [MtSpeed(), MtUnread()]})
    with pytest.raises(TypeError, match="MtIntegrator does not require, use or provide MtOther"):
        ModuleHarness(MtIntegrator).feed({MtOther: [MtOther()]})


@representation
class MtOther:
    value: int = 0


def test_reads_and_writes_pin_a_modules_data_dependencies() -> None:
    harness = ModuleHarness(MtIntegrator)
    with pytest.raises(RuntimeError, match="execute a frame first"):
        harness.reads()
    harness.execute()
    assert harness.reads(MtIntegrator) == {FrameInfo}  # the first frame reads only the clock
    assert harness.writes(MtIntegrator) == {MtPosition}
    harness.execute()
    assert harness.reads() == {FrameInfo, MtSpeed}  # MtUnread is declared but never read
    with pytest.raises(ValueError, match="runs MtIntegrator"):
        harness.reads(_Unrelated)


class _Unrelated:
    pass


def test_assert_close_names_every_differing_field_with_both_values() -> None:
    actual = MtSpeed(value=1.0, distance=5.0, counts=np.array([0.1, 0.2, 0.3]))
    expected = MtSpeed(value=1.1, distance=5.0, counts=np.array([0.1, 0.25, 0.3]))
    with pytest.raises(AssertionError) as failure:
        assert_close(actual, expected, abs=0.01)
    text = str(failure.value)
    assert "2 difference(s)" in text
    assert "MtSpeed.value: 1.0 instead of 1.1" in text
    assert "MtSpeed.counts[1]: 0.2 instead of 0.25" in text
    assert_close(actual, expected, abs=0.11)  # within the tolerance: passes
    assert differences([1.0, 2.0], [1.0]) == ["list: [1.0, 2.0] instead of [1.0] (lengths differ)"]
    assert differences(np.zeros((2, 2)), np.zeros(3)) == ["ndarray: shape (2, 2) instead of (3,)"]


@given(strategy_for(MtSpeed))
def test_bounded_strategies_keep_to_the_declared_ranges(speed: MtSpeed) -> None:
    assert math.isfinite(speed.value) and abs(speed.value) <= 1e6  # no range: finite, sensible
    assert 0.0 <= speed.distance <= 9000.0
    assert speed.counts.shape == (3,) and np.all((speed.counts >= 0.0) & (speed.counts <= 1.0))
    assert -5 <= speed.steps <= 5


@given(strategy_for(MtSpeed, value=st.just(0.0)))
def test_a_field_of_a_strategy_can_be_overridden(speed: MtSpeed) -> None:
    assert speed.value == 0.0


def test_an_override_for_a_field_that_does_not_exist_is_an_error() -> None:
    with pytest.raises(TypeError, match="no field 'valeu'; did you mean 'value'"):
        strategy_for(MtSpeed, valeu=st.just(0.0))
    assert dict((f.name, f.range) for f in fields_of(MtSpeed))["distance"] == (0.0, 9000.0)


@requires(FrameInfo)
@provides(MtPosition)
class MtLeaky(Module):
    """Declares debug outputs a test switches on and pins."""

    draw = DebugRequest("a request a test switches on")
    gain = ModifyValue(1.0, "the factor of x")
    x = Plot("the x it wrote")

    def execute(self) -> None:
        self.mt_position.x = self.gain() * self.frame_info.frame_number
        self.x.add(self.mt_position.x)
        if self.draw:
            self.draw.canvas(Canvas.FIELD).circle(self.mt_position.x, 0.0, 10.0)


# Two tests in this order: the first leaves a pin and a switched-on request, the second must not see them.
def test_isolation_part_one_leaves_debug_state_behind() -> None:
    harness = ModuleHarness(MtLeaky)
    harness.debug.requests["MtLeaky:draw"].on = True
    harness.debug.modifies["MtLeaky:gain"].pinned, harness.debug.modifies["MtLeaky:gain"].pinned_value = True, 5.0
    assert harness.execute(frames=2)[MtPosition].x == 10.0


def test_isolation_part_two_starts_clean() -> None:
    harness = ModuleHarness(MtLeaky)
    assert harness.debug.requests["MtLeaky:draw"].on is False
    assert harness.execute(frames=2)[MtPosition].x == 2.0
    assert harness.debug.drawings() == []


def test_the_harness_shows_the_modules_drawings_and_plots() -> None:
    harness = ModuleHarness(MtLeaky)
    harness.execute(frames=3)
    assert harness.debug.plot_values("MtLeaky:x") == [1.0, 2.0, 3.0]
    harness.module.draw.on = True  # the module's own switch: the harness's context's entry
    harness.execute(frames=1)
    assert harness.debug.drawings(Canvas.FIELD) == [
        {"canvas": "field", "kind": "circle", "points": [4.0, 0.0, 10.0], "color": "black", "width": 1.0, "text": ""}]
    assert harness.debug.drawings("image:top") == []
    assert ModuleHarness(MtLeaky).debug.requests["MtLeaky:draw"].on is False  # another harness: its own


# ------------------------------------------------------------------------------ recorded situations
SITUATION = REPO / "tests" / "data" / "ball_situation.mcap"


def test_replay_feeds_recorded_inputs_with_recorded_times_and_compares_outputs() -> None:
    result = replay_module(BallLocator, SITUATION, start_s=1.0, seconds=1.0)
    assert result.context == "cognition" and len(result.frames) == 30
    times = [frame.time_ns for frame in result.frames]
    # lockstep at 30 and 100 Hz: cognition runs on motion's 10 ms ticks, 3 frames per 100 ms
    assert {b - a for a, b in zip(times, times[1:])} == {30_000_000, 40_000_000}
    assert all(frame.recorded for frame in result.frames) and result.differences() == []


def test_replay_of_a_stateful_module_shows_where_it_differs_from_the_recording() -> None:
    # the situation was recorded before the model followed odometry and read the pose (whether it is lost);
    # the robot stood still in it, and knew where it was
    result = replay_module(KalmanBallModeler, SITUATION, start_s=1.0, seconds=1.0, allow_missing=[Odometry, RobotPose])
    found = result.differences(abs=1.0)
    assert found and found[0].startswith("frame ")  # it starts without the history the recorded one had
    assert result.differences(abs=1e9) == []  # and never strays far


def test_replay_names_what_the_log_lacks() -> None:
    with pytest.raises(ValueError, match=r"does not hold HeadMotionRequest, JointSensorData, CognitionStatus, which HeadMotion reads"):
        replay_module(HeadMotion, SITUATION)
    with pytest.raises(ValueError, match=r"^context takes cognition or motion, got 'vision'$"):
        replay_module(BallLocator, SITUATION, context="vision")
    with pytest.raises(ValueError, match="no cognition frame between 100"):
        replay_module(BallLocator, SITUATION, start_s=100.0)
    result = replay_module(SimpleBallModeler, SITUATION, seconds=0.5)  # BallPercept and FrameInfo are there
    assert len(result.frames) == 15


@pytest.mark.slow
def test_log_slice_cuts_a_situation_that_replays_like_the_original(tmp_path) -> None:
    piece = tmp_path / "piece.mcap"
    done = tafel("log", "slice", str(SITUATION), "--out", str(piece), "--rep", "FrameInfo,BallImagePercept,CameraMatrixBuffer,BallPercept",
                 "--start", "1", "--seconds", "1")
    assert done.returncode == 0, done.stderr
    assert "wrote" in done.stdout
    whole = replay_module(BallLocator, SITUATION, start_s=1.0, seconds=1.0)
    sliced = replay_module(BallLocator, piece)
    assert [f.time_ns for f in sliced.frames] == [f.time_ns for f in whole.frames]
    assert_close(sliced.outputs(BallPercept), whole.outputs(BallPercept))
    wrong = tafel("log", "slice", str(SITUATION), "--out", str(tmp_path / "x.mcap"), "--rep", "BallPercpt")
    assert wrong.returncode == 1 and "did you mean 'BallPercept'" in wrong.stderr
