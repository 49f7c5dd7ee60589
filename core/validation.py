"""Checking values that come from outside the program against what a representation declares.

Debug clients (``representation:set``, ``modify:set``, ``parameter:set``), configuration and tests
hand the program values it did not compute. Before such a value reaches a blackboard, a module or an
actuator it is checked here against the field's declared type, array shape and dtype, finiteness and,
where the field declares one, its range (``bounded``). A value that does not fit is refused with a
``ValueCheckError`` that names the field and says what would be right; nothing is changed.

Modules' own writes are not checked here (that would cost every frame): only array shapes are, by
the writer views.
"""

from __future__ import annotations

import dataclasses
import math
from typing import Any

import numpy as np

from tafel.core.access import ArrayFieldError, check_array
from tafel.core.errors import TafelError
from tafel.core.representation import RANGE_META, FieldInfo, fields_of

__all__ = ["ValueCheckError", "check_field", "check_instance", "check_number", "declared_range"]


class ValueCheckError(TafelError, ValueError):
    """A value from outside that does not fit its field; the message names the field and what fits."""


def declared_range(field: dataclasses.Field | None) -> tuple[float, float] | None:
    """The ``(low, high)`` a field declares through ``bounded`` or ``metadata={"range": ...}``."""
    if field is None:
        return None
    bounds = field.metadata.get(RANGE_META)
    return None if bounds is None else (float(bounds[0]), float(bounds[1]))


def check_number(value: Any, where: str, *, kind: str = "float", bounds: tuple[float, float] | None = None) -> Any:
    """``value`` as a finite ``float`` (or ``int``) within ``bounds``, or ``ValueCheckError``."""
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
        raise ValueCheckError(f"{where} takes {'a whole number' if kind == 'int' else 'a number'}, got {value!r}")
    if kind == "int":
        if isinstance(value, (float, np.floating)) and not float(value).is_integer():
            raise ValueCheckError(f"{where} takes a whole number, got {value!r}")
        number: Any = int(value)
    else:
        number = float(value)
        if not math.isfinite(number):
            raise ValueCheckError(f"{where} takes a finite number, got {number}")
    if bounds is not None and not bounds[0] <= number <= bounds[1]:
        raise ValueCheckError(f"{where} takes {bounds[0]:g} to {bounds[1]:g}, got {number:g}")
    return number


def check_field(owner: type, name: str, value: Any, where: str = "") -> Any:
    """``value`` converted to field ``name`` of the dataclass ``owner``, checked; raises ``ValueCheckError``."""
    infos = {info.name: info for info in fields_of(owner)}
    if name not in infos:
        from tafel.core.naming import did_you_mean

        raise ValueCheckError(f"{owner.__name__} has no field {name!r}; {did_you_mean(name, infos)}")
    return _check(infos[name], value, where or f"{owner.__name__}.{name}")


def check_instance(instance: Any, where: str = "") -> None:
    """Check every field of a representation (or nested dataclass) in place; raises on the first misfit."""
    cls = type(instance)
    where = where or cls.__name__
    for info in fields_of(cls):
        value = _check(info, getattr(instance, info.name), f"{where}.{info.name}")
        object.__setattr__(instance, info.name, value)


def _check(info: FieldInfo, value: Any, where: str) -> Any:
    bounds = info.range
    kind = info.kind
    if kind in ("float", "int"):
        return check_number(value, where, kind=kind, bounds=bounds)
    if kind == "bool":
        if not isinstance(value, (bool, np.bool_)):
            raise ValueCheckError(f"{where} takes true or false, got {value!r}")
        return bool(value)
    if kind in ("str", "bytes"):
        if not isinstance(value, info.type):
            raise ValueCheckError(f"{where} takes {kind}, got {type(value).__name__}")
        return value
    if kind == "enum":
        if isinstance(value, info.type):
            return value
        names = ", ".join(m.name for m in info.type)
        raise ValueCheckError(f"{where} takes one of {names}, got {value!r}")
    if kind == "nested":
        if not isinstance(value, info.type):
            raise ValueCheckError(f"{where} takes a {info.type.__name__}, got {type(value).__name__}")
        check_instance(value, where)
        return value
    if kind == "list":
        if not isinstance(value, list):
            raise ValueCheckError(f"{where} takes a list, got {type(value).__name__}")
        assert info.element is not None
        return [_check(info.element, element, f"{where}[{i}]") for i, element in enumerate(value)]
    return _check_array(info, value, where, bounds)


def _check_array(info: FieldInfo, value: Any, where: str, bounds: tuple[float, float] | None) -> np.ndarray:
    spec = info.array
    assert spec is not None
    try:
        array = check_array(value, spec, "a client", where.split(".")[0], where.split(".", 1)[-1]) if spec.declared \
            else np.asarray(value, dtype=np.float64)
    except ArrayFieldError:
        shape = "x".join("any" if n is None else str(n) for n in spec.shape)
        got = np.asarray(value)
        raise ValueCheckError(f"{where} takes an array of shape {shape} ({spec.dtype}); got shape "
                              f"{'x'.join(map(str, got.shape)) or 'scalar'} ({got.dtype})") from None
    except (TypeError, ValueError):
        raise ValueCheckError(f"{where} takes an array of numbers, got {value!r:.60}") from None
    if array.dtype.kind == "f" and not np.isfinite(array).all():
        bad = int(np.flatnonzero(~np.isfinite(array))[0])
        raise ValueCheckError(f"{where} takes finite numbers; element {bad} is {array.flat[bad]}")
    if bounds is not None and array.size and (array.min() < bounds[0] or array.max() > bounds[1]):
        raise ValueCheckError(f"{where} takes values from {bounds[0]:g} to {bounds[1]:g}; got {array.min():g} to {array.max():g}")
    return array

