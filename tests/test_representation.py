"""@representation: defaults, supported types, registry, equality."""

from __future__ import annotations

import dataclasses
import enum

import numpy as np
import pytest

from tafel.core import (
    RepresentationDefinitionError,
    array,
    fields_of,
    get_representation,
    is_representation,
    registered_representations,
    representation,
    values_equal,
)
from tafel.core.framework.representation import copy_into, reset


class Color(enum.Enum):
    ORANGE = 1
    WHITE = 2


@dataclasses.dataclass
class Point:
    x: float = 0.0
    y: float = 0.0


@representation
class RepInner:
    a: int


@representation
class RepAllTypes:
    flag: bool
    count: int
    ratio: float
    label: str
    blob: bytes
    color: Color
    point: Point
    inner: RepInner
    values: list[float]
    points: list[Point]
    image: np.ndarray = array((2, 3), np.uint8)
    free: np.ndarray


def test_every_field_gets_the_default_of_its_type() -> None:
    r = RepAllTypes()
    assert (r.flag, r.count, r.ratio, r.label, r.blob) == (False, 0, 0.0, "", b"")
    assert r.color is Color.ORANGE
    assert r.point == Point() and r.inner == RepInner()
    assert r.values == [] and r.points == []
    assert r.image.shape == (2, 3) and r.image.dtype == np.uint8
    assert r.free.shape == (0,) and r.free.dtype == np.float64


def test_mutable_defaults_are_not_shared() -> None:
    a, b = RepAllTypes(), RepAllTypes()
    a.values.append(1.0)
    a.image[0, 0] = 9
    a.point.x = 5
    assert b.values == [] and b.image[0, 0] == 0 and b.point.x == 0


def test_literal_array_and_list_defaults_become_factories() -> None:
    @representation
    class RepLiteralDefaults:
        v: np.ndarray = np.ones(3, dtype=np.float32)
        items: list[int] = [1, 2]  # noqa: RUF012 - turned into a factory by @representation

    a, b = RepLiteralDefaults(), RepLiteralDefaults()
    a.v[0] = 7
    a.items.append(3)
    assert b.v.tolist() == [1, 1, 1] and b.items == [1, 2]
    (info,) = [f for f in fields_of(RepLiteralDefaults) if f.name == "v"]
    assert info.array is not None and info.array.dtype == np.float32 and info.array.shape == (3,)


def test_field_descriptions_keep_type_information() -> None:
    kinds = {f.name: f.kind for f in fields_of(RepAllTypes)}
    assert kinds == {
        "flag": "bool", "count": "int", "ratio": "float", "label": "str", "blob": "bytes",
        "color": "enum", "point": "nested", "inner": "nested", "values": "list", "points": "list",
        "image": "ndarray", "free": "ndarray",
    }
    values = next(f for f in fields_of(RepAllTypes) if f.name == "values")
    assert values.element is not None and values.element.kind == "float"


def test_registry_finds_classes_by_name() -> None:
    assert get_representation("RepAllTypes") is RepAllTypes
    assert "RepInner" in registered_representations()
    assert is_representation(RepAllTypes) and not is_representation(Point) and not is_representation(RepInner())


def test_unknown_name_suggests_close_names() -> None:
    with pytest.raises(KeyError, match="did you mean 'RepAllTypes'"):
        get_representation("RepAllType")


def test_duplicate_names_fail_naming_both_modules() -> None:
    namespace = {"__name__": "other_package.reps"}
    with pytest.raises(RepresentationDefinitionError) as info:
        exec("from core import representation\n@representation\nclass RepInner:\n    b: int\n", namespace)  # noqa: S102
    message = str(info.value)
    assert "tests.test_representation.RepInner" in message or "test_representation.RepInner" in message
    assert "other_package.reps.RepInner" in message


@pytest.mark.parametrize(
    ("annotation", "expected"),
    [
        ("dict[str, int]", "is not supported"),
        ("list", "write list\\[T\\]"),
        ("list[list[int]]", "lists of lists"),
        ("complex", "is not supported"),
    ],
)
def test_unsupported_field_types_fail_with_the_supported_list(annotation: str, expected: str) -> None:
    source = f"from core import representation\n@representation\nclass RepBadType:\n    f: {annotation}\n"
    with pytest.raises(RepresentationDefinitionError, match=expected):
        exec(source, {"__name__": "bad_types"})  # noqa: S102
    assert "RepBadType" not in registered_representations()


def test_nested_plain_dataclass_without_defaults_is_rejected() -> None:
    @dataclasses.dataclass
    class NoDefault:
        x: float

    with pytest.raises(RepresentationDefinitionError, match="needs a default for field 'x'"):
        representation(type("RepNoDefaultNested", (), {"__annotations__": {"n": NoDefault}, "__module__": __name__}))


def test_underscore_fields_are_rejected() -> None:
    with pytest.raises(RepresentationDefinitionError, match="underscore"):
        representation(type("RepUnderscore", (), {"__annotations__": {"_hidden": int}, "__module__": __name__}))


def test_equality_understands_arrays_and_nesting() -> None:
    a, b = RepAllTypes(), RepAllTypes()
    assert a == b
    b.image[1, 1] = 1
    assert a != b
    b.image = a.image.astype(np.int16)
    assert a != b  # same values, other dtype
    assert values_equal(np.array([np.nan]), np.array([np.nan]))
    assert not values_equal(np.zeros(2), [0.0, 0.0])
    assert values_equal(float("nan"), float("nan"))


def test_repr_summarises_large_arrays() -> None:
    r = RepAllTypes()
    r.free = np.zeros((100, 100))
    assert "array(shape=(100, 100), dtype=float64)" in repr(r)


def test_reset_and_copy_into_keep_identity() -> None:
    a = RepAllTypes(count=3, values=[1.0])
    identity = id(a)
    reset(a)
    assert id(a) == identity and a == RepAllTypes()
    source = RepAllTypes(count=5, values=[2.0])
    copy_into(a, source)
    source.values.append(3.0)
    assert a.count == 5 and a.values == [2.0]
