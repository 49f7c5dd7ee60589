"""The run_module fixture, ModuleHarness and strategy_for."""

from __future__ import annotations

import enum
from dataclasses import dataclass

import numpy as np
import pytest
from hypothesis import given, settings

from tafel.core import Module, array, provides, representation, requires, uses, values_equal
from tafel.core.testing import ModuleHarness, strategy_for


class TsMode(enum.Enum):
    IDLE = 0
    RUN = 1


@dataclass
class TsPoint:
    x: float = 0.0


@representation
class TsInput:
    value: int
    scale: float = 1.0


@representation
class TsFeedback:
    value: int


@representation
class TsOutput:
    value: float
    history: list[int]


@representation
class TsEverything:
    flag: bool
    n: int
    f: float
    s: str
    b: bytes
    mode: TsMode
    point: TsPoint
    points: list[TsPoint]
    image: np.ndarray = array((2, None, 3), np.uint8)
    vector: np.ndarray = array((3,), np.float32)


@requires(TsInput)
@uses(TsFeedback)
@provides(TsOutput)
class TsModule(Module):
    def execute(self) -> None:
        self.ts_output.value = self.ts_input.value * self.ts_input.scale + self.ts_feedback.value
        self.ts_output.history = [*self.ts_output.history, self.ts_input.value]


def test_run_module_fixture_runs_one_module_strictly(run_module) -> None:
    bb = run_module(TsModule, TsInput(value=2, scale=1.5), frames=3)
    assert bb[TsOutput].value == 3.0 and bb[TsOutput].history == [2, 2, 2]
    assert bb[TsFeedback] == TsFeedback()  # not given: default-constructed


def test_inputs_are_copied(run_module) -> None:
    given_input = TsInput(value=1)
    bb = run_module(TsModule, given_input)
    assert bb[TsInput] is not given_input and bb[TsInput] == given_input


def test_run_module_rejects_undeclared_inputs(run_module) -> None:
    with pytest.raises(TypeError, match="TsModule does not require, use or provide TsEverything; it declares"):
        run_module(TsModule, TsEverything())
    with pytest.raises(TypeError, match="representation instances"):
        run_module(TsModule, 3)
    with pytest.raises(ValueError, match="frames must be at least 1"):
        run_module(TsModule, frames=0)


def test_module_errors_propagate_in_tests(run_module) -> None:
    @provides(TsOutput)
    class Failing(Module):
        def execute(self) -> None:
            raise ZeroDivisionError("boom")

    with pytest.raises(ZeroDivisionError):
        run_module(Failing)


def test_harness_runs_frame_by_frame(module_harness) -> None:
    harness = module_harness(TsModule, TsInput(value=1))
    harness.execute()
    harness.set(TsInput(value=5), TsFeedback(value=10))
    harness.execute(frames=2)
    assert harness[TsOutput].history == [1, 5, 5] and harness[TsOutput].value == 15
    assert harness.module is harness.manager.module("TsModule")


def test_harness_parameters() -> None:
    @provides(TsOutput)
    class WithParameters(Module):
        @dataclass
        class Parameters:
            offset: float = 0.0

        def execute(self) -> None:
            self.ts_output.value = self.parameters.offset

    assert ModuleHarness(WithParameters, parameters={"offset": 2.5}).execute()[TsOutput].value == 2.5


@settings(max_examples=100, deadline=None)
@given(strategy_for(TsEverything))
def test_strategy_draws_valid_instances(rep: TsEverything) -> None:
    assert isinstance(rep, TsEverything)
    assert rep.image.dtype == np.uint8 and rep.image.shape[0] == 2 and rep.image.shape[2] == 3
    assert 0 <= rep.image.shape[1] <= 4
    assert rep.vector.dtype == np.float32 and rep.vector.shape == (3,)
    assert np.isfinite(rep.vector).all() and rep.f == rep.f
    assert isinstance(rep.mode, TsMode) and all(isinstance(p, TsPoint) for p in rep.points)
    assert values_equal(rep, rep)
