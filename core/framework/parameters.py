"""Module parameters: a typed dataclass per module, filled from configuration.

A module declares ``class Parameters`` (a dataclass) in its body and reads ``self.parameters``.
Values from configuration are checked against the field types, so a typo or a string where a number
belongs fails at start-up with the field's name instead of misbehaving later.

Every number has a range: the one its field declares (``bounded``), else its type's natural one
(``tafel.core.framework.validation.natural_range``). A string parameter may declare what it names:

- ``choice_of(options)``: one of a few words (``GameStateProvider.start_state``), checked like an enum
  wherever a value comes from, so a stored value always loads again;
- ``folder_within(base)``: a folder the module reads. Configuration (what the user typed) may name any
  folder; a debug client (``parameter:set``, ``set_parameter(..., client=True)``) only one inside
  ``base`` or inside the folder configuration named at start, so a client cannot make the program read
  (and list) a folder of its choosing.
"""

from __future__ import annotations

import dataclasses
import enum
import typing
import weakref
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

from tafel.core.framework.errors import TafelError
from tafel.core.framework.naming import did_you_mean
from tafel.core.framework.validation import declared_range
from tafel.core.framework.values import convert, refusal


class ParameterError(TafelError, ValueError):
    """A parameter value or name that does not fit the module's Parameters dataclass."""


CHOICES_META = "choices"
FOLDER_META = "folder_within"
#: the attribute of a Parameters instance that keeps what configuration gave its folder parameters
_CONFIGURED = "_tafel_configured_folders"
#: each Parameters class's resolved field types (``parameter_hints``)
_HINTS: weakref.WeakKeyDictionary[type, dict[str, Any]] = weakref.WeakKeyDictionary()


def choice_of(options: Sequence[str], default: str | None = None) -> Any:
    """A string parameter that takes one of ``options`` (in any case; kept as listed): checked at start,
    at ``parameter:set`` and at ``parameter:store``. The default is ``default`` or the first option."""
    options = tuple(str(option) for option in options)
    if not options or (default is not None and default not in options):
        raise ValueError(f"choice_of({options!r}, default={default!r}): the default must be one of the options")
    return dataclasses.field(default=options[0] if default is None else default, metadata={CHOICES_META: options})


def folder_within(base: str | Path, default: str = "") -> Any:
    """A string parameter naming a folder the module reads ("" means ``base``). Configuration may name
    any folder; a debug client only ``base``, the folder configuration named, or a folder inside them."""
    return dataclasses.field(default=default, metadata={FOLDER_META: str(base)})


def parameters_class(module: type) -> type | None:
    cls = getattr(module, "Parameters", None)
    return cls if isinstance(cls, type) and dataclasses.is_dataclass(cls) else None


def coerce(module_name: str, field: dataclasses.Field, hint: Any, value: Any) -> Any:
    """``value`` converted to the field's type and checked against its range and choices
    (``tafel.core.framework.values.convert``), or a ``ParameterError`` saying what would fit."""
    return convert(value, hint, where=f"parameter {module_name}.{field.name}", bounds=declared_range(field),
                   choices=field.metadata.get(CHOICES_META), error=ParameterError)


def _client_folder(where: str, field: dataclasses.Field, value: str, configured: str | None) -> str:
    """A folder a client named, resolved, if it lies inside the declared base or the configured folder."""
    if value == "":
        return value
    base = field.metadata[FOLDER_META]
    roots = [Path(base)] + ([Path(configured)] if configured else [])
    try:
        path = Path(value).resolve()  # symbolic links followed: a link inside that points out is outside
        inside = any(path == root.resolve() or path.is_relative_to(root.resolve()) for root in roots)
    except (OSError, ValueError):  # a NUL byte, a loop of links
        inside = False
    if not inside:
        allowed = " or ".join(str(root.resolve()) for root in roots)
        raise refusal(f"parameter {where}", f"a folder inside {allowed} (configuration may name another one)", value,
                      ParameterError)
    return str(path)


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
    configured = {f.name: getattr(instance, f.name) for f in dataclasses.fields(instance) if FOLDER_META in f.metadata}
    if configured:
        object.__setattr__(instance, _CONFIGURED, configured)  # the folders clients may stay within
    return instance


def set_parameter(module_name: str, instance: Any, name: str, value: Any, *, client: bool = False) -> Any:
    """Set one parameter on a Parameters instance after checking name and type; returns the value.

    ``client``: the value comes from a debug client, not from configuration; a folder parameter then
    only takes a folder within its base or the configured folder (``folder_within``).
    """
    fields = {f.name: f for f in dataclasses.fields(instance)}
    if name not in fields:
        raise ParameterError(f"{module_name} has no parameter {name!r}; {did_you_mean(name, fields)}")
    converted = coerce(module_name, fields[name], parameter_hints(type(instance))[name], value)
    if client and FOLDER_META in fields[name].metadata:
        configured = getattr(instance, _CONFIGURED, {}).get(name)
        converted = _client_folder(f"{module_name}.{name}", fields[name], converted, configured)
    setattr(instance, name, converted)
    return converted


def parameter_hints(cls: type) -> dict[str, Any]:
    """The resolved field types of a Parameters class (``typing.get_type_hints``), worked out once per class: every
    ``set_parameter`` needs one, and resolving them anew cost about a millisecond a call. Read-only for callers."""
    hints = _HINTS.get(cls)
    if hints is None:
        hints = _HINTS[cls] = typing.get_type_hints(cls)
    return hints


def parameter_values(instance: Any) -> dict[str, Any]:
    """Current values as plain data (enums by name), e.g. for storing into configuration."""
    result = {}
    for f in dataclasses.fields(instance):
        value = getattr(instance, f.name)
        result[f.name] = value.name if isinstance(value, enum.Enum) else value
    return result
