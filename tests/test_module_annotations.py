"""Class-level annotations of a module (what it reads and writes, its parameters) are checked against its
decorators, so that what a type checker sees cannot drift from what the manager wires."""

from __future__ import annotations

import dataclasses
from typing import Any

import pytest

from tafel.core import Module, ModuleDefinitionError, ModuleManager, provides, representation, requires, uses
from tafel.core.testing import run_module


@representation
class AnnInput:
    value: float


@representation
class AnnPrevious:
    value: float


@representation
class AnnOutput:
    value: float


@dataclasses.dataclass
class AnnSharedParameters:
    gain: float = 2.0


def test_matching_annotations_are_accepted_and_the_module_runs() -> None:
    @requires(AnnInput)
    @uses(AnnPrevious)
    @provides(AnnOutput)
    class AnnDoubler(Module):
        ann_input: AnnInput
        ann_previous: AnnPrevious
        ann_output: AnnOutput

        @dataclasses.dataclass
        class Parameters:
            gain: float = 2.0

        parameters: Parameters

        def execute(self) -> None:
            self.ann_output.value = self.parameters.gain * self.ann_input.value + self.ann_previous.value

    assert AnnDoubler.requirements().provides == (AnnOutput,)
    board = run_module(AnnDoubler, AnnInput(value=1.5), AnnPrevious(value=0.25), parameters={"gain": 3.0})
    assert board[AnnOutput].value == pytest.approx(4.75)


def test_annotations_are_optional() -> None:
    @requires(AnnInput)
    @provides(AnnOutput)
    class AnnUnannotated(Module):
        def execute(self) -> None:
            self.ann_output.value = self.ann_input.value  # type: ignore[attr-defined]

    assert run_module(AnnUnannotated, AnnInput(value=4.0))[AnnOutput].value == 4.0


def test_an_annotation_of_another_type_than_the_declared_representation_is_refused_at_class_creation() -> None:
    with pytest.raises(ModuleDefinitionError, match=r"AnnWrongType annotates ann_output: float but ann_output is the "
                                                    r"AnnOutput it declares in @provides; annotate ann_output: AnnOutput"):
        @provides(AnnOutput)
        class AnnWrongType(Module):
            ann_output: float

            def execute(self) -> None:
                pass


def test_a_representation_annotated_under_another_name_is_refused_at_class_creation() -> None:
    with pytest.raises(ModuleDefinitionError, match=r"AnnMisnamed annotates output: AnnOutput, but a module reaches "
                                                    r"AnnOutput as ann_output; annotate ann_output: AnnOutput"):
        @provides(AnnOutput)
        class AnnMisnamed(Module):
            output: AnnOutput

            def execute(self) -> None:
                pass


def test_an_annotated_representation_that_is_not_declared_is_refused_before_anything_runs() -> None:
    @requires(AnnInput)
    class AnnUndeclared(Module):
        ann_input: AnnInput
        ann_output: AnnOutput

        def execute(self) -> None:
            pass

    message = (r"AnnUndeclared annotates ann_output: AnnOutput but does not @requires/@uses/@provides AnnOutput; "
               r"add @requires\(AnnOutput\) or remove the annotation")
    with pytest.raises(ModuleDefinitionError, match=message):
        AnnUndeclared.requirements()
    with pytest.raises(ModuleDefinitionError, match=message):
        ModuleManager([AnnUndeclared], external=[AnnInput])


def test_a_subclass_is_checked_against_the_declarations_it_inherits() -> None:
    @provides(AnnOutput)
    class AnnBase(Module):
        def execute(self) -> None:
            pass

    with pytest.raises(ModuleDefinitionError, match=r"AnnDerived annotates ann_output: AnnInput"):
        class AnnDerived(AnnBase):
            ann_output: AnnInput


def test_an_unresolvable_annotation_of_a_declared_representation_is_refused() -> None:
    with pytest.raises(ModuleDefinitionError, match=r"annotates ann_input: NoSuchName \(which cannot be resolved at run "
                                                    r"time\) but ann_input is the AnnInput it declares in @requires"):
        @requires(AnnInput)
        class AnnUnresolvable(Module):
            ann_input: NoSuchName  # type: ignore[name-defined]  # noqa: F821

            def execute(self) -> None:
                pass


def test_a_representation_local_to_a_function_is_matched_by_its_name() -> None:
    @representation
    class AnnLocal:
        value: int

    @provides(AnnLocal)
    class AnnLocalWriter(Module):
        ann_local: AnnLocal  # the string "AnnLocal" cannot be evaluated from the file's globals

        def execute(self) -> None:
            self.ann_local.value = 7

    assert run_module(AnnLocalWriter)[AnnLocal].value == 7


def test_annotations_that_are_objects_not_strings_are_checked_too() -> None:
    def execute(self: Any) -> None:
        pass

    raw = type("AnnRawAnnotations", (Module,), {"__annotations__": {"ann_input": float}, "execute": execute})
    with pytest.raises(ModuleDefinitionError, match=r"annotates ann_input: float but ann_input is the AnnInput"):
        requires(AnnInput)(raw)
    with pytest.raises(ModuleDefinitionError, match=r"AnnRawMisnamed annotates source: AnnInput, but a module reaches"):
        type("AnnRawMisnamed", (Module,), {"__annotations__": {"source": AnnInput}, "execute": execute})


def test_parameters_must_name_the_modules_parameters_class() -> None:
    with pytest.raises(ModuleDefinitionError, match=r"AnnOtherParameters annotates parameters: AnnSharedParameters but "
                                                    r"its parameters are .*AnnOtherParameters.Parameters; annotate "
                                                    r"parameters: Parameters"):
        class AnnOtherParameters(Module):
            @dataclasses.dataclass
            class Parameters:
                gain: float = 1.0

            parameters: AnnSharedParameters

    with pytest.raises(ModuleDefinitionError, match=r"AnnNoParameters annotates parameters: AnnSharedParameters but has "
                                                    r"no Parameters dataclass"):
        class AnnNoParameters(Module):
            parameters: AnnSharedParameters


def test_parameters_may_be_a_class_defined_elsewhere_or_a_base_of_the_modules_own() -> None:
    class AnnSharedGain(Module):
        Parameters = AnnSharedParameters
        parameters: AnnSharedParameters

    class AnnMoreGain(AnnSharedGain):
        @dataclasses.dataclass
        class Parameters(AnnSharedParameters):
            offset: float = 0.0

    assert AnnMoreGain.requirements().reads() == ()
    assert issubclass(AnnMoreGain.Parameters, AnnSharedParameters)
