"""ModuleManager: order, configuration errors, reconfiguration, failures, transparency."""

from __future__ import annotations

import logging
import re
import typing
from dataclasses import dataclass

import pytest

from tafel.core import (
    Blackboard,
    ConflictingProvidersError,
    DependencyCycleError,
    MissingProviderError,
    Module,
    ModuleDefinitionError,
    ModuleGraphError,
    ModuleManager,
    UnknownModuleError,
    provides,
    prune_unsatisfiable,
    representation,
    requires,
    uses,
)
from tafel.core.framework.parameters import ParameterError, set_parameter


@representation
class MgrImage:
    frame: int


@representation
class MgrPercept:
    value: int


@representation
class MgrModel:
    value: int
    source: str


@representation
class MgrDecision:
    value: int


@provides(MgrImage)
class MgrCamera(Module):
    def execute(self) -> None:
        self.mgr_image.frame += 1


@requires(MgrImage)
@provides(MgrPercept)
class MgrDetector(Module):
    def execute(self) -> None:
        self.mgr_percept.value = self.mgr_image.frame * 10


@requires(MgrPercept)
@provides(MgrModel)
class MgrPlainModel(Module):
    def execute(self) -> None:
        self.mgr_model.value = self.mgr_percept.value
        self.mgr_model.source = "plain"


@requires(MgrPercept)
@provides(MgrModel)
class MgrFilterModel(Module):
    def __init__(self) -> None:
        self.frames = 0

    def execute(self) -> None:
        self.frames += 1
        self.mgr_model.value = self.mgr_percept.value + 1
        self.mgr_model.source = "filter"


@requires(MgrModel)
@provides(MgrDecision)
class MgrBehavior(Module):
    def execute(self) -> None:
        self.mgr_decision.value = self.mgr_model.value


PIPELINE = [MgrBehavior, MgrFilterModel, MgrPlainModel, MgrDetector, MgrCamera]


def test_order_follows_requires_edges() -> None:
    manager = ModuleManager(PIPELINE, providers={"MgrModel": "MgrPlainModel"})
    assert manager.order == ["MgrCamera", "MgrDetector", "MgrPlainModel", "MgrBehavior"]
    manager.execute()
    assert manager.blackboard[MgrDecision].value == 10
    assert manager.blackboard[MgrModel].source == "plain"


def test_ties_keep_the_given_order() -> None:
    @provides(MgrPercept)
    class First(Module):
        def execute(self) -> None: ...

    @provides(MgrDecision)
    class Second(Module):
        def execute(self) -> None: ...

    assert ModuleManager([Second, First]).order == ["Second", "First"]
    assert ModuleManager([First, Second]).order == ["First", "Second"]


def test_missing_provider_names_module_and_representation() -> None:
    with pytest.raises(MissingProviderError) as info:
        ModuleManager([MgrDetector])
    assert "MgrDetector requires MgrImage, but no module provides it" in str(info.value)
    assert isinstance(info.value, ModuleGraphError)


def test_missing_provider_mentions_a_disabled_provider() -> None:
    manager = ModuleManager([MgrCamera, MgrDetector])
    with pytest.raises(MissingProviderError, match="MgrCamera would, but is disabled"):
        manager.set_enabled("MgrCamera", False)


def test_external_representations_need_no_provider() -> None:
    manager = ModuleManager([MgrDetector], external=[MgrImage])
    manager.blackboard[MgrImage].frame = 4
    manager.execute()
    assert manager.blackboard[MgrPercept].value == 40


def test_external_and_module_provider_conflict() -> None:
    with pytest.raises(ConflictingProvidersError, match="provided from outside .* and by MgrCamera"):
        ModuleManager([MgrCamera], external=[MgrImage])


def test_two_providers_need_a_choice() -> None:
    with pytest.raises(ConflictingProvidersError) as info:
        ModuleManager(PIPELINE)
    message = str(info.value)
    assert "MgrModel is provided by MgrFilterModel and MgrPlainModel" in message
    assert 'providers={"MgrModel": "MgrFilterModel"}' in message
    assert 'MgrModel = "MgrFilterModel" under [cognition.providers] or [motion.providers]' in message  # the sections configuration has


def test_unknown_module_in_providers_suggests_close_names() -> None:
    with pytest.raises(UnknownModuleError, match="did you mean 'MgrPlainModel'"):
        ModuleManager(PIPELINE, providers={"MgrModel": "MgrPlainModle"})


def test_providers_for_unknown_representation() -> None:
    with pytest.raises(UnknownModuleError, match="no module in this manager provides a representation"):
        ModuleManager(PIPELINE, providers={"MgrModle": "MgrPlainModel"})


def test_providers_choosing_a_module_that_does_not_provide_it() -> None:
    with pytest.raises(UnknownModuleError, match="MgrDetector does not provide MgrModel; modules that do"):
        ModuleManager(PIPELINE, providers={"MgrModel": "MgrDetector"})


def test_duplicate_module_names_and_non_modules_are_rejected() -> None:
    with pytest.raises(ModuleDefinitionError, match="two module classes are named 'MgrCamera'"):
        type("MgrCamera", (Module,), {"__module__": "elsewhere"})  # fails where it is defined
    with pytest.raises(ModuleDefinitionError, match="take Module subclasses"):
        ModuleManager([object])


def test_cycle_is_reported_as_a_path() -> None:
    @requires(MgrDecision)
    @provides(MgrPercept)
    class CycleA(Module):
        pass

    @requires(MgrPercept)
    @provides(MgrDecision)
    class CycleB(Module):
        pass

    with pytest.raises(DependencyCycleError) as info:
        ModuleManager([CycleA, CycleB])
    message = str(info.value)
    assert "CycleA.MgrPercept -> CycleB.MgrDecision -> CycleA" in message
    assert "@uses" in message
    assert info.value.cycle == [("CycleA", "MgrPercept"), ("CycleB", "MgrDecision")]


def test_uses_breaks_cycles_and_reads_the_previous_frame() -> None:
    @uses(MgrDecision)
    @provides(MgrPercept)
    class Feedback(Module):
        def execute(self) -> None:
            self.mgr_percept.value = self.mgr_decision.value + 1

    @requires(MgrPercept)
    @provides(MgrDecision)
    class Decider(Module):
        def execute(self) -> None:
            self.mgr_decision.value = self.mgr_percept.value * 2

    manager = ModuleManager([Decider, Feedback])
    assert manager.order == ["Feedback", "Decider"]
    manager.execute()
    manager.execute()
    assert manager.blackboard[MgrDecision].value == 6  # (0+1)*2 = 2, then (2+1)*2


def test_set_provider_switches_and_resets_the_representation() -> None:
    manager = ModuleManager(PIPELINE, providers={"MgrModel": "MgrPlainModel"})
    manager.execute()
    assert manager.blackboard[MgrModel].source == "plain"
    model = manager.blackboard[MgrModel]
    manager.set_provider("MgrModel", "MgrFilterModel")
    assert model is manager.blackboard[MgrModel]  # identity kept, value reset
    assert model.source == "" and model.value == 0
    assert "MgrFilterModel" in manager.order and "MgrPlainModel" not in manager.order
    manager.execute()
    assert model.source == "filter" and manager.module("MgrFilterModel").frames == 1


def test_newly_enabled_module_gets_a_fresh_instance() -> None:
    manager = ModuleManager(PIPELINE, providers={"MgrModel": "MgrFilterModel"})
    manager.execute()
    first = manager.module("MgrFilterModel")
    manager.set_provider("MgrModel", "MgrPlainModel")
    manager.set_provider("MgrModel", "MgrFilterModel")
    assert manager.module("MgrFilterModel") is not first
    assert manager.module("MgrFilterModel").frames == 0


def test_failed_reconfiguration_changes_nothing() -> None:
    manager = ModuleManager(PIPELINE, providers={"MgrModel": "MgrPlainModel"})
    manager.execute()
    before = (manager.order, manager.providers, manager.disabled, manager.module("MgrPlainModel"))
    value = manager.blackboard[MgrModel].value
    with pytest.raises(UnknownModuleError):
        manager.set_provider("MgrModel", "Nope")
    with pytest.raises(MissingProviderError):
        manager.set_enabled("MgrDetector", False)
    with pytest.raises(UnknownModuleError):
        manager.set_enabled("MgrDetectr", False)
    assert (manager.order, manager.providers, manager.disabled, manager.module("MgrPlainModel")) == before
    assert manager.blackboard[MgrModel].value == value


def test_failing_constructor_during_reconfiguration_changes_nothing() -> None:
    @requires(MgrPercept)
    @provides(MgrModel)
    class Fragile(Module):
        def __init__(self) -> None:
            raise RuntimeError("no calibration file")

    manager = ModuleManager([*PIPELINE, Fragile], providers={"MgrModel": "MgrPlainModel"})
    manager.execute()
    with pytest.raises(ModuleDefinitionError, match="constructing Fragile failed: no calibration file"):
        manager.set_provider("MgrModel", "Fragile")
    assert manager.provider_of("MgrModel") == "MgrPlainModel"
    assert manager.blackboard[MgrModel].source == "plain"


def test_disabling_an_alternative_and_enabling_again() -> None:
    manager = ModuleManager(PIPELINE, providers={"MgrModel": "MgrPlainModel"})
    manager.set_enabled("MgrFilterModel", False)
    assert not manager.is_enabled("MgrFilterModel") and manager.is_enabled("MgrPlainModel")
    manager.set_enabled("MgrFilterModel", True)
    assert manager.alternatives("MgrModel") == ["MgrFilterModel", "MgrPlainModel"]
    assert manager.provider_of("MgrModel") == "MgrPlainModel"


def test_exception_is_logged_counted_and_outputs_keep_last_values(caplog) -> None:
    @provides(MgrModel)
    class Flaky(Module):
        def __init__(self) -> None:
            self.frame = 0

        def execute(self) -> None:
            self.frame += 1
            self.mgr_model.value = self.frame
            self.mgr_model.source = "half"
            if self.frame == 2:
                raise ValueError("bad frame")
            self.mgr_model.source = "good"

    manager = ModuleManager([Flaky, MgrBehavior], name="cognition")
    with caplog.at_level(logging.ERROR, logger="tafel.cognition"):
        manager.execute()
        manager.execute()
    assert manager.blackboard[MgrModel].value == 1 and manager.blackboard[MgrModel].source == "good"
    assert manager.blackboard[MgrDecision].value == 1  # the frame went on
    assert manager.errors() == {"Flaky": (1, "ValueError: bad frame")}
    assert manager.timings()["Flaky"].errors == 1
    record = caplog.records[-1].getMessage()
    assert "Flaky failed in frame 2" in record and "Traceback" in record and "bad frame" in record
    manager.execute()
    assert manager.blackboard[MgrModel].value == 3
    manager.set_enabled("MgrBehavior", False)
    manager.set_enabled("Flaky", False)  # switched off, its instance gone: its failure still counts for the run's summary
    assert manager.errors() == {"Flaky": (1, "ValueError: bad frame")}


def test_strict_mode_propagates() -> None:
    @provides(MgrModel)
    class Broken(Module):
        def execute(self) -> None:
            raise KeyError("x")

    with pytest.raises(KeyError):
        ModuleManager([Broken], strict=True).execute()


def test_timings_and_access_are_recorded() -> None:
    manager = ModuleManager(PIPELINE, providers={"MgrModel": "MgrPlainModel"})
    for _ in range(3):
        manager.execute()
    timing = manager.timings()["MgrDetector"]
    assert timing.frames == 3 and timing.max_us >= timing.mean_us > 0 and timing.last_us > 0
    access = manager.access()
    assert access["MgrPercept"] == {"readers": ["MgrPlainModel"], "writers": ["MgrDetector"]}
    assert access["MgrImage"] == {"readers": ["MgrDetector"], "writers": ["MgrCamera"]}


def test_access_reflects_the_last_frame_only() -> None:
    @requires(MgrImage)
    @provides(MgrPercept)
    class Sometimes(Module):
        def execute(self) -> None:
            if self.mgr_image.frame == 1:
                self.mgr_percept.value = 1

    manager = ModuleManager([MgrCamera, Sometimes])
    manager.execute()
    assert manager.access()["MgrPercept"]["writers"] == ["Sometimes"]
    manager.execute()
    assert manager.access()["MgrPercept"]["writers"] == []
    assert manager.access()["MgrImage"]["readers"] == ["Sometimes"]


def test_graph_export_as_data_and_dot() -> None:
    manager = ModuleManager(PIPELINE, providers={"MgrModel": "MgrPlainModel"})
    graph = manager.graph()
    assert graph["order"] == manager.order
    assert graph["representations"]["MgrModel"] == {
        "provider": "MgrPlainModel", "alternatives": ["MgrFilterModel", "MgrPlainModel"],
    }
    filter_entry = next(m for m in graph["modules"] if m["name"] == "MgrFilterModel")
    assert filter_entry["enabled"] and not filter_entry["active"]
    dot = manager.to_dot()
    assert dot.startswith("digraph tafel {")
    assert '"cognition:MgrPlainModel" -> "cognition:MgrModel";' in dot
    assert '"cognition:MgrModel" -> "cognition:MgrBehavior";' in dot
    assert '"cognition:MgrFilterModel" [shape=box, style=dashed' in dot


def test_blackboard_lookup_errors_are_helpful() -> None:
    manager = ModuleManager([MgrCamera])
    with pytest.raises(KeyError, match="MgrPercept is not on this blackboard"):
        manager.blackboard[MgrPercept]
    with pytest.raises(KeyError, match="did you mean 'MgrImage'"):
        manager.blackboard.get("MgrImag")
    bb = Blackboard()
    bb.ensure(MgrImage)
    bb.set(MgrImage(frame=3))
    assert bb.get("MgrImage").frame == 3 and len(bb) == 1 and MgrImage in bb


def test_module_lookup_errors() -> None:
    manager = ModuleManager(PIPELINE, providers={"MgrModel": "MgrPlainModel"})
    with pytest.raises(UnknownModuleError, match="did you mean"):
        manager.module("MgrPlainModle")
    with pytest.raises(KeyError, match="is not running"):
        manager.module("MgrFilterModel")
    with pytest.raises(UnknownModuleError):
        manager.provider_of("Nothing")


def test_parameters_are_typed_and_checked() -> None:
    @provides(MgrModel)
    class Tunable(Module):
        @dataclass
        class Parameters:
            gain: float = 1.0
            steps: int = 2
            name: str = "a"
            active: bool = True

        def execute(self) -> None:
            self.mgr_model.value = int(self.parameters.gain * self.parameters.steps)

    manager = ModuleManager([Tunable], parameters={"Tunable": {"gain": 3, "steps": "4", "active": "false"}})
    manager.execute()
    assert manager.blackboard[MgrModel].value == 12
    assert manager.module("Tunable").parameters.active is False
    with pytest.raises(ParameterError, match="Tunable has no parameter 'gian'; did you mean 'gain'"):
        ModuleManager([Tunable], parameters={"Tunable": {"gian": 1}})
    with pytest.raises(ParameterError, match="Tunable.steps takes a whole number that fits in 64 bits, got 'many'"):
        ModuleManager([Tunable], parameters={"Tunable": {"steps": "many"}})
    with pytest.raises(UnknownModuleError):
        ModuleManager([Tunable], parameters={"Tunabel": {"gain": 1}})


def test_each_parameters_class_is_checked_by_its_own_types_worked_out_once(monkeypatch: pytest.MonkeyPatch) -> None:
    """A client's parameter:set checks the value against the field's type: the types are worked out once per class
    (anew each time, the value-range tests took 10 s), and a class of the same name defined again with other types
    (a module reloaded) is checked by its own."""
    @dataclass
    class FloatGain:
        gain: float = 1.0

    @dataclass
    class IntGain:
        gain: int = 1

    resolved: list[type] = []
    real = typing.get_type_hints
    monkeypatch.setattr(typing, "get_type_hints", lambda cls, *args, **kwargs: resolved.append(cls) or real(cls, *args, **kwargs))
    instance = FloatGain()
    for value in ("0.5", 2, "2.5"):
        set_parameter("Tunable", instance, "gain", value, client=True)
    assert instance.gain == 2.5 and resolved == [FloatGain]
    with pytest.raises(ParameterError, match="Tunable.gain takes a whole number"):
        set_parameter("Tunable", IntGain(), "gain", "2.5", client=True)
    assert resolved == [FloatGain, IntGain]


def test_prune_unsatisfiable_is_transitive() -> None:
    pruned = prune_unsatisfiable([MgrDetector, MgrPlainModel, MgrBehavior], external=[])
    assert pruned == {"MgrDetector": ["MgrImage"], "MgrPlainModel": ["MgrPercept"], "MgrBehavior": ["MgrModel"]}
    assert prune_unsatisfiable([MgrDetector, MgrPlainModel], external=[MgrImage]) == {}


@provides(MgrPercept)
class MgrAlwaysFails(Module):
    def execute(self) -> None:
        raise ValueError("broken sensor model")


def test_a_module_failing_every_frame_logs_its_traceback_once_then_a_line_a_second(caplog, monkeypatch) -> None:
    import tafel.core.framework.manager as manager_module

    now = [1000.0]
    monkeypatch.setattr(manager_module.time, "monotonic", lambda: now[0])
    manager = ModuleManager([MgrAlwaysFails])
    with caplog.at_level("ERROR", logger="tafel.cognition"):
        for _ in range(250):  # 250 frames within 2.5 s
            manager.execute()
            now[0] += 0.01
    records = [r.getMessage() for r in caplog.records]
    assert sum("Traceback" in m for m in records) == 1 and "broken sensor model" in records[0]
    assert len(records) == 3, records  # the traceback, then one line each second
    assert re.search(r"failed 10[01] more times \(10[12] in all\)", records[1]) and "ValueError: broken sensor model" in records[1]
    assert manager.errors()["MgrAlwaysFails"][0] == 250
