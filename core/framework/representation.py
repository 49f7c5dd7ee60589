"""Representations: plain data classes exchanged between modules through the blackboard.

``@representation`` turns an annotated class into a dataclass whose every field has a default, records
a description of each field (kind, element type, array dtype and shape) for views, serialization and
test strategies, and registers the class by name so that logs, configuration and the debug server can
find it. Supported field types: ``bool``, ``int``, ``float``, ``str``, ``bytes``, ``Enum`` subclasses,
nested dataclasses (plain or representations), ``list[T]`` of those, and ``numpy.ndarray``.
"""

from __future__ import annotations

import copy
import dataclasses
import enum
import sys
import typing
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, TypeVar, dataclass_transform, overload

import numpy as np

from tafel.core.framework.errors import RepresentationDefinitionError

T = TypeVar("T")

SCALAR_KINDS = {bool: "bool", int: "int", float: "float", str: "str", bytes: "bytes"}
SCALAR_DEFAULTS: dict[str, Any] = {"bool": False, "int": 0, "float": 0.0, "str": "", "bytes": b""}
SUPPORTED_TYPES = "bool, int, float, str, bytes, an Enum, a dataclass, list[T] of those, numpy.ndarray"


@dataclass(frozen=True)
class ArraySpec:
    """What a numpy field is expected to hold; ``None`` in ``shape`` means any length along that axis."""

    dtype: np.dtype
    shape: tuple[int | None, ...]
    #: False for arrays declared without ``array(...)``: any float array goes, nothing is checked
    declared: bool = True


@dataclass(frozen=True)
class FieldInfo:
    """Static description of one representation field.

    ``kind`` is one of bool, int, float, str, bytes, enum, nested, list, ndarray. For ``list`` the
    element is described by ``element`` (a FieldInfo with an empty name).
    """

    name: str
    kind: str
    type: Any
    element: FieldInfo | None = None
    array: ArraySpec | None = None
    #: (low, high) the field's numbers must lie in, declared with ``bounded`` (for arrays and lists: each element)
    range: tuple[float, float] | None = None


_REGISTRY: dict[str, type] = {}
_FIELDS_ATTR = "__tafel_fields__"
_ARRAY_META = "tafel_array"
RANGE_META = "range"


def bounded(low: float, high: float, default: Any = dataclasses.MISSING, *, array_shape: tuple[int | None, ...] | None = None,
            dtype: Any = np.float64) -> Any:
    """A field whose numbers lie in ``[low, high]``: checked for values from outside, used by test strategies.

    ``distance: float = bounded(0.0, 9000.0)`` (default: ``low``, or 0 when it lies inside), or for an
    array, ``stiffness: np.ndarray = bounded(0.0, 1.0, array_shape=(25,))``. The same as
    ``field(metadata={"range": (low, high)})``.
    """
    if not low <= high:
        raise RepresentationDefinitionError(f"bounded({low}, {high}): the low end must not be above the high end")
    if array_shape is not None:
        field = array(array_shape, dtype)
        return dataclasses.field(default_factory=field.default_factory, metadata={**field.metadata, RANGE_META: (low, high)})
    if default is dataclasses.MISSING:
        default = 0.0 if low <= 0.0 <= high else low
    return dataclasses.field(default=default, metadata={RANGE_META: (low, high)})


#: the most a counter may hold: exact in JSON and in a float, and far from where a module's ``+= 1`` leaves 64 bits
MAX_COUNT = 2**53


def counter(default: int = 0) -> Any:
    """A whole number that counts up from 0 (packets, presses, messages): ``bounded(0, MAX_COUNT)``, so that a
    client cannot set it where the next increment would no longer fit a log's 64 bits."""
    return bounded(0, MAX_COUNT, default)


def array(shape: tuple[int | None, ...] = (0,), dtype: Any = np.float64) -> Any:
    """Field default for a numpy array: zeros of ``shape`` (``None`` axes start empty).

    Example: ``image: np.ndarray = array((240, 320, 3), np.uint8)``.
    """
    spec = ArraySpec(np.dtype(dtype), tuple(shape))
    concrete = tuple(0 if n is None else int(n) for n in spec.shape)
    return dataclasses.field(
        default_factory=lambda: np.zeros(concrete, dtype=spec.dtype), metadata={_ARRAY_META: spec}
    )


@overload
def representation(cls: type[T], /) -> type[T]: ...


@overload
def representation(*, state: bool = True) -> Callable[[type[T]], type[T]]: ...


@dataclass_transform(field_specifiers=(dataclasses.field,))
def representation(cls: type[T] | None = None, /, *, state: bool = True) -> Any:
    """Make ``cls`` a representation: a dataclass with defaults for every field, registered by name.

    ``@representation(state=False)`` marks diagnostics about the run rather than the robot's state (how
    long modules took): equal runs differ in them, so program fingerprints and ``tafel log compare``
    leave them out (``is_state``).

    Raises ``RepresentationDefinitionError`` for unsupported field types and when another module
    already registered a representation of the same class name.

    Type checkers see a dataclass (``dataclass_transform``), so keyword arguments are checked; they take a
    field without a default as required, so give one (``x: float = 0.0``) where checked code builds the
    representation without it.
    """
    if cls is None:
        return lambda target: _make_representation(target, state)
    return _make_representation(cls, state)


def is_state(cls: type) -> bool:
    """False for representations declared ``state=False`` (timing and other facts about the run)."""
    return bool(getattr(cls, "__tafel_state__", True))


def _make_representation(cls: type[T], state: bool) -> type[T]:
    name = cls.__name__
    previous = _REGISTRY.get(name)
    if previous is not None and (previous.__module__, previous.__qualname__) != (
        cls.__module__,
        cls.__qualname__,
    ):
        raise RepresentationDefinitionError(
            f"two representations are named {name!r}: {previous.__module__}.{previous.__qualname__} "
            f"and {cls.__module__}.{cls.__qualname__}; representation names must be unique because "
            "logs, configuration and debug commands refer to them by name. Rename one of them."
        )
    hints = _resolve_hints(cls)
    own = cls.__dict__.get("__annotations__", {})
    for field_name in own:
        if field_name.startswith("_"):
            raise RepresentationDefinitionError(
                f"{name}.{field_name}: field names may not start with an underscore"
            )
        _install_default(cls, field_name, hints[field_name])
    data_cls: Any = dataclasses.dataclass(cls, eq=False, repr=False)  # Any: it gets the attributes set below
    infos = tuple(_describe(name, f.name, hints[f.name], f) for f in dataclasses.fields(data_cls))
    setattr(data_cls, _FIELDS_ATTR, infos)
    data_cls.__eq__ = _representation_eq
    data_cls.__hash__ = None
    data_cls.__repr__ = _representation_repr
    data_cls.__tafel_representation__ = True
    data_cls.__tafel_state__ = state
    _REGISTRY[name] = data_cls
    return data_cls


def is_representation(obj: Any) -> bool:
    """True for a representation class (not an instance)."""
    return isinstance(obj, type) and obj.__dict__.get("__tafel_representation__", False)


def registered_representations() -> dict[str, type]:
    """All registered representation classes by name (a copy)."""
    return dict(_REGISTRY)


def defining_modules() -> list[str]:
    """The Python modules that define the registered representations, in registration order.

    A process started with ``spawn`` imports only what unpickling its arguments needs; importing these
    first gives it the same representations by name as the process that started it (a viewer's feed or
    a log names representations that none of the context's own modules mention)."""
    names: dict[str, None] = {}
    for cls in _REGISTRY.values():
        if cls.__module__ != "__main__":
            names.setdefault(cls.__module__, None)
    return list(names)


def get_representation(name: str) -> type:
    """The representation class registered under ``name``; ``KeyError`` with suggestions otherwise."""
    try:
        return _REGISTRY[name]
    except KeyError:
        from tafel.core.framework.naming import did_you_mean

        raise KeyError(f"no representation named {name!r}; {did_you_mean(name, _REGISTRY)}") from None


def fields_of(cls: type) -> tuple[FieldInfo, ...]:
    """Field descriptions of a representation or of any dataclass nested in one (cached)."""
    infos = cls.__dict__.get(_FIELDS_ATTR)
    if infos is None:
        if not dataclasses.is_dataclass(cls):
            raise TypeError(f"{cls!r} is not a dataclass")
        hints = _resolve_hints(cls)
        infos = tuple(_describe(cls.__name__, f.name, hints[f.name], f) for f in dataclasses.fields(cls))
        setattr(cls, _FIELDS_ATTR, infos)
    return infos


def reset(instance: Any) -> None:
    """Set every field of ``instance`` back to its default, keeping the object's identity."""
    fresh = type(instance)()
    instance.__dict__.update(fresh.__dict__)


def copy_into(target: Any, source: Any) -> None:
    """Make ``target`` an independent copy of ``source`` (same class), keeping ``target``'s identity."""
    target.__dict__.update(copy.deepcopy(source.__dict__))


def values_equal(a: Any, b: Any) -> bool:
    """Equality that understands numpy arrays (same dtype, shape and values, NaN equal to NaN)."""
    if isinstance(a, np.ndarray) or isinstance(b, np.ndarray):
        if not (isinstance(a, np.ndarray) and isinstance(b, np.ndarray)):
            return False
        if a.dtype != b.dtype or a.shape != b.shape:
            return False
        return bool(np.array_equal(a, b, equal_nan=a.dtype.kind in "fc"))
    if isinstance(a, list) and isinstance(b, list):
        return len(a) == len(b) and all(values_equal(x, y) for x, y in zip(a, b))
    if dataclasses.is_dataclass(a) and not isinstance(a, type):
        if type(a) is not type(b):
            return False
        return all(values_equal(getattr(a, f.name), getattr(b, f.name)) for f in dataclasses.fields(a))
    if isinstance(a, float) and isinstance(b, float) and a != a and b != b:
        return True  # NaN round-trips as NaN
    return bool(a == b)


def _representation_eq(self: Any, other: Any) -> bool:
    if type(self) is not type(other):
        return NotImplemented
    return values_equal(self, other)


def _representation_repr(self: Any) -> str:
    parts = []
    for f in dataclasses.fields(self):
        value = getattr(self, f.name)
        if isinstance(value, np.ndarray) and value.size > 16:
            text = f"array(shape={value.shape}, dtype={value.dtype})"
        else:
            text = repr(value)
        parts.append(f"{f.name}={text}")
    return f"{type(self).__name__}({', '.join(parts)})"


def _resolve_hints(cls: type) -> dict[str, Any]:
    module = sys.modules.get(cls.__module__)
    try:
        return typing.get_type_hints(cls, globalns=vars(module) if module else None)
    except NameError as exc:
        raise RepresentationDefinitionError(
            f"{cls.__name__}: cannot resolve a field type ({exc}); define nested types before "
            "the representation that uses them"
        ) from None


def _install_default(cls: type, field_name: str, hint: Any) -> None:
    """Give a field without a default the default of its type; wrap mutable defaults in factories."""
    current = cls.__dict__.get(field_name, dataclasses.MISSING)
    if isinstance(current, dataclasses.Field):
        if current.default is dataclasses.MISSING and current.default_factory is dataclasses.MISSING:
            current.default_factory = _default_factory(cls.__name__, field_name, hint)
        return
    if current is dataclasses.MISSING:
        setattr(cls, field_name, dataclasses.field(default_factory=_default_factory(cls.__name__, field_name, hint)))
    elif isinstance(current, (np.ndarray, list)) or (
        dataclasses.is_dataclass(current) and not isinstance(current, type)
    ):
        prototype = current
        metadata = {}
        if isinstance(current, np.ndarray):
            metadata = {_ARRAY_META: ArraySpec(current.dtype, current.shape)}
        setattr(
            cls,
            field_name,
            dataclasses.field(default_factory=lambda: copy.deepcopy(prototype), metadata=metadata),
        )


def _default_factory(owner: str, field_name: str, hint: Any) -> Any:
    info = _describe(owner, field_name, hint, None)
    if info.kind in SCALAR_DEFAULTS:
        value = SCALAR_DEFAULTS[info.kind]
        return lambda: value
    if info.kind == "enum":
        first = next(iter(info.type))
        return lambda: first
    if info.kind == "nested":
        return info.type
    if info.kind == "list":
        return list
    return lambda: np.zeros(0, dtype=np.float64)


def _describe(owner: str, field_name: str, hint: Any, field: dataclasses.Field | None) -> FieldInfo:
    """Classify a field type, raising a clear error for anything unsupported."""
    info = _classify(owner, field_name, hint, field)
    bounds = field.metadata.get(RANGE_META) if field is not None else None
    if bounds is None:
        return info
    low, high = (float(v) for v in bounds)
    numeric = info.kind in ("int", "float", "ndarray") or (info.element is not None and info.element.kind in ("int", "float"))
    if not numeric or not low <= high:
        raise RepresentationDefinitionError(f"{owner}.{field_name}: a range (low <= high) fits only numbers, numeric "
                                            f"arrays and lists of numbers; got {bounds!r} on a {info.kind} field")
    element = dataclasses.replace(info.element, range=(low, high)) if info.element is not None else None
    return dataclasses.replace(info, range=(low, high), element=element)


def _classify(owner: str, field_name: str, hint: Any, field: dataclasses.Field | None) -> FieldInfo:
    origin = typing.get_origin(hint)
    if hint in SCALAR_KINDS:
        return FieldInfo(field_name, SCALAR_KINDS[hint], hint)
    if isinstance(hint, type) and issubclass(hint, enum.Enum):
        if not list(hint):
            raise RepresentationDefinitionError(f"{owner}.{field_name}: enum {hint.__name__} has no members")
        return FieldInfo(field_name, "enum", hint)
    if hint is np.ndarray or origin is np.ndarray:
        spec = None
        if field is not None:
            spec = field.metadata.get(_ARRAY_META)
        return FieldInfo(field_name, "ndarray", np.ndarray, array=spec or ArraySpec(np.dtype(np.float64), (None,), declared=False))
    if origin is list or hint is list:
        (element_hint,) = typing.get_args(hint) or (None,)
        if element_hint is None:
            raise RepresentationDefinitionError(
                f"{owner}.{field_name}: write list[T] with an element type, e.g. list[float]"
            )
        element = _describe(owner, field_name, element_hint, None)
        if element.kind == "list":
            raise RepresentationDefinitionError(
                f"{owner}.{field_name}: lists of lists are not supported; wrap the inner list in a dataclass"
            )
        return FieldInfo(field_name, "list", hint, element=dataclasses.replace(element, name=""))
    if isinstance(hint, type) and dataclasses.is_dataclass(hint):
        for f in dataclasses.fields(hint):
            if f.default is dataclasses.MISSING and f.default_factory is dataclasses.MISSING:
                raise RepresentationDefinitionError(
                    f"{owner}.{field_name}: nested dataclass {hint.__name__} needs a default for "
                    f"field {f.name!r} (or make it a @representation, which adds defaults)"
                )
        return FieldInfo(field_name, "nested", hint)
    raise RepresentationDefinitionError(
        f"{owner}.{field_name}: type {hint!r} is not supported; use {SUPPORTED_TYPES}"
    )
