"""One way in for values from outside: converted to their declared type and checked, with one wording.

Module parameters (configuration and ``parameter:set``), representation fields a client sets, text a
debug client types, platform options, configuration and the command line's types all come through
``convert``. It turns a value into a type (``bool``, ``int``, ``float``, ``str``, ``bytes``, an ``Enum``
by member name, ``list[T]``, ``tuple[T, ...]``, ``dict[str, T]``, ``T | None``, ``Literal``, or a
dataclass instance), checks its range (a field's ``bounded``, or ``Annotated[float, Range(...)]`` on an
element type), and refuses what does not fit with a ``ValueCheckError`` (or the caller's error class)
worded one way everywhere::

    <where> takes <what would be right>, got <what came>

Text (what a client types, a command-line word, a ``--set`` value that was not TOML) is read as the type
says: numbers, ``on``/``off``, ``true``/``false``, ``yes``/``no``, ``1``/``0``, enum names, lists as JSON
(``[1, 2]``) or separated (``1,2``). Values that are already data (TOML, JSON, Python) are taken
strictly: ``"5"`` is no number there, ``1`` no ``true``.

Every number has a range: the declared one, else its type's natural one: a whole number fits in 64 bits
(``INT_RANGE``, what logs store) and any other number is finite and at most ``MAX_MAGNITUDE`` (1e12) in
size, so that a 1e308 or a 309-digit integer a module squares or loops over cannot stop the program.

The checks are msgspec's (``msgspec.convert`` with ``Meta`` constraints, strict for data and lax for
text; ``msgspec.json`` for JSON text); this module chooses the type and words the refusal. Nothing here
runs in a frame: modules' own writes are not converted.
"""

from __future__ import annotations

import dataclasses
import enum
import math
import types
import typing
from collections.abc import Mapping
from functools import lru_cache
from typing import Annotated, Any

from tafel.core.framework.errors import TafelError

__all__ = ["BOOL_WORDS", "INT_RANGE", "MAX_MAGNITUDE", "Range", "ValueCheckError", "convert", "decode_json", "describe",
           "natural_range", "refusal", "shown"]

#: the range of a whole number without a declared one: what a 64-bit signed integer holds (logs store int64)
INT_RANGE = (-(2**63), 2**63 - 1)
#: the largest size of any other number without a declared range
MAX_MAGNITUDE = 1e12
#: the words text may say a yes or no with
BOOL_WORDS = {"on": True, "true": True, "yes": True, "1": True, "off": False, "false": False, "no": False, "0": False}


class ValueCheckError(TafelError, ValueError):
    """A value from outside that does not fit its field; the message names the field and what fits."""


@dataclasses.dataclass(frozen=True)
class Range:
    """The numbers a value may take: ``low`` to ``high``, ``low`` itself refused when ``low_open``
    (``Range(0, low_open=True)``: above zero). Put it on a type with ``Annotated[float, Range(0, 1)]``."""

    low: float = -math.inf
    high: float = math.inf
    low_open: bool = False

    def __post_init__(self) -> None:
        if not self.low <= self.high:  # also refuses NaN
            raise ValueError(f"Range({self.low!r}, {self.high!r}): low must be at most high")

    @classmethod
    def of(cls, bounds: Range | tuple[float, float] | None) -> Range | None:
        """A ``Range`` from a ``(low, high)`` pair (what ``bounded`` declares), or None for None."""
        if bounds is None or isinstance(bounds, Range):
            return bounds
        low, high = bounds
        return cls(float(low), float(high))

    def words(self, whole: bool = False) -> str:
        """The range as words: "from 0 to 1", "above 0", "above 0 and at most 1000", "of at least 2"."""
        def number(x: float) -> str:
            return str(int(x)) if whole and float(x).is_integer() else f"{x:g}"

        low, high = math.isfinite(self.low), math.isfinite(self.high)
        if low and high and not self.low_open:
            return f"from {number(self.low)} to {number(self.high)}"
        lower = f"above {number(self.low)}" if self.low_open else f"of at least {number(self.low)}"
        if low and high:
            return f"{lower} and at most {number(self.high)}"
        return lower if low else f"of at most {number(self.high)}" if high else ""


def natural_range(kind: str) -> tuple[float, float]:
    """The range of a number whose field declares none: 64 bits for whole numbers, ``MAX_MAGNITUDE`` otherwise."""
    return INT_RANGE if kind == "int" else (-MAX_MAGNITUDE, MAX_MAGNITUDE)


def shown(value: Any, limit: int = 60) -> str:
    """A value for a message: short, whatever its size (a 309-digit integer is not printed whole)."""
    if isinstance(value, bool) or value is None:
        return repr(value)
    if isinstance(value, int) and abs(value) >= 10**20:
        digits = int(abs(value).bit_length() * math.log10(2)) + 1  # str() of a huge int is slow, or refused
        return f"{'-' if value < 0 else ''}a number of about {digits} digits"
    if isinstance(value, float):
        return f"{value:g}"
    if isinstance(value, enum.Enum):
        return value.name
    text = repr(value)
    return text if len(text) <= limit else text[:limit] + f"... ({len(value) if isinstance(value, (str, bytes, list)) else len(text)} long)"


def refusal(where: str, expected: str, value: Any, error: type[Exception] = ValueCheckError) -> Exception:
    """The one wording of a refused value: ``<where> takes <expected>, got <value>`` (an error to raise)."""
    return error(f"{where + ' ' if where else ''}takes {expected}, got {shown(value)}")


def _parts(kind: Any) -> tuple[Any, Range | None]:
    """``Annotated[T, Range(...)]`` -> (T, the range); any other type -> (it, None)."""
    if typing.get_origin(kind) is Annotated:
        base, *extras = typing.get_args(kind)
        return base, next((extra for extra in extras if isinstance(extra, Range)), None)
    return kind, None


def _optional(kind: Any) -> Any | None:
    """T of ``T | None`` (or ``Optional[T]``), else None."""
    if typing.get_origin(kind) in (typing.Union, types.UnionType):
        args = [arg for arg in typing.get_args(kind) if arg is not type(None)]
        if len(args) == 1 and len(typing.get_args(kind)) == 2:
            return args[0]
    return None


def describe(kind: Any, bounds: Range | tuple[float, float] | None = None, choices: tuple[str, ...] | None = None,
             unit: str = "") -> str:
    """What a value of ``kind`` (within ``bounds``, one of ``choices``) is, in words, for ``refusal``."""
    kind, declared = _parts(kind)
    rng = Range.of(bounds) or declared
    of = f" of {unit}" if unit else ""
    if choices:
        return "one of " + ", ".join(choices)
    if kind is bool:
        return "on/off or true/false"
    if kind is int:
        return f"a whole number{of} {rng.words(whole=True)}" if rng else f"a whole number{of} that fits in 64 bits"
    if kind is float:
        if rng is None:
            return f"a finite number{of} of at most {MAX_MAGNITUDE:g} in size"
        return f"a finite number{of} {rng.words()}"
    if kind is str:
        return "text"
    if kind is bytes:
        return "bytes"
    if isinstance(kind, type) and issubclass(kind, enum.Enum):
        return "one of " + ", ".join(kind.__members__)
    if typing.get_origin(kind) is typing.Literal:
        return "one of " + ", ".join(map(str, typing.get_args(kind)))
    origin, args = typing.get_origin(kind), typing.get_args(kind)
    if origin is list:
        return f"a list ({describe(args[0] if args else Any, rng)} each)"
    if origin is tuple:
        return f"{len(args)} values: " + ", ".join(describe(arg, rng) for arg in args)
    if origin in (dict, Mapping):
        return f"a table ({describe(args[1] if args else Any, rng)} each)"
    inner = _optional(kind)
    if inner is not None:
        return f"{describe(inner, rng, unit=unit)} or none"
    if isinstance(kind, type) and dataclasses.is_dataclass(kind):
        return f"a {kind.__name__}"
    return "a value" if kind is Any else getattr(kind, "__name__", str(kind))


@lru_cache(maxsize=512)
def _number_type(kind: type, rng: Range | None) -> Any:
    """``kind`` with its range (declared within the natural one) as msgspec's ``Meta`` constraints."""
    import msgspec
    low, high = natural_range("int" if kind is int else "float")
    if rng is not None:
        low, high = max(low, rng.low), min(high, rng.high)
    if kind is int:
        low, high = math.ceil(low), math.floor(high)
    if rng is not None and rng.low_open and low == rng.low:
        return Annotated[kind, msgspec.Meta(gt=low, le=high)]
    return Annotated[kind, msgspec.Meta(ge=low, le=high)]


def decode_json(text: str, where: str, expected: str, error: type[Exception] = ValueCheckError) -> Any:
    """JSON text as data (msgspec), or the refusal saying what was expected."""
    import msgspec

    try:
        return msgspec.json.decode(text)
    except (msgspec.DecodeError, msgspec.ValidationError):  # not JSON; a number beyond a float
        raise refusal(where, expected, text, error) from None


def convert(value: Any, kind: Any, *, where: str, bounds: Range | tuple[float, float] | None = None,
            choices: tuple[str, ...] | None = None, text: bool | None = None, expected: str | None = None, unit: str = "",
            separator: str = ",", error: type[Exception] = ValueCheckError) -> Any:
    """``value`` as a ``kind`` within ``bounds`` (or one of the strings ``choices``, in any case), else ``error``.

    ``text``: True, ``value`` is text someone typed, read as ``kind`` says; False, it is data and taken
    strictly; None (the default), text if it is a string and ``kind`` is not. ``expected`` replaces the
    description of what would be right (a format such as ``X,Y in mm``): then a misfit anywhere inside
    refuses the whole value. ``separator`` splits text into a list's or tuple's elements (``320x240``).
    """
    try:
        return _convert(value, kind, where, Range.of(bounds), choices, text, unit, separator, error)
    except _Misfit as misfit:
        if expected is not None:
            raise refusal(where, expected, value, error) from None
        raise refusal(misfit.where, misfit.expected, misfit.value, error) from None


class _Misfit(Exception):
    """Where inside a value what did not fit, and what would have (worded by ``convert``)."""

    def __init__(self, where: str, expected: str, value: Any) -> None:
        super().__init__(where)
        self.where, self.expected, self.value = where, expected, value


def _convert(value: Any, kind: Any, where: str, rng: Range | None, choices: tuple[str, ...] | None, text: bool | None,
             unit: str, separator: str, error: type[Exception]) -> Any:
    import msgspec  # here, not at the top: the command line's parser (tafel --help) converts nothing

    kind, declared = _parts(kind)
    rng = rng or declared
    generic = _numpy_scalar()
    if generic is not None and isinstance(value, generic):
        value = value.item()  # numpy's scalars as Python's: msgspec knows only those
    is_text = isinstance(value, str) and kind is not str if text is None else text
    if is_text and not isinstance(value, str):
        raise _Misfit(where, describe(kind, rng, choices, unit), value)

    def misfit() -> _Misfit:
        return _Misfit(where, describe(kind, rng, choices, unit), value)

    if kind is Any:
        return value
    inner = _optional(kind)
    if inner is not None:
        if value is None or (is_text and value.strip().lower() in ("none", "null")):
            return None
        return _convert(value, inner, where, rng, choices, text, unit, separator, error)
    if choices is not None:
        if isinstance(value, str):
            for option in choices:
                if value.lower() == option.lower():
                    return option
        raise misfit()
    if kind is bool:
        if is_text:
            word = BOOL_WORDS.get(value.strip().lower())
            if word is None:
                raise misfit()
            return word
        if not isinstance(value, bool):
            raise misfit()
        return value
    if kind is int or kind is float:
        if is_text:
            value = value.strip().replace("_", "") if value.strip() else value
        elif kind is int and isinstance(value, float) and value.is_integer():
            value = int(value)  # 5.0 from TOML or JSON is the whole number 5
        try:
            return msgspec.convert(value, _number_type(kind, rng), strict=not is_text)
        except msgspec.ValidationError:
            raise misfit() from None
    if kind is str or kind is bytes:
        if not isinstance(value, kind):
            raise misfit()
        return value
    if isinstance(kind, type) and issubclass(kind, enum.Enum):
        if isinstance(value, kind):
            return value
        member = kind.__members__.get(value.strip() if is_text else value) if isinstance(value, str) else None
        if member is None:
            raise misfit()
        return member
    origin, args = typing.get_origin(kind), typing.get_args(kind)
    if origin is typing.Literal:
        if value not in args:
            raise misfit()
        return value
    if origin in (list, tuple):
        items = value
        elements_text = text
        if is_text:
            stripped = value.strip()
            if stripped.startswith("["):
                try:
                    items, elements_text = msgspec.json.decode(stripped), False
                except (msgspec.DecodeError, msgspec.ValidationError):
                    raise misfit() from None
            else:
                items, elements_text = [part for part in stripped.split(separator) if part.strip()], True
        if not isinstance(items, (list, tuple)):
            raise misfit()
        if origin is tuple:
            if len(args) == 2 and args[1] is Ellipsis:
                args = (args[0],) * len(items)
            if len(items) != len(args):
                raise misfit()
            return tuple(_convert(item, arg, f"{where}[{i}]", rng, None, elements_text, unit, separator, error)
                         for i, (item, arg) in enumerate(zip(items, args)))
        element = args[0] if args else Any
        return [_convert(item, element, f"{where}[{i}]", rng, None, elements_text, unit, separator, error)
                for i, item in enumerate(items)]
    if origin in (dict, Mapping):
        if is_text:
            try:
                value, text = msgspec.json.decode(value.strip()), False
            except (msgspec.DecodeError, msgspec.ValidationError):
                raise misfit() from None
        if not isinstance(value, Mapping) or not all(isinstance(key, str) for key in value):
            raise misfit()
        element = args[1] if args else Any
        return {key: _convert(item, element, f"{where}.{key}", rng, None, text, unit, separator, error) for key, item in value.items()}
    if isinstance(kind, type):
        if not isinstance(value, kind):
            raise misfit()
        return value
    raise TypeError(f"convert: {where}: {kind!r} is no type values can be converted to")


_NUMPY: Any = None


def _numpy_scalar() -> Any:
    """numpy's scalar base class if numpy is loaded (this module does not load it), else None."""
    global _NUMPY
    if _NUMPY is None:
        import sys

        numpy = sys.modules.get("numpy")
        if numpy is None:
            return None
        _NUMPY = numpy.generic
    return _NUMPY
