"""Deprecated: the free debug functions of earlier versions, for module code not yet moved to declarations.

``request``, ``modify``, ``modify_fields``, ``plot``, ``stopwatch`` and ``drawing`` still work inside a
frame, on the state of the context that runs it (never a process-wide one); outside a frame a request is
off, ``modify`` returns its value and nothing is recorded. Nothing lists them before they are used.
Declare the outputs on the module instead (``tafel.debug.outputs``): ``DebugRequest``, ``Plot``,
``Stopwatch``, ``ModifyValue``, ``ModifyParameters``.
"""

from __future__ import annotations

import warnings
from typing import Any

from tafel.debug.concepts import NO_PAINTER, RUNNING, Canvas, DebugState, Painter, StopwatchTimes, TunedParameters

_WARNED: set[str] = set()


def _deprecated(function: str, instead: str) -> None:
    if function not in _WARNED:
        _WARNED.add(function)
        warnings.warn(f"tafel.debug.{function}() is deprecated: declare {instead} on the module class "
                      "(README, 'Debugging a running program')", DeprecationWarning, stacklevel=3)


def _running() -> DebugState | None:
    return getattr(RUNNING, "state", None)


class LegacyRequest:
    """A request by name, looked up in the context whose frame runs when it is checked."""

    __slots__ = ("name", "description")

    def __init__(self, name: str, description: str) -> None:
        self.name, self.description = name, description

    def __bool__(self) -> bool:
        state = _running()
        return state is not None and state.request(self.name, self.description).on

    @property
    def on(self) -> bool:
        return bool(self)


def request(name: str, description: str = "") -> LegacyRequest:
    """Deprecated: ``DebugRequest(description)`` on the module class."""
    _deprecated("request", "DebugRequest(...)")
    return LegacyRequest(name, description)


def modify(name: str, value: Any) -> Any:
    """Deprecated: ``ModifyValue(default)`` on the module class."""
    _deprecated("modify", "ModifyValue(...)")
    state = _running()
    return value if state is None else state.modify(name, value)(value)


def modify_fields(prefix: str, values: Any, names: tuple[str, ...]) -> Any:
    """Deprecated: ``ModifyParameters(names)`` on the module class."""
    _deprecated("modify_fields", "ModifyParameters(...)")
    state = _running()
    if state is None:
        return values
    return TunedParameters({n: state.modify(f"{prefix}:{n}", getattr(values, n)) for n in names}).apply(values)


def plot(name: str, value: float) -> None:
    """Deprecated: ``Plot(...)`` on the module class."""
    _deprecated("plot", "Plot(...)")
    state = _running()
    if state is not None:
        state.plot(name).add(value)


def stopwatch(name: str) -> StopwatchTimes:
    """Deprecated: ``Stopwatch(...)`` on the module class."""
    _deprecated("stopwatch", "Stopwatch(...)")
    state = _running()
    return StopwatchTimes(name) if state is None else state.stopwatch(name)


def drawing(canvas: Canvas | str = "field") -> Painter:
    """Deprecated: drawings go under a ``DebugRequest``: ``self.draw.canvas(Canvas.FIELD)``."""
    _deprecated("drawing", "a DebugRequest and draw with self.<request>.canvas(...)")
    Canvas.of(canvas)
    state = _running()
    return NO_PAINTER if state is None else state.painter(canvas)
