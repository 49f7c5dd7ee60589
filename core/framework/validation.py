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
import math
from typing import Any

import numpy as np

from tafel.core.framework.access import ArrayFieldError, check_array
from tafel.core.framework.errors import TafelError
from tafel.core.framework.representation import RANGE_META, FieldInfo, fields_of

__all__ = ["INT_RANGE", "MAX_MAGNITUDE", "ValueCheckError", "check_field", "check_instance", "check_number", "declared_range",
           "natural_range"]

#: the range of a whole number without a declared one: what a 64-bit signed integer holds (logs store int64)
INT_RANGE = (-(2**63), 2**63 - 1)
#: the largest size of any other number without a declared range
MAX_MAGNITUDE = 1e12


class ValueCheckError(TafelError, ValueError):
    """A value from outside that does not fit its field; the message names the field and what fits."""


def declared_range(field: dataclasses.Field | None) -> tuple[float, float] | None:
    """The ``(low, high)`` a field declares through ``bounded`` or ``metadata={"range": ...}``."""
    if field is None:
        return None
    bounds = field.metadata.get(RANGE_META)
    return None if bounds is None else (float(bounds[0]), float(bounds[1]))


def natural_range(kind: str) -> tuple[float, float]:
    """The range of a number whose field declares none: 64 bits for whole numbers, ``MAX_MAGNITUDE`` otherwise."""
    return INT_RANGE if kind == "int" else (-MAX_MAGNITUDE, MAX_MAGNITUDE)


def _text(number: Any) -> str:
    """A number for a message: short, whatever its size (a 309-digit integer is not printed whole)."""
    if isinstance(number, int) and abs(number) >= 10**20:
        digits = int(abs(number).bit_length() * math.log10(2)) + 1  # str() of a huge int is slow, or refused
        return f"{'-' if number < 0 else ''}a number of about {digits} digits"
    return str(number) if isinstance(number, int) else f"{number:g}"


def check_number(value: Any, where: str, *, kind: str = "float", bounds: tuple[float, float] | None = None) -> Any:
    """``value`` as a finite ``float`` (or ``int``) within ``bounds``, or without them within the type's
    natural range (``natural_range``); otherwise ``ValueCheckError``."""
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
        raise ValueCheckError(f"{where} takes {'a whole number' if kind == 'int' else 'a number'}, got {value!r:.60}")
    if kind == "int":
        if isinstance(value, (float, np.floating)) and not float(value).is_integer():
            raise ValueCheckError(f"{where} takes a whole number, got {value!r}")
        number: Any = int(value)
    else:
        try:
            number = float(value)
        except OverflowError:  # a whole number beyond any float
            raise ValueCheckError(f"{where} takes a finite number, got {_text(int(value))}") from None
        if not math.isfinite(number):
            raise ValueCheckError(f"{where} takes a finite number, got {number}")
    if bounds is not None:
        if not bounds[0] <= number <= bounds[1]:
            raise ValueCheckError(f"{where} takes {bounds[0]:g} to {bounds[1]:g}, got {_text(number)}")
        return number
    low, high = natural_range(kind)
    if not low <= number <= high:
        what = "a whole number that fits in 64 bits" if kind == "int" else f"a number of at most {MAX_MAGNITUDE:g} in size"
        raise ValueCheckError(f"{where} takes {what} (it declares no narrower range), got {_text(number)}")
    return number


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
        with np.errstate(over="ignore", invalid="ignore"):  # 1e308 into float32 becomes inf: refused below, no warning
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
    if bounds is None and array.dtype.kind == "f":  # whole-number dtypes hold their own range
        bounds = natural_range("float")
    if bounds is not None and array.size and (array.min() < bounds[0] or array.max() > bounds[1]):
        raise ValueCheckError(f"{where} takes values from {bounds[0]:g} to {bounds[1]:g}; got {array.min():g} to {array.max():g}")
    return array

