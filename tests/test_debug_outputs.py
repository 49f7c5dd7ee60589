"""Debug outputs declared by the module: known before anything runs, each context's own, cheap while off."""

from __future__ import annotations

import warnings

import pytest

from tafel.core import Module, ModuleManager, provides, representation, requires
from tafel.debug import Canvas, DebugRequest, ModifyValue, declared_outputs, legacy
from tafel.debug.commands import ContextDebug
from tafel.debug.concepts import NO_PAINTER, DebugState
from tafel.debug.executors import RateMeter, instrument
from tafel.debug.protocol import parse
from tafel.modules.behavior.soccer_behavior import SoccerBehavior
from tafel.modules.behavior.striker import Striker
from tafel.modules.perception.ball_detector import BallDetector
from tafel.representations.infrastructure import FrameInfo
from tests.support.debug_user import DebugUser, DebugUserOutput


def manager_of(*modules: type, name: str = "cognition") -> ModuleManager:
    return ModuleManager(list(modules), name=name, external=[FrameInfo], strict=True)


def run(manager: ModuleManager, frames: int) -> None:
    for _ in range(frames):
        manager.blackboard.set(FrameInfo(frame_number=manager.frame + 1))
        manager.execute()


def ask(debug: ContextDebug, line: str) -> str:
    status, answer = debug.execute(parse(line))
    assert status == "ok", answer
    return str(answer)


def test_a_class_lists_its_debug_outputs_without_running() -> None:
    declared = {a: (d.kind, d.name) for a, d in declared_outputs(BallDetector).items()}
    assert declared == {"draw_candidates": ("request", "BallDetector:draw_candidates"),
                        "segmentation": ("stopwatch", "BallDetector:segmentation")}
    assert declared_outputs(SoccerBehavior)["show_target"].name == "SoccerBehavior:draw_target"  # a name of its own
    assert "modify Kick:behind = 190.0" in declared_outputs(Striker)["kick_tuning"].describe().splitlines()


def test_a_context_lists_its_modules_outputs_before_the_first_frame() -> None:
    debug = ContextDebug("cognition", manager_of(DebugUser))
    assert "off DebugUser:draw  a circle on the field every frame" in ask(debug, "debug_request:list")
    assert ask(debug, "modify:list") == "  DebugUser:gain = 1"
    assert ask(debug, "modify:set -name DebugUser:gain -value 2") == "DebugUser:gain pinned to 2"


def test_two_contexts_do_not_share_switches_pins_plots_or_drawings() -> None:
    first, second = manager_of(DebugUser), manager_of(DebugUser, name="other")
    one, two = ContextDebug("cognition", first), ContextDebug("other", second)
    ask(one, "debug_request:set -name DebugUser:draw -value on")
    ask(one, "modify:set -name DebugUser:gain -value 3")
    run(first, 2)
    run(second, 5)
    assert first.blackboard[DebugUserOutput].value == 6.0 and second.blackboard[DebugUserOutput].value == 5.0
    assert len(first.debug.drawings()) == 2 and second.debug.drawings() == []
    assert first.debug.plot_values("DebugUser:frame") == [1.0, 2.0]
    assert second.debug.plot_values("DebugUser:frame") == [1.0, 2.0, 3.0, 4.0, 5.0]
    assert "off DebugUser:draw" in ask(two, "debug_request:list")


def test_a_module_made_again_keeps_its_contexts_switches_and_pins() -> None:
    manager = manager_of(DebugUser)
    debug = ContextDebug("cognition", manager)
    ask(debug, "debug_request:set -name DebugUser:draw -value on")
    ask(debug, "modify:set -name DebugUser:gain -value 2")
    before = manager.module("DebugUser")
    manager.set_enabled("DebugUser", False)
    manager.set_enabled("DebugUser", True)
    assert manager.module("DebugUser") is not before  # a new instance (as after a hot reload)
    run(manager, 1)
    assert manager.blackboard[DebugUserOutput].value == 2.0 and len(manager.debug.drawings()) == 2


def test_a_request_is_an_attribute_of_the_instance_and_draws_nothing_while_off() -> None:
    manager = manager_of(DebugUser)
    module = manager.module("DebugUser")
    assert module.__dict__["draw"] is manager.debug.requests["DebugUser:draw"]  # no descriptor call per read
    assert not module.draw and module.draw.canvas(Canvas.FIELD) is NO_PAINTER
    module.draw.on = True
    assert module.draw.canvas("field").circle(1, 2, 3) is not NO_PAINTER
    with pytest.raises(ValueError, match="no drawing canvas 'feild'"):
        module.draw.canvas("feild")


def test_modules_sharing_a_prefix_share_the_modify_values_of_their_context() -> None:
    reads = {rep for m in (Striker, SoccerBehavior) for rep in m.requirements().reads()} - {rep for rep in Striker.requirements().provides}
    manager = ModuleManager([Striker, SoccerBehavior], name="cognition", external=reads, providers={"MotionRequest": "Striker"})
    debug = ContextDebug("cognition", manager)
    assert ask(debug, "modify:set -name Kick:behind -value 300") == "Kick:behind pinned to 300"
    striker = manager.module("Striker")
    assert striker.kick_tuning.apply(striker.parameters).behind == 300.0
    manager.set_provider("MotionRequest", "SoccerBehavior")
    soccer = manager.module("SoccerBehavior")
    assert soccer.kick_tuning.apply(soccer.parameters).behind == 300.0


def test_a_parameter_tried_live_outside_its_declared_range_is_refused_not_clamped() -> None:
    reads = {rep for rep in Striker.requirements().reads()} - set(Striker.requirements().provides)
    manager = ModuleManager([Striker], name="cognition", external=reads)
    debug = ContextDebug("cognition", manager)
    entry = manager.debug.modifies["Kick:behind"]
    low, high = entry.bounds
    status, answer = debug.execute(parse(f"modify:set -name Kick:behind -value {high * 10:g}"))
    assert status == "error" and answer == f"Kick:behind takes a number from {low:g} to {high:g} (the parameter's declared range), got {high * 10:g}; nothing pinned"
    assert not entry.pinned
    assert ask(debug, f"modify:set -name Kick:behind -value {high:g}") == f"Kick:behind pinned to {high:g}"


def test_a_module_without_a_manager_has_outputs_of_its_own() -> None:
    @representation
    class DoLoneOutput:
        value: float = 0.0

    @provides(DoLoneOutput)
    class DoLone(Module):
        gain = ModifyValue(2.0)
        draw = DebugRequest()

        def execute(self) -> None:
            pass

    module, other = DoLone(), DoLone()
    assert module.gain() == 2.0 and not module.draw
    module.draw.on = True
    assert not other.draw


@requires(FrameInfo)
@provides(DebugUserOutput)
class DoLegacy(Module):
    """Module code not moved to declarations yet."""

    def execute(self) -> None:
        self.debug_user_output.value = legacy.modify("DoLegacy:gain", 1.0) * self.frame_info.frame_number
        legacy.plot("DoLegacy:frame", self.frame_info.frame_number)
        if legacy.request("DoLegacy:draw"):
            legacy.drawing("robot").circle(0, 0, 1)


def test_the_deprecated_free_functions_use_the_running_context_and_warn() -> None:
    legacy._WARNED.clear()
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        assert legacy.modify("DoLegacy:gain", 1.5) == 1.5  # outside a frame: its value, nothing kept
        first, second = manager_of(DoLegacy), manager_of(DoLegacy, name="other")
        instrument("cognition", first, RateMeter())
        instrument("other", second, RateMeter())
        run(first, 1)
        debug = ContextDebug("cognition", first)
        ask(debug, "modify:set -name DoLegacy:gain -value 4")
        ask(debug, "debug_request:set -name DoLegacy:draw -value on")
        run(first, 1)
        run(second, 2)
    assert first.blackboard[DebugUserOutput].value == 8.0 and second.blackboard[DebugUserOutput].value == 2.0
    assert len(first.debug.drawings(Canvas.ROBOT)) == 1 and second.debug.drawings() == []
    assert second.debug.plot_values("DoLegacy:frame") == [1.0, 2.0]
    assert {str(w.message).split("(")[0] for w in caught if w.category is DeprecationWarning} >= {
        "tafel.debug.modify", "tafel.debug.plot", "tafel.debug.request", "tafel.debug.drawing"}
    assert isinstance(first.debug, DebugState)


@pytest.mark.slow
def test_tafel_modules_lists_every_modules_debug_outputs_before_anything_runs() -> None:
    from tests.test_cli_runtime import tafel

    result = tafel("modules", "--platform", "dummy")
    assert result.returncode == 0, result.stderr
    cognition, motion = result.stdout.split("\nmotion (")
    assert "  debug outputs of Striker:\n    request Striker:draw_target  where the striker wants to stand" in cognition
    assert "    modify Kick:behind = 190.0" in cognition
    assert "    modify WalkingEngine:step_duration = 0.25" in motion and "    plot WalkingEngine:phase" in motion


def _router(*contexts: str):
    from tafel.debug.executors import LocalExecutor
    from tafel.debug.router import DebugRouter

    router = DebugRouter()
    for context in contexts:
        router.add_context(context, LocalExecutor(ContextDebug(context, manager_of(DebugUser, name=context))))
    return router


@pytest.mark.parametrize("line", ["modules:list -context Motion", "debug_request:list -context vision",
                                  "representation:print FrameInfo -context cognition2", "modules:list -context cognition,motion"])
def test_a_context_that_is_no_context_is_an_error_not_an_empty_answer(line: str) -> None:
    # modules:list -context Motion answered nothing (every context said "not me", merged to ""): an error now
    [(is_error, answer)] = _router("cognition", "motion").handle_batch([parse(line)])
    given = line.split("-context", 1)[1].strip()
    assert is_error and answer == f"-context takes cognition or motion, got {given!r}"


def test_a_context_the_program_does_not_run_is_an_error_naming_those_it_runs() -> None:
    [(is_error, answer)] = _router("cognition").handle_batch([parse("modules:list -context motion")])
    assert is_error and answer == "-context motion: this program runs no motion context; it runs cognition"
    [(is_error, answer)] = _router("cognition", "motion").handle_batch([parse("debug_request:list -context motion")])
    assert not is_error and "DebugUser:draw" in str(answer)


def test_a_context_asked_directly_refuses_a_name_that_is_no_context() -> None:
    status, answer = ContextDebug("cognition", manager_of(DebugUser)).execute(parse("modify:list -context COGNITION"))
    assert (status, answer) == ("error", "-context takes cognition or motion, got 'COGNITION'")
