"""Checking values that come from outside the program against what a representation declares.

Debug clients (``representation:set``, ``modify:set``, ``parameter:set``), configuration and tests
hand the program values it did not compute. Before such a value reaches a blackboard, a module or an
actuator it is checked here against the field's declared type, array shape and dtype, finiteness and,
where the field declares one, its range (``bounded``). A number whose field declares no range still
has one, its type's natural range: a whole number fits in 64 bits (``INT_RANGE``) and any other number
is finite and at most ``MAX_MAGNITUDE`` (1e12) in size: no length in mm, time in s or gain a robot uses
comes near it, and a 309-digit integer or a 1e308 that a module squares or loops over would stop the
program. A value that does not fit is refused with a ``ValueCheckError`` that names the field and says
what would be right; nothing is changed.

Modules' own writes are not checked here (that would cost every frame): only array shapes are, by
the writer views.
"""

from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np

from tafel.core.framework.access import ArrayFieldError, check_array
from tafel.core.framework.representation import RANGE_META, FieldInfo, fields_of
from tafel.core.framework.values import INT_RANGE, MAX_MAGNITUDE, ValueCheckError, convert, natural_range, refusal

__all__ = ["INT_RANGE", "MAX_MAGNITUDE", "ValueCheckError", "check_field", "check_instance", "check_number", "declared_range",
           "natural_range"]


def declared_range(field: dataclasses.Field | None) -> tuple[float, float] | None:
    """The ``(low, high)`` a field declares through ``bounded`` or ``metadata={"range": ...}``."""
    if field is None:
        return None
    bounds = field.metadata.get(RANGE_META)
    return None if bounds is None else (float(bounds[0]), float(bounds[1]))


def check_number(value: Any, where: str, *, kind: str = "float", bounds: tuple[float, float] | None = None) -> Any:
    """``value`` as a finite ``float`` (or ``int``) within ``bounds``, or without them within the type's
    natural range (``natural_range``); otherwise ``ValueCheckError``."""
    return convert(value, int if kind == "int" else float, where=where, bounds=bounds, text=False)


def check_field(owner: type, name: str, value: Any, where: str = "") -> Any:
    """``value`` converted to field ``name`` of the dataclass ``owner``, checked; raises ``ValueCheckError``."""
    infos = {info.name: info for info in fields_of(owner)}
    if name not in infos:
        from tafel.core.framework.naming import did_you_mean

        raise ValueCheckError(f"{owner.__name__} has no field {name!r}; {did_you_mean(name, infos)}")
    return _check(infos[name], value, where or f"{owner.__name__}.{name}")


def check_instance(instance: Any, where: str = "") -> None:
    """Check every field of a representation (or nested dataclass) in place; raises on the first misfit."""
    cls = type(instance)
    where = where or cls.__name__
    for info in fields_of(cls):
        value = _check(info, getattr(instance, info.name), f"{where}.{info.name}")
        object.__setattr__(instance, info.name, value)


#: the Python type of each scalar kind of field
_SCALARS = {"float": float, "int": int, "bool": bool, "str": str, "bytes": bytes}


def _check(info: FieldInfo, value: Any, where: str) -> Any:
    bounds = info.range
    kind = info.kind
    if kind in _SCALARS or kind == "enum":
        return convert(value, _SCALARS.get(kind, info.type), where=where, bounds=bounds, text=False)
    if kind == "nested":
        if not isinstance(value, info.type):
            raise refusal(where, f"a {info.type.__name__}", value)
        check_instance(value, where)
        return value
    if kind == "list":
        if not isinstance(value, list):
            raise refusal(where, "a list", value)
        assert info.element is not None
        return [_check(info.element, element, f"{where}[{i}]") for i, element in enumerate(value)]
    return _check_array(info, value, where, bounds)


def _check_array(info: FieldInfo, value: Any, where: str, bounds: tuple[float, float] | None) -> np.ndarray:
    spec = info.array
    assert spec is not None
    try:
        with np.errstate(over="ignore", invalid="ignore"):  # 1e308 into float32 becomes inf: refused below, no warning
            array = check_array(value, spec, "a client", where.split(".")[0], where.split(".", 1)[-1]) if spec.declared \
                else np.asarray(value, dtype=np.float64)
    except ArrayFieldError:
        shape = "x".join("any" if n is None else str(n) for n in spec.shape)
        got = np.asarray(value)
        raise refusal(where, f"an array of shape {shape} ({spec.dtype})",
                      _Said(f"shape {'x'.join(map(str, got.shape)) or 'scalar'} ({got.dtype})")) from None
    except (TypeError, ValueError):
        raise refusal(where, "an array of numbers", value) from None
    if array.dtype.kind == "f" and not np.isfinite(array).all():
        bad = int(np.flatnonzero(~np.isfinite(array))[0])
        raise refusal(where, "finite numbers", _Said(f"{array.flat[bad]} at element {bad}"))
    if bounds is None and array.dtype.kind == "f":  # whole-number dtypes hold their own range
        bounds = natural_range("float")
    if bounds is not None and array.size and (array.min() < bounds[0] or array.max() > bounds[1]):
        raise refusal(where, f"values from {bounds[0]:g} to {bounds[1]:g}", _Said(f"{array.min():g} to {array.max():g}"))
    return array


class _Said(str):
    """Words about a value (its shape, its range) for ``refusal``, shown as they are."""

    def __repr__(self) -> str:
        return str(self)

