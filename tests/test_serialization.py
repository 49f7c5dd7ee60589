"""Automatic protobuf serialization: round trips, arrays, schema evolution, errors."""

from __future__ import annotations

import dataclasses
import enum

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tafel.core import array, registered_representations, representation, values_equal
from tafel.core.logs.serialization import (
    SerializationError,
    check_compatible,
    deserialize,
    field_number,
    file_descriptor_set,
    message_name,
    schema_of,
    serialize,
)
from tafel.core.testing import strategy_for
from tafel.tools.launch.program import discover_modules

discover_modules()  # every representation of the project takes part in the round-trip property


class SerColor(enum.Enum):
    RED = "r"
    BLUE = "b"


@dataclasses.dataclass
class SerPoint:
    x: float = 0.0
    label: SerColor = SerColor.RED


@representation
class SerAll:
    flag: bool
    count: int
    ratio: float
    text: str
    blob: bytes
    color: SerColor
    point: SerPoint
    points: list[SerPoint]
    numbers: list[float]
    names: list[str]
    colors: list[SerColor]
    image: np.ndarray = array((2, None, 3), np.uint8)
    matrix: np.ndarray = array((3, 3), np.float32)
    arrays: list[np.ndarray]


@settings(max_examples=60)
@given(st.data())
def test_every_registered_representation_round_trips_exactly(data) -> None:
    registry = registered_representations()
    cls = data.draw(st.sampled_from(sorted(registry)), label="representation")
    rep = data.draw(strategy_for(registry[cls]))
    back = deserialize(registry[cls], serialize(rep))
    assert values_equal(back, rep), (rep, back)


@given(strategy_for(SerAll))
def test_all_field_types_round_trip(rep: SerAll) -> None:
    back = deserialize(SerAll, serialize(rep))
    assert back == rep
    assert back.image.dtype == rep.image.dtype and back.image.shape == rep.image.shape
    back.image.fill(1)  # decoded arrays are writeable and independent


def test_arrays_are_stored_as_bytes_with_dtype_and_shape() -> None:
    rep = SerAll(image=np.arange(2 * 4 * 3, dtype=np.uint8).reshape(2, 4, 3))
    schema = schema_of(SerAll)
    ndarray = next(m for m in schema.message_type[0].nested_type if m.name == "NDArray")
    assert [(f.name, f.type) for f in ndarray.field] == [("dtype", 9), ("shape", 3), ("data", 12)]
    data = serialize(rep)
    assert rep.image.tobytes() in data  # raw bytes, not repeated scalars
    big_endian = SerAll(matrix=np.arange(9, dtype=">f4").reshape(3, 3))
    back = deserialize(SerAll, serialize(big_endian))
    assert back.matrix.dtype == np.dtype(">f4") and np.array_equal(back.matrix, big_endian.matrix)


def test_schema_is_a_self_contained_file() -> None:
    schema = schema_of(SerAll)
    assert schema.package == "tafel" and schema.message_type[0].name == "SerAll"
    assert message_name(SerAll) == "tafel.SerAll"
    nested = {m.name for m in schema.message_type[0].nested_type}
    assert nested == {"SerPoint", "NDArray"}
    assert file_descriptor_set(SerAll)  # what MCAP stores


def test_field_numbers_are_stable_and_valid() -> None:
    numbers = [field_number(f"field_{i}") for i in range(2000)]
    assert all(1 <= n <= 536_870_911 and not 19000 <= n < 20000 for n in numbers)
    assert field_number("x") == field_number("x")


# ------------------------------------------------------------------------------ schema evolution
@representation
class EvoV1:
    a: int
    b: float
    gone: str


@representation
class EvoV2:
    """EvoV1 after removing ``gone``, reordering, and adding fields with non-zero defaults."""

    b: float
    a: int
    added: float = 2.5
    added_list: list[int]
    added_array: np.ndarray = array((2,), np.int16)


@representation
class EvoTypeChanged:
    a: str
    b: float


def test_old_data_reads_with_added_removed_and_reordered_fields() -> None:
    old = serialize(EvoV1(a=7, b=1.5, gone="x"))
    new = deserialize(EvoV2, old, schema=schema_of(EvoV1))
    assert (new.a, new.b) == (7, 1.5)
    assert new.added == 2.5  # missing fields take the class default, not zero
    assert new.added_list == [] and new.added_array.dtype == np.int16


def test_new_data_reads_with_the_old_class() -> None:
    back = deserialize(EvoV1, serialize(EvoV2(a=3, b=4.0, added=9.0)))
    assert (back.a, back.b, back.gone) == (3, 4.0, "")


def test_incompatible_type_change_names_the_field() -> None:
    with pytest.raises(SerializationError, match=r"EvoTypeChanged.a was written as sint64 but is string now"):
        check_compatible(EvoTypeChanged, schema_of(EvoV1))
    with pytest.raises(SerializationError, match=r"EvoTypeChanged.a: the data holds this field with another type"):
        deserialize(EvoTypeChanged, serialize(EvoV1(a=5)))


def test_values_that_do_not_fit_are_named() -> None:
    with pytest.raises(SerializationError, match="EvoV1.a = 100000000000000000000 is outside the 64-bit range"):
        serialize(EvoV1(a=10**20))
    with pytest.raises(SerializationError, match="EvoV1.gone holds 3 \\(int\\), but is declared str"):
        serialize(EvoV1(gone=3))


def test_garbage_bytes_give_a_clear_error() -> None:
    with pytest.raises(SerializationError, match="cannot decode EvoV1 from 3 bytes"):
        deserialize(EvoV1, b"\xff\xff\xff")


def test_numpy_scalars_are_accepted_in_scalar_fields() -> None:
    back = deserialize(EvoV1, serialize(EvoV1(a=np.int64(4), b=np.float32(0.5))))
    assert (back.a, back.b) == (4, 0.5)


def test_the_core_package_offers_serialization() -> None:
    import tafel.core as core
    from tafel.representations.modeling import BallModel

    model = BallModel(valid=True, x=1200.0, y=-40.0)
    assert core.deserialize(BallModel, core.serialize(model)) == model
    assert core.schema_of(BallModel).message_type[0].name == "BallModel"
