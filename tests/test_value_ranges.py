"""Every number a client can set has a range, and what names a folder or a choice is checked like one.

The attacks of the second security issue: ``representation:set -name ChestButton -field presses -value
1000000000000`` (a module looped that often), ``{"presses": 1e308}`` (a 309-digit integer), 1e308 into
parameters and fields, a field of view of 0, ``parameter:set KeyframePlayer.motions_dir /any/dir``.
"""

from __future__ import annotations

import dataclasses
import json
import math
import typing
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from tafel.core.framework.manager import ModuleManager
from tafel.core.framework.module import Module
from tafel.core.framework.parameters import ParameterError, make_parameters, parameter_hints, parameters_class, set_parameter
from tafel.core.framework.representation import fields_of, registered_representations
from tafel.core.framework.validation import MAX_MAGNITUDE, ValueCheckError, check_field, check_number
from tafel.core.testing import ModuleHarness
from tafel.debug.commands import CommandError, ContextDebug
from tafel.debug.protocol import parse
from tafel.modules.communication.game_state_provider import GameStateProvider
from tafel.modules.motion.keyframe_player import KeyframePlayer
from tafel.modules.motion.keyframes import SHIPPED_MOTIONS
from tafel.modules.perception.image_geometry import camera_views, focal_lengths
from tafel.representations.game import GameControllerPackets, GameState, Penalty, State
from tafel.representations.infrastructure import FrameInfo
from tafel.representations.motion import CameraMatrix, CameraMatrixBuffer, ChestButton, InertialSensorData, JointSensorData
from tafel.representations.motion_control import FallState, MotionRequest, MotionSelection
from tafel.representations.perception import CameraImageBottom, CameraImageTop
from tafel.tools.launch.program import discover_modules
from tafel.tools.simulation.stepped_program import SteppedProgram

#: floats no field or parameter takes: not finite, or beyond any range a robot needs
BAD_FLOATS = (math.nan, math.inf, -math.inf, 1e308, -1e308, 2 * MAX_MAGNITUDE, -2 * MAX_MAGNITUDE)
#: whole numbers none takes: beyond 64 bits (a log's int64), and a float's largest as a whole number
BAD_INTS = (2**63, -(2**63) - 1, 10**23, int(1e308))


def answer(debug: ContextDebug, line: str) -> tuple[str, str]:
    """(status, text) of one command line, as a client's would be answered."""
    status, text = debug.execute(parse(line).as_text())
    return status, str(text)


# ------------------------------------------------------------------------------------ natural ranges
@pytest.mark.parametrize("value, kind", [*((v, "float") for v in BAD_FLOATS), *((v, "int") for v in BAD_INTS), (1e308, "int")],
                         ids=lambda v: f"{v:.3g}" if isinstance(v, (int, float)) else str(v))
def test_a_number_without_a_declared_range_keeps_to_its_types_natural_one(value: Any, kind: str) -> None:
    with pytest.raises(ValueCheckError, match="finite|at most 1e\\+12|fits in 64 bits"):
        check_number(value, "Thing.x", kind=kind)


def test_the_ends_of_the_natural_ranges_are_taken() -> None:
    assert check_number(2**63 - 1, "Thing.n", kind="int") == 2**63 - 1
    assert check_number(-(2**63), "Thing.n", kind="int") == -(2**63)
    assert check_number(MAX_MAGNITUDE, "Thing.x") == MAX_MAGNITUDE and check_number(-MAX_MAGNITUDE, "Thing.x") == -MAX_MAGNITUDE


def test_a_huge_whole_number_is_refused_without_being_printed_whole() -> None:
    with pytest.raises(ValueCheckError) as refused:
        check_number(10**5000, "ChestButton.presses", kind="int")
    assert "about 5001 digits" in str(refused.value) and len(str(refused.value)) < 200


# --------------------------------------------------------------------- every field and every parameter
def numeric_fields(cls: type, prefix: str = "") -> Iterator[tuple[type, str, str, Any]]:
    """(owner class, field name, dotted path, field info) of every number, numeric array and list of numbers,
    through nested dataclasses."""
    for info in fields_of(cls):
        path = f"{prefix}{info.name}"
        if info.kind in ("int", "float") or (info.kind == "ndarray" and info.array is not None and info.array.dtype.kind == "f") \
                or (info.kind == "list" and info.element is not None and info.element.kind in ("int", "float")):
            yield cls, info.name, path, info
        elif info.kind == "nested":
            yield from numeric_fields(info.type, f"{path}.")
        elif info.kind == "list" and info.element is not None and info.element.kind == "nested":
            yield from numeric_fields(info.element.type, f"{path}[].")


def bad_value(info: Any, kind: str, data: st.DataObject) -> Any:
    """A value the field must refuse, drawn: one bad number, alone or inside an array or list."""
    number = data.draw(st.sampled_from(BAD_INTS if kind == "int" else BAD_FLOATS))
    if info.kind == "ndarray":
        shape = tuple(2 if n is None else n for n in info.array.shape)
        array = np.zeros(shape)
        array.flat[data.draw(st.integers(0, max(0, array.size - 1)))] = number
        return array
    if info.kind == "list":
        return [0, number]
    return number


def all_modules() -> list[type]:
    discover_modules()

    def below(cls: type) -> Iterator[type]:
        for sub in cls.__subclasses__():
            yield sub
            yield from below(sub)

    return sorted({m for m in below(Module) if parameters_class(m) is not None and m.__module__.startswith("tafel.modules")},
                  key=lambda m: m.__name__)


@settings(max_examples=15, deadline=None)
@given(st.data())
def test_no_field_of_any_representation_takes_a_non_finite_or_huge_number(data: st.DataObject) -> None:
    """Every representation the shipped modules define: camera fields of view, Odometry, InertialModel,
    CameraMatrix and the rest; the check every client path goes through (representation:set and :override)."""
    discover_modules()
    checked = 0
    for name, rep in sorted(registered_representations().items()):
        for owner, field_name, path, info in numeric_fields(rep):
            kind = info.element.kind if info.kind == "list" else info.kind
            value = bad_value(info, kind, data)
            with pytest.raises(ValueCheckError):
                check_field(owner, field_name, value, f"{name}.{path}")
            checked += 1
    assert checked > 100, checked  # the walk found the fields


@settings(max_examples=15, deadline=None)
@given(st.data())
def test_no_parameter_of_any_module_takes_a_non_finite_or_huge_number_from_a_client(data: st.DataObject) -> None:
    """InertialFilter, KalmanBallModeler, LookAtBallBehavior, HeadMotion, StandMotion and every other
    module's numbers: refused as text (what parameter:set gets) and as numbers (configuration)."""
    modules = all_modules()
    assert {"InertialFilter", "KalmanBallModeler", "LookAtBallBehavior", "HeadMotion", "StandMotion"} <= {m.__name__ for m in modules}
    for module in modules:
        instance = make_parameters(module)
        hints = parameter_hints(type(instance))
        for field in dataclasses.fields(instance):
            hint = hints[field.name]
            element = typing.get_args(hint)[0] if typing.get_origin(hint) is list else hint
            if element not in (int, float):
                continue
            number = data.draw(st.sampled_from(BAD_INTS if element is int else BAD_FLOATS))
            value = [number] if hint is not element else number
            before = getattr(instance, field.name)
            for given_value in (value, str(number) if hint is element else value):
                with pytest.raises(ParameterError):
                    set_parameter(module.__name__, instance, field.name, given_value, client=True)
            assert getattr(instance, field.name) == before


@pytest.fixture(scope="module")
def program() -> Iterator[SteppedProgram]:
    """The shipped program on the dummy platform, stepped here, with a debug executor per context."""
    stepped = SteppedProgram("dummy", {})
    stepped.run(0.2)
    yield stepped
    stepped.close()


def debug_of(program: SteppedProgram, context: str) -> ContextDebug:
    return ContextDebug(context, program.runtime.runners[context].manager)


def frames(program: SteppedProgram) -> dict[str, int]:
    return {context: runner.manager.frame for context, runner in program.runtime.runners.items()}


@settings(max_examples=10, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(st.data())
def test_through_the_debug_commands_nothing_non_finite_or_huge_gets_in_and_the_loops_go_on(program: SteppedProgram,
                                                                                             data: st.DataObject) -> None:
    """Every number of every representation on the running program's blackboards (representation:set with
    -field, and :override with JSON) and of every module's parameters (parameter:set): refused, with a
    message that names it; afterwards both loops still run their frames without a module failing."""
    refused = 0
    for context, runner in program.runtime.runners.items():
        debug = debug_of(program, context)
        blackboard = runner.manager.blackboard
        for name in sorted(blackboard.names()):
            for _, _, path, info in numeric_fields(type(blackboard.find(name))):
                if "[]" in path:
                    continue  # elements of lists of records travel only as protobuf bytes (checked like the rest)
                kind = info.element.kind if info.kind == "list" else info.kind
                value = bad_value(info, kind, data)
                plain = value.tolist() if isinstance(value, np.ndarray) else value
                text = json.dumps(plain, separators=(",", ":"))
                status, said = answer(debug, f"representation:set -name {name} -context {context} -field {path} -value {text}")
                assert status == "error" and name in said, (name, path, text[:80], said)
                if "." not in path:
                    fields = json.dumps({path: plain}, separators=(",", ":"))
                    status, said = answer(debug, f"representation:override -name {name} -context {context} -fields {fields}")
                    assert status == "error", (name, path, said)
                refused += 1
        for module in runner.manager.order:
            parameters = runner.manager.module(module).parameters
            if parameters is None:
                continue
            for field in dataclasses.fields(parameters):
                current = getattr(parameters, field.name)
                if isinstance(current, bool) or not isinstance(current, (int, float)):
                    continue
                number = data.draw(st.sampled_from(BAD_INTS if isinstance(current, int) else BAD_FLOATS))
                status, said = answer(debug, f"parameter:set -module {module} -name {field.name} -value {number!r}")
                assert status == "error" and f"{module}.{field.name}" in said, (module, field.name, said)
                assert getattr(parameters, field.name) == current
                refused += 1
    assert refused > 100, refused
    before = frames(program)
    program.run(0.1)
    after = frames(program)
    assert all(after[c] > before[c] for c in before), (before, after)
    for runner in program.runtime.runners.values():
        assert runner.manager.errors() == {}, runner.manager.errors()


# ------------------------------------------------------------------------------- the chest button
def test_the_chest_button_attack_freezes_nothing(program: SteppedProgram, monkeypatch: pytest.MonkeyPatch) -> None:
    """The issue's command: a trillion presses are taken (a count fits), but a frame carries out at most
    three of them; 1e308 and more than 64 bits are refused."""
    motion, cognition = debug_of(program, "motion"), debug_of(program, "cognition")
    assert answer(motion, 'representation:override -name ChestButton -fields {"presses":1e308}')[0] == "error"
    assert answer(motion, f"representation:set -name ChestButton -context motion -field presses -value {2**63}")[0] == "error"
    assert answer(cognition, f"representation:set -name GameState -field ignored_packets -value {10**23}")[0] == "error"
    presses: list[int] = []
    real_press = GameStateProvider.press

    def counted(game: GameState) -> None:
        presses.append(1)
        if len(presses) > 10:  # before the fix: a trillion; stop it here instead of waiting for ever
            raise AssertionError("GameStateProvider pressed more than ten times: a loop a client's number bounds")
        real_press(game)

    monkeypatch.setattr(GameStateProvider, "press", staticmethod(counted))
    status, said = answer(motion, "representation:set -name ChestButton -context motion -field presses -value 1000000000000")
    assert status == "ok", said
    before = frames(program)
    program.run(0.1)
    assert frames(program)["cognition"] > before["cognition"]
    assert 1 <= len(presses) <= 3, len(presses)
    assert all(runner.manager.errors() == {} for runner in program.runtime.runners.values())


def carry_out(presses: int, start: State, penalty: Penalty, bounded: bool) -> tuple[State, Penalty, int, bool]:
    """The game state after ``presses`` presses in manual mode, one by one or as the provider does."""
    harness = ModuleHarness(GameStateProvider, GameControllerPackets(team_number=1, player_number=2),
                            parameters={"start_state": start.name})
    harness.execute()
    game = harness.blackboard[GameState]
    game.own_player().penalty = penalty
    if bounded:
        harness.set(ChestButton(presses=presses))
        game = harness.execute()[GameState]
    else:
        for count in range(1, presses + 1):
            harness.set(ChestButton(presses=count))
            game = harness.execute()[GameState]
    player = game.own_player()
    return game.state, player.penalty, player.secs_till_unpenalised, game.manual


@settings(max_examples=40, deadline=None)
@given(presses=st.integers(0, 12), start=st.sampled_from([State.initial, State.playing]),
       penalty=st.sampled_from([Penalty.none, Penalty.manual]))
def test_many_presses_in_one_frame_do_what_they_do_one_by_one(presses: int, start: State, penalty: Penalty) -> None:
    assert carry_out(presses, start, penalty, bounded=True) == carry_out(presses, start, penalty, bounded=False)


# -------------------------------------------------------------------------------- fields of view
def test_a_field_of_view_of_zero_projects_nothing_and_one_beyond_a_camera_is_refused() -> None:
    top = CameraImageTop(horizontal_fov=1.06, vertical_fov=0.0)  # what representation:set -field vertical_fov -value 0 leaves
    buffer = CameraMatrixBuffer.of(CameraMatrix(valid=True), CameraMatrix(valid=True))
    assert list(camera_views(top, CameraImageBottom(), buffer)) == []  # not known: nothing projected, nothing divided by 0
    with pytest.raises(ValueError, match="describe no camera"):
        focal_lengths(320, 240, 1.06, 0.0)
    for fov in (3.5, -0.1, 1e308):
        with pytest.raises(ValueCheckError, match="vertical_fov takes a finite number from 0 to 3, got " + f"{fov:g}".replace("+", "[+]")):
            check_field(CameraImageTop, "vertical_fov", fov)


# ------------------------------------------------------------------- strings that name folders and choices
KEYFRAME_INPUTS = [MotionSelection, MotionRequest, FallState, JointSensorData, InertialSensorData, FrameInfo]


def keyframe_debug(configured: str | None = None) -> tuple[ContextDebug, ModuleManager]:
    parameters = {"KeyframePlayer": {"motions_dir": configured}} if configured is not None else None
    manager = ModuleManager([KeyframePlayer], external=KEYFRAME_INPUTS, parameters=parameters)
    return ContextDebug("motion", manager), manager


def test_a_client_cannot_point_a_folder_parameter_outside_the_configured_folders(tmp_path: Path) -> None:
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    (elsewhere / "secret_plans.toml").write_text("x = 1\n")
    debug, manager = keyframe_debug()
    for outside in (str(elsewhere), "/", str(SHIPPED_MOTIONS / ".." / "..")):
        status, said = answer(debug, f'parameter:set -module KeyframePlayer -name motions_dir -value "{outside}"')
        assert status == "error" and "takes a folder inside" in said and "secret_plans" not in said, said
        assert manager.module("KeyframePlayer").parameters.motions_dir == ""
    assert answer(debug, f"parameter:set -module KeyframePlayer -name motions_dir -value {SHIPPED_MOTIONS}")[0] == "ok"


def test_a_folder_configuration_names_is_one_clients_may_stay_within(tmp_path: Path) -> None:
    (tmp_path / "elsewhere").mkdir()
    (tmp_path / "motions").mkdir()
    (tmp_path / "motions" / "link-out").symlink_to(tmp_path / "elsewhere")
    tmp_path = tmp_path / "motions"
    (tmp_path / "kicks").mkdir()
    debug, manager = keyframe_debug(str(tmp_path))  # what the user typed: any folder
    assert manager.module("KeyframePlayer").parameters.motions_dir == str(tmp_path)
    status, said = answer(debug, f"parameter:set -module KeyframePlayer -name motions_dir -value {tmp_path / 'kicks'}")
    assert status == "ok", said
    assert manager.module("KeyframePlayer").parameters.motions_dir == str((tmp_path / "kicks").resolve())
    assert answer(debug, f"parameter:set -module KeyframePlayer -name motions_dir -value {tmp_path.parent}")[0] == "error"
    # a link inside the folder that leads out of it is outside
    assert answer(debug, f"parameter:set -module KeyframePlayer -name motions_dir -value {tmp_path / 'link-out'}")[0] == "error"
    assert debug.parameter_values("KeyframePlayer") == {"motions_dir": str((tmp_path / "kicks").resolve())}  # stored, it loads


def test_a_choice_parameter_takes_only_its_choices_at_start_at_set_and_at_store() -> None:
    with pytest.raises(ParameterError, match="start_state takes one of initial, ready, set, playing, finished, standby, got 'bogus'"):
        make_parameters(GameStateProvider, {"start_state": "bogus"})  # configuration: --set parameters.GameStateProvider.start_state=bogus
    manager = ModuleManager([GameStateProvider], external=[GameControllerPackets, FrameInfo, ChestButton])
    debug = ContextDebug("cognition", manager)
    status, said = answer(debug, "parameter:set -module GameStateProvider -name start_state -value bogus")
    assert status == "error" and "takes one of initial" in said, said
    assert answer(debug, "parameter:set -module GameStateProvider -name start_state -value PLAYING") == (
        "ok", "GameStateProvider.start_state = playing")
    manager.module("GameStateProvider").parameters.start_state = "kickoff"  # a bug wrote it directly
    with pytest.raises(CommandError, match="not stored: parameter GameStateProvider.start_state takes one of"):
        debug.parameter_values("GameStateProvider")
