"""The option framework (modules/behavior/options/framework.py) on the mocked blackboard: states,
transitions driven by time, calls with parameters, the ActivationGraph, and clear errors."""

from __future__ import annotations

from dataclasses import dataclass

import pytest

from tafel.core import Module, provides, requires
from tafel.core.testing import ModuleHarness
from tafel.debug.commands import ContextDebug
from tafel.debug.protocol import parse
from tafel.modules.behavior.options import Next, Option, OptionError, OptionRunner, common, state
from tafel.representations.behavior import ActivationGraph, OptionGraph
from tafel.representations.infrastructure import FrameInfo
from tafel.representations.modeling import BallModel
from tafel.representations.motion_control import MotionRequest, MotionType


class Walk(Option["OptionsDemo"]):
    """Walk at a speed."""

    @dataclass
    class Args:
        speed: float

    args: Args

    @state(initial=True)
    def walking(self, b: OptionsDemo) -> Next:
        """Walk."""
        b.motion_request.motion, b.motion_request.walk_x = MotionType.walk, self.args.speed


class Demo(Option["OptionsDemo"]):
    """Wait a second, walk until four seconds in the option, then stand for good; a ball restarts it all."""

    calls = (Walk,)

    @common(to=("waiting",))
    def ball(self, b: OptionsDemo) -> Next:
        return "waiting" if b.ball_model.valid else None

    @state(initial=True, to=("walking",))
    def waiting(self, b: OptionsDemo) -> Next:
        """Stand a second."""
        if self.time_in_state >= 1.0 and not b.ball_model.valid:
            return "walking"
        b.motion_request.motion = MotionType.stand

    @state(to=("done",))
    def walking(self, b: OptionsDemo) -> Next:
        """Walk until the option is four seconds old."""
        if self.time_in_option >= 4.0:
            return "done"
        self.call(Walk, speed=100.0 + 100.0 * self.time_in_state)

    @state(final=True)
    def done(self, b: OptionsDemo) -> Next:
        """Stand: done."""
        b.motion_request.motion = MotionType.stand


@requires(FrameInfo, BallModel)
@provides(MotionRequest, ActivationGraph)
class OptionsDemo(Module):
    """Runs Demo once a frame."""

    def __init__(self) -> None:
        self.runner = OptionRunner(Demo)

    def execute(self) -> None:
        self.runner.run(self, self.frame_info.time_s, self.activation_graph)


def path(harness: ModuleHarness) -> list[tuple[str, str]]:
    return [(o.name, o.state) for o in harness[ActivationGraph].options]


def test_time_in_state_and_in_option_drive_the_transitions() -> None:
    harness = ModuleHarness(OptionsDemo)
    harness.advance(0.9)
    assert path(harness) == [("Demo", "waiting")] and harness[MotionRequest].motion is MotionType.stand
    harness.advance(0.2)  # a second in "waiting"
    assert path(harness) == [("Demo", "walking"), ("Walk", "walking")] and harness[MotionRequest].motion is MotionType.walk
    harness.advance(2.0)
    assert harness[MotionRequest].motion is MotionType.walk
    harness.advance(1.0)  # four seconds in the option
    assert path(harness) == [("Demo", "done")] and harness[MotionRequest].motion is MotionType.stand
    harness.advance(5.0)
    assert path(harness) == [("Demo", "done")]  # final: it stays


def test_the_activation_graph_lists_the_active_options_root_down_with_times_depths_and_parameters() -> None:
    harness = ModuleHarness(OptionsDemo)
    harness.advance(1.5)
    root, walk = harness[ActivationGraph].options
    assert (root.name, root.depth, walk.name, walk.depth) == ("Demo", 0, "Walk", 1)
    assert root.time_in_option == pytest.approx(harness.time_s)
    assert root.time_in_state == pytest.approx(harness.time_s - 1.0, abs=0.05)  # entered "walking" at 1 s
    assert walk.time_in_option == pytest.approx(root.time_in_state)  # called since then
    assert walk.parameters == f"speed={100.0 + 100.0 * root.time_in_state:.4g}"
    assert harness[MotionRequest].walk_x == pytest.approx(100.0 + 100.0 * root.time_in_state)
    assert harness[ActivationGraph].status_text() == "Demo/walking > Walk/walking"


def test_common_transitions_come_first_and_a_reactivated_option_starts_again() -> None:
    harness = ModuleHarness(OptionsDemo)
    harness.advance(1.5)
    harness.set(BallModel(valid=True))
    harness.execute()
    assert path(harness) == [("Demo", "waiting")]
    assert harness[ActivationGraph].options[0].time_in_state == 0.0
    harness.set(BallModel(valid=False))
    harness.advance(1.1)
    walk = harness[ActivationGraph].options[1]
    assert walk.name == "Walk" and walk.time_in_option < 0.1  # called anew: its clock starts again


def test_representation_print_shows_the_activation_graph() -> None:
    harness = ModuleHarness(OptionsDemo)
    harness.advance(1.5)
    status, text = ContextDebug("cognition", harness.manager).execute(parse("representation:print -name ActivationGraph"))
    assert status == "ok" and "Demo" in text and "walking" in text and "speed=" in text


def test_the_static_graph_lists_options_states_transitions_and_calls() -> None:
    graph = OptionRunner(Demo).graph()
    assert isinstance(graph, OptionGraph) and graph.root == "Demo" and [o.name for o in graph.options] == ["Demo", "Walk"]
    demo = graph.options[0]
    assert [(s.name, s.initial, s.final, s.to) for s in demo.states] == [
        ("waiting", True, False, ["walking"]), ("walking", False, False, ["done"]), ("done", False, True, [])]
    assert demo.common == ["waiting"] and demo.calls == ["Walk"] and demo.states[0].doc == "Stand a second."


# ------------------------------------------------------------------------------------------ errors
def run_once(root: type[Option[object]]) -> None:
    OptionRunner(root).run(object(), 0.0)


def test_a_transition_or_call_that_was_not_declared_is_an_error_naming_it() -> None:
    class Sneaky(Option[object]):
        @state(initial=True, to=("b",))
        def a(self, b: object) -> Next:
            return "c"

        @state
        def b(self, b: object) -> Next:
            return None

        @state
        def c(self, b: object) -> Next:
            return None

    with pytest.raises(OptionError, match=r"Sneaky, state a, returned 'c', which it does not declare \(to: b\)"):
        run_once(Sneaky)

    class Caller(Option[object]):
        @state(initial=True)
        def a(self, b: object) -> Next:
            self.call(Walk, speed=1.0)

    with pytest.raises(OptionError, match="calls Walk, which it does not declare: add it to Caller.calls"):
        run_once(Caller)


def test_wrong_parameters_a_loop_of_transitions_and_a_second_call_are_errors() -> None:
    class BadArgs(Option[object]):
        calls = (Walk,)

        @state(initial=True)
        def a(self, b: object) -> Next:
            self.call(Walk, pace=1.0)

    with pytest.raises(OptionError, match="option Walk takes speed; was given pace"):
        run_once(BadArgs)

    class Loop(Option[object]):
        @state(initial=True, to=("b",))
        def a(self, b: object) -> Next:
            return "b"

        @state(to=("a",))
        def b(self, b: object) -> Next:
            return "a"

    with pytest.raises(OptionError, match="go round in a loop"):
        run_once(Loop)

    class Twice(Option[object]):
        calls = (Walk,)

        @state(initial=True)
        def a(self, b: object) -> Next:
            self.call(Walk, speed=1.0)
            self.call(Walk, speed=2.0)

    with pytest.raises(OptionError, match="Walk is called twice in one frame"):
        OptionRunner(Twice).run(type("B", (), {"motion_request": MotionRequest()})(), 0.0)


def test_options_written_wrongly_fail_where_they_are_defined() -> None:
    with pytest.raises(OptionError, match="needs exactly one initial state, has 0"):
        class NoStart(Option[object]):
            @state
            def a(self, b: object) -> Next:
                return None

    with pytest.raises(OptionError, match="a may go to nowhere, which is no state; it has a"):
        class Nowhere(Option[object]):
            @state(initial=True, to=("nowhere",))
            def a(self, b: object) -> Next:
                return None

    with pytest.raises(OptionError, match=r"give a tuple of state names, e.g. to=\('b',\)"):
        state(to="b")
