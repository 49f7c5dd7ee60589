"""Module parameters: a typed dataclass per module, filled from configuration.

A module declares ``class Parameters`` (a dataclass) in its body and reads ``self.parameters``.
Values from configuration are checked against the field types, so a typo or a string where a number
belongs fails at start-up with the field's name instead of misbehaving later.
"""

from __future__ import annotations

import dataclasses
import enum
import typing
from collections.abc import Mapping
from typing import Any

from tafel.core.errors import TafelError
from tafel.core.naming import did_you_mean
from tafel.core.validation import ValueCheckError, check_number, declared_range


class ParameterError(TafelError, ValueError):
    """A parameter value or name that does not fit the module's Parameters dataclass."""


def parameters_class(module: type) -> type | None:
    cls = getattr(module, "Parameters", None)
    return cls if isinstance(cls, type) and dataclasses.is_dataclass(cls) else None


def coerce(module_name: str, field: dataclasses.Field, hint: Any, value: Any) -> Any:
    """``value`` converted to the field's type, or a ``ParameterError`` saying what would fit."""
    where = f"{module_name}.{field.name}"
    try:
        if hint is bool:
            if isinstance(value, str) and value.lower() in ("true", "false", "1", "0", "on", "off"):
                return value.lower() in ("true", "1", "on")
            if isinstance(value, bool):
                return value
            raise ValueError
        if hint is int:
            if isinstance(value, bool):
                raise ValueError
            if isinstance(value, float) and not value.is_integer():
                raise ValueError
            return _within(where, field, int(value), "int")
        if hint is float:
            if isinstance(value, bool):
                raise ValueError
            return _within(where, field, float(value), "float")
        if hint is str:
            return str(value)
        if isinstance(hint, type) and issubclass(hint, enum.Enum):
            if isinstance(value, hint):
                return value
            return hint[str(value)]
        if typing.get_origin(hint) is list:
            (element,) = typing.get_args(hint)
            if isinstance(value, str):
                value = [v for v in value.split(",") if v.strip()]
            return [coerce(module_name, field, element, v) for v in value]
    except ParameterError:
        raise
    except (ValueError, TypeError, KeyError):
        expected = getattr(hint, "__name__", str(hint))
        if isinstance(hint, type) and issubclass(hint, enum.Enum):
            expected += " (" + ", ".join(m.name for m in hint) + ")"
        raise ParameterError(f"parameter {where} takes {expected}, got {value!r}") from None
    return value


def _within(where: str, field: dataclasses.Field, number: Any, kind: str) -> Any:
    """``number`` if it is finite and in the field's declared range (``bounded`` or ``metadata={"range": ...}``)."""
    try:
        return check_number(number, f"parameter {where}", kind=kind, bounds=declared_range(field))
    except ValueCheckError as exc:
        raise ParameterError(str(exc)) from None


def make_parameters(module: type, values: Mapping[str, Any] | None = None) -> Any:
    """An instance of the module's Parameters with ``values`` applied, or None if it has none."""
    cls = parameters_class(module)
    if cls is None:
        if values:
            raise ParameterError(f"{module.__name__} has no parameters, but values were given: {sorted(values)}")
        return None
    instance = cls()
    for name, value in (values or {}).items():
        set_parameter(module.__name__, instance, name, value)
    return instance


def set_parameter(module_name: str, instance: Any, name: str, value: Any) -> Any:
    """Set one parameter on a Parameters instance after checking name and type; returns the value."""
    fields = {f.name: f for f in dataclasses.fields(instance)}
    if name not in fields:
        raise ParameterError(f"{module_name} has no parameter {name!r}; {did_you_mean(name, fields)}")
    hints = typing.get_type_hints(type(instance))
    converted = coerce(module_name, fields[name], hints[name], value)
    setattr(instance, name, converted)
    return converted


def parameter_values(instance: Any) -> dict[str, Any]:
    """Current values as plain data (enums by name), e.g. for storing into configuration."""
    result = {}
    for f in dataclasses.fields(instance):
        value = getattr(instance, f.name)
        result[f.name] = value.name if isinstance(value, enum.Enum) else value
    return result
