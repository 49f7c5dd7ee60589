"""Module declarations and the read-only protection of required and used representations."""

from __future__ import annotations

import copy
import dataclasses
from typing import Any

import numpy as np
import pytest

from tafel.core import (
    Module,
    ModuleDefinitionError,
    ModuleManager,
    ReadOnlyArray,
    ReadOnlyRepresentationError,
    array,
    provides,
    representation,
    requires,
    snake_case,
    uses,
)
from tafel.core.framework.access import ArrayFieldError


@dataclasses.dataclass
class AccVec:
    x: float = 0.0
    y: float = 0.0


@representation
class AccSource:
    n: int
    pos: AccVec
    samples: np.ndarray = array((4,), np.float32)
    items: list[float]
    vecs: list[AccVec]

    def norm(self) -> float:
        return float(np.hypot(self.pos.x, self.pos.y))

    def bump(self) -> None:
        self.n += 1


@representation
class AccSink:
    value: float


@representation
class IMUData:
    gyro: float


@provides(AccSource)
class AccWriter(Module):
    def execute(self) -> None:
        self.acc_source.n += 1
        self.acc_source.pos.x = 3.0
        self.acc_source.pos.y = 4.0
        self.acc_source.samples = np.arange(4, dtype=np.float32)
        self.acc_source.vecs = [AccVec(1.0, 2.0)]


def make_reader(action):
    @requires(AccSource)
    @provides(AccSink)
    class AccReader(Module):
        def execute(self) -> None:
            action(self)

    return AccReader


def run_reader(action) -> ModuleManager:
    manager = ModuleManager([make_reader(action), AccWriter], strict=True)
    manager.execute()
    return manager


def test_snake_case_names() -> None:
    assert snake_case("BallPercept") == "ball_percept"
    assert snake_case("CameraMatrixTop") == "camera_matrix_top"
    assert snake_case("IMUData") == "imu_data"
    assert snake_case("HeadMotionRequest") == "head_motion_request"
    assert snake_case("X") == "x"


def test_requirements_are_static_and_inherited() -> None:
    @requires(AccSource)
    @uses(IMUData)
    @provides(AccSink)
    class Base(Module):
        pass

    class Derived(Base):
        pass

    req = Derived.requirements()
    assert req.requires == (AccSource,) and req.uses == (IMUData,) and req.provides == (AccSink,)
    assert set(req.attribute_names()) == {"acc_source", "imu_data", "acc_sink"}


def test_declaring_a_non_representation_fails() -> None:
    with pytest.raises(ModuleDefinitionError, match="takes representation classes"):
        requires(AccVec)


def test_decorating_a_non_module_fails() -> None:
    with pytest.raises(ModuleDefinitionError, match="decorates Module subclasses"):
        requires(AccSource)(AccVec)


@pytest.mark.parametrize(("first", "second"), [(requires, provides), (uses, requires), (provides, uses)])
def test_declaring_one_representation_twice_fails(first, second) -> None:
    with pytest.raises(ModuleDefinitionError, match="both in"):
        second(AccSource)(first(AccSource)(type("Twice", (Module,), {})))


def test_attribute_name_clash_fails() -> None:
    with pytest.raises(ModuleDefinitionError, match="already defined"):
        requires(AccSource)(type("Clash", (Module,), {"acc_source": lambda self: None}))


def test_unbound_module_explains_how_to_test_it() -> None:
    reader = make_reader(lambda self: None)()
    with pytest.raises(AttributeError, match="run_module"):
        _ = reader.acc_source


def test_reads_see_the_providers_values_and_methods_work() -> None:
    seen = {}

    def action(self) -> None:
        seen["n"] = self.acc_source.n
        seen["norm"] = self.acc_source.norm()
        seen["samples"] = self.acc_source.samples.sum()
        seen["vec"] = self.acc_source.vecs[0].y
        self.acc_sink.value = self.acc_source.pos.x

    manager = run_reader(action)
    assert seen == {"n": 1, "norm": 5.0, "samples": 6.0, "vec": 2.0}
    assert manager.blackboard[AccSink].value == 3.0


@pytest.mark.parametrize(
    ("action", "path"),
    [
        (lambda self: setattr(self.acc_source, "n", 5), "AccSource.n"),
        (lambda self: setattr(self.acc_source.pos, "x", 5.0), "AccSource.pos.x"),
        (lambda self: self.acc_source.samples.__setitem__(0, 1.0), "AccSource.samples[...]"),
        (lambda self: self.acc_source.samples.__iadd__(1.0), "AccSource.samples[...]"),
        (lambda self: np.add(self.acc_source.samples, 1, out=self.acc_source.samples), "AccSource.samples"),
        (lambda self: self.acc_source.samples[1:3].fill(0), "AccSource.samples[...]"),
        (lambda self: self.acc_source.items.append(1.0), "AccSource.items"),
        (lambda self: setattr(self.acc_source.vecs[0], "x", 1.0), "AccSource.vecs[0].x"),
        (lambda self: self.acc_source.bump(), "AccSource.n"),
        (lambda self: delattr(self.acc_source, "n"), "AccSource.n"),
    ],
)
def test_writes_to_required_representations_fail_naming_module_and_representation(action, path) -> None:
    with pytest.raises(ReadOnlyRepresentationError) as info:
        run_reader(action)
    assert info.value.module == "AccReader"
    assert info.value.representation == "AccSource"
    assert path in str(info.value)
    assert "AccReader wrote to" in str(info.value)


def test_writes_to_used_representations_fail() -> None:
    @uses(AccSource)
    class User(Module):
        def execute(self) -> None:
            self.acc_source.pos.y = 1.0

    with pytest.raises(ReadOnlyRepresentationError, match="User wrote to AccSource.pos.y"):
        ModuleManager([User, AccWriter], strict=True).execute()


def test_replacing_a_representation_attribute_fails() -> None:
    def action(self) -> None:
        self.acc_sink = AccSink()

    with pytest.raises(AttributeError, match="cannot be replaced; assign its fields"):
        run_reader(action)


def test_read_only_arrays_compute_into_plain_arrays() -> None:
    results = {}

    def action(self) -> None:
        doubled = self.acc_source.samples * 2
        doubled[0] = 100.0  # a result is the module's own array
        results["doubled"] = doubled
        results["copy"] = copy.deepcopy(self.acc_source)

    run_reader(action)
    assert type(results["doubled"]) is np.ndarray and results["doubled"][0] == 100.0
    private = results["copy"]
    private.n = 42  # a deep copy is writeable and detached
    assert type(private) is AccSource


def test_read_only_array_slices_stay_read_only() -> None:
    base = np.arange(6.0)
    from tafel.core.framework.access import read_only_array

    view = read_only_array(base, "M", "R", ".f")
    part = view[2:4]
    assert isinstance(part, ReadOnlyArray)
    with pytest.raises(ReadOnlyRepresentationError):
        part[0] = 1.0
    assert base[2] == 2.0


def test_provider_writes_reach_the_blackboard_and_unknown_fields_fail() -> None:
    @provides(AccSink)
    class Typo(Module):
        def execute(self) -> None:
            self.acc_sink.valeu = 1.0

    with pytest.raises(AttributeError, match="valeu"):
        ModuleManager([Typo], strict=True).execute()


def test_module_may_keep_its_own_state() -> None:
    @provides(AccSink)
    class OwnStateCounter(Module):  # a name no other test file's module has: module names are global
        def __init__(self) -> None:
            self.count = 0

        def execute(self) -> None:
            self.count += 1
            self.acc_sink.value = self.count

    manager = ModuleManager([OwnStateCounter], strict=True)
    for _ in range(3):
        manager.execute()
    assert manager.blackboard[AccSink].value == 3 and manager.module("OwnStateCounter").count == 3


@representation
class ShapedArrays:
    joints: np.ndarray = array((25,))
    image: np.ndarray = array((4, 6, 3), np.uint8)
    free: np.ndarray = array((None, 2))


@provides(ShapedArrays)
class WritesShapes(Module):
    value: Any = None
    field_name = "joints"

    def execute(self) -> None:
        setattr(self.shaped_arrays, self.field_name, self.value)


@pytest.mark.parametrize(("field_name", "value", "message"), [
    ("joints", [1.0, 2.0, 3.0], r"module WritesShapes wrote ShapedArrays.joints as an array of shape \(3,\) and dtype float64; "
                                r"the field declares shape \(25,\) and dtype float64"),
    ("image", np.zeros((4, 6, 3), np.float32), r"ShapedArrays.image as an array of shape \(4, 6, 3\) and dtype float32; "
                                               r"the field declares shape \(4, 6, 3\) and dtype uint8"),
    ("free", np.zeros((3, 3)), r"declares shape \(any, 2\)"),
])
def test_declared_array_shapes_and_dtypes_are_enforced_on_write(field_name: str, value: Any, message: str) -> None:
    manager = ModuleManager([WritesShapes], strict=True)
    module = manager.module("WritesShapes")
    module.field_name, module.value = field_name, value
    with pytest.raises(ArrayFieldError, match=message):
        manager.execute()


def test_fitting_arrays_and_lists_are_accepted_and_converted() -> None:
    manager = ModuleManager([WritesShapes], strict=True)
    module = manager.module("WritesShapes")
    module.field_name, module.value = "joints", list(range(25))  # ints fit a float array
    manager.execute()
    assert manager.blackboard[ShapedArrays].joints.dtype == np.float64
    module.field_name, module.value = "free", np.ones((7, 2))
    manager.execute()
    assert manager.blackboard[ShapedArrays].free.shape == (7, 2)


def test_a_wrong_array_is_a_module_error_and_the_previous_value_stays() -> None:
    manager = ModuleManager([WritesShapes])
    module = manager.module("WritesShapes")
    module.field_name, module.value = "joints", np.ones(25)
    manager.execute()
    module.value = np.ones(24)
    manager.execute()  # not strict: logged and counted, the frame goes on
    assert manager.errors()["WritesShapes"][0] == 1
    assert manager.blackboard[ShapedArrays].joints.shape == (25,) and manager.blackboard[ShapedArrays].joints[0] == 1.0


def test_two_module_classes_with_one_name_fail_at_definition_naming_both() -> None:
    namespace: dict[str, Any] = {"__name__": "first_place"}
    exec("from tafel.core import Module\nclass TwinModuleName(Module):\n    pass\n", namespace)  # noqa: S102
    other: dict[str, Any] = {"__name__": "second_place"}
    with pytest.raises(ModuleDefinitionError, match=r"two module classes are named 'TwinModuleName': "
                                                     r"first_place.TwinModuleName and second_place.TwinModuleName"):
        exec("from tafel.core import Module\nclass TwinModuleName(Module):\n    pass\n", other)  # noqa: S102


@representation
class HarnessCopied:
    samples: np.ndarray = array((3,))
    names: list[str]


@requires(HarnessCopied)
@provides(ShapedArrays)
class ReadsCopied(Module):
    def execute(self) -> None:
        pass


@provides(HarnessCopied)
class ScribblesOnItsOutput(Module):
    def execute(self) -> None:
        self.harness_copied.samples[0] = 99.0  # in place
        self.harness_copied.names.append("changed")


def test_the_harness_never_changes_the_tests_own_objects() -> None:
    from tafel.core.testing import ModuleHarness, run_module

    mine = HarnessCopied(samples=np.array([1.0, 2.0, 3.0]), names=["a"])
    harness = ModuleHarness(ScribblesOnItsOutput, mine)
    harness.execute()
    assert harness[HarnessCopied].samples[0] == 99.0
    assert mine.samples.tolist() == [1.0, 2.0, 3.0] and mine.names == ["a"]
    run_module(ReadsCopied, mine)
    assert mine.samples.tolist() == [1.0, 2.0, 3.0]
