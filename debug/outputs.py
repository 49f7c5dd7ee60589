"""Debug outputs declared by the module, as NaoTH's modules declare their debug requests:

    from tafel.debug import Canvas, DebugRequest, ModifyValue, Plot, Stopwatch

    class BallDetector(Module):
        draw_candidates = DebugRequest("circle around every ball candidate")   # BallDetector:draw_candidates
        radius = Plot("radius of the largest candidate, px")                    # BallDetector:radius
        segmentation = Stopwatch("colour segmentation of one image")
        min_radius = ModifyValue(3.0, "px; modify:set pins another value")

        def execute(self) -> None:
            with self.segmentation:
                ...
            self.radius.add(r)
            if self.draw_candidates:                       # off until debug_request:set
                self.draw_candidates.canvas(Canvas.IMAGE_TOP).circle(x, y, r, color="orange")
            if r < self.min_radius():                      # the declared value, or the pinned one
                ...

A declaration's name is ``ClassName:attribute`` (or ``name=``). The manager that runs the module gives
every declaration its context's entry of that name (``debug_state``) before ``__init__``; after that,
``self.draw_candidates`` is an ordinary attribute read. ``declared_outputs(cls)`` lists a class's
declarations without running anything (``tafel modules``).
"""

from __future__ import annotations

import dataclasses
from typing import Any, Generic, Self, TypeVar, overload

from tafel.core.framework.representation import RANGE_META
from tafel.debug.concepts import DebugState, ModifyEntry, PlotSeries, RequestSwitch, StopwatchTimes, TunedParameters

E = TypeVar("E")


class Declaration(Generic[E]):
    """A debug output declared on a module class; the instance's attribute is its context's entry (``E``)."""

    kind = ""

    def __init__(self, description: str = "", *, name: str = "") -> None:
        self.description = description
        self.explicit_name = name
        self.name = name
        self.attribute = ""

    def __set_name__(self, owner: type, attribute: str) -> None:
        self.attribute = attribute
        self.name = self.explicit_name or f"{owner.__name__}:{attribute}"
        if "__tafel_attach__" not in owner.__dict__:
            owner.__tafel_attach__ = staticmethod(attach_outputs)  # type: ignore[attr-defined]

    @overload
    def __get__(self, instance: None, owner: type) -> Self: ...

    @overload
    def __get__(self, instance: object, owner: type) -> E: ...

    def __get__(self, instance: Any, owner: type) -> Any:
        if instance is None:
            return self
        attach_outputs(instance)  # a module made without a manager: its own state
        return instance.__dict__[self.attribute]

    def entry(self, state: DebugState, owner: str, parameters: Any = None) -> E:
        raise NotImplementedError

    def describe(self) -> str:
        """One line for listings."""
        return f"{self.kind} {self.name}" + (f"  {self.description}" if self.description else "")


class DebugRequest(Declaration[RequestSwitch]):
    """A switch for a code path (off until ``debug_request:set``); ``if self.draw:`` costs an attribute read.
    Drawings under it: ``self.draw.canvas(Canvas.FIELD).circle(...)`` (nothing is drawn while it is off)."""

    kind = "request"

    def entry(self, state: DebugState, owner: str, parameters: Any = None) -> RequestSwitch:
        return state.request(self.name, self.description, owner)


class Plot(Declaration[PlotSeries]):
    """A series, one value a frame: ``self.radius.add(r)``; ``plot:get`` and the views' plots show it."""

    kind = "plot"

    def entry(self, state: DebugState, owner: str, parameters: Any = None) -> PlotSeries:
        return state.plot(self.name, self.description, owner)


class Stopwatch(Declaration[StopwatchTimes]):
    """A timed section: ``with self.segmentation:``; ``stopwatch:list`` shows last, mean, max, p95."""

    kind = "stopwatch"

    def entry(self, state: DebugState, owner: str, parameters: Any = None) -> StopwatchTimes:
        return state.stopwatch(self.name, self.description, owner)


class ModifyValue(Declaration[ModifyEntry]):
    """A value a debug client can pin (``modify:set``): ``self.gain()`` is ``default`` or the pinned value;
    ``self.gain(x)`` publishes a value the code computed and returns it, or the pinned one."""

    kind = "modify"

    def __init__(self, default: Any, description: str = "", *, name: str = "") -> None:
        super().__init__(description, name=name)
        self.default = default

    def entry(self, state: DebugState, owner: str, parameters: Any = None) -> ModifyEntry:
        return state.modify(self.name, self.default, self.description, owner)

    def describe(self) -> str:
        return f"modify {self.name} = {self.default!r}" + (f"  {self.description}" if self.description else "")


class ModifyParameters(Declaration[TunedParameters]):
    """Fields of the module's parameters as modify values ``PREFIX:FIELD`` (prefix: the class name), tried
    live: ``p = self.tuned.apply(self.parameters)`` gives them with the pinned values, clamped into each
    field's declared range. Modules sharing a prefix in one context share the values (``Kick:behind``)."""

    kind = "modify"

    def __init__(self, fields: tuple[str, ...], description: str = "", *, prefix: str = "") -> None:
        super().__init__(description)
        self.fields, self.prefix = tuple(fields), prefix

    def __set_name__(self, owner: type, attribute: str) -> None:
        super().__set_name__(owner, attribute)
        self.owner = owner
        self.prefix = self.prefix or owner.__name__
        self.name = f"{self.prefix}:{{{','.join(self.fields)}}}"

    def entry(self, state: DebugState, owner: str, parameters: Any = None) -> TunedParameters:
        entries: dict[str, ModifyEntry] = {}
        declared = {f.name: f for f in dataclasses.fields(parameters)} if dataclasses.is_dataclass(parameters) else {}
        for name in self.fields:
            value = getattr(parameters, name, None)
            entries[name] = state.modify(f"{self.prefix}:{name}", value, self.description, owner)
            if name in declared and RANGE_META in declared[name].metadata:  # modify:set refuses what the field does not take
                entries[name].bounds = declared[name].metadata[RANGE_META]
        return TunedParameters(entries)

    def describe(self) -> str:
        defaults = _default_parameters(self.owner)
        return "\n".join(f"modify {self.prefix}:{name}" + (f" = {getattr(defaults, name)!r}" if hasattr(defaults, name) else "")
                         for name in self.fields)


def declared_outputs(cls: type) -> dict[str, Declaration[Any]]:
    """Attribute name -> declaration, for every debug output ``cls`` and its bases declare."""
    found: dict[str, Declaration[Any]] = {}
    for klass in reversed(cls.__mro__):
        for attribute, value in vars(klass).items():
            if isinstance(value, Declaration):
                found[attribute] = value
    return found


def debug_state(manager: Any) -> DebugState:
    """The debug state of the context ``manager`` runs (made on first use, kept as ``manager.debug``),
    with the declared outputs of every module class the manager knows (running or not)."""
    state = getattr(manager, "debug", None)
    if state is None:
        state = DebugState(manager)
        manager.debug = state
        for cls in manager.module_classes:
            declared = declared_outputs(cls)
            defaults = _default_parameters(cls) if declared else None
            for declaration in declared.values():
                declaration.entry(state, cls.__name__, defaults)
    return state


def attach_outputs(instance: Any, manager: Any = None) -> None:
    """Give a module instance its context's entry for each declared output (the manager calls this before
    the module's ``__init__``; without a manager, the instance gets a state of its own)."""
    if "__tafel_debug__" in instance.__dict__:
        return
    state = debug_state(manager) if manager is not None else DebugState()
    instance.__dict__["__tafel_debug__"] = state
    owner, parameters = type(instance).__name__, instance.__dict__.get("parameters")
    for attribute, declaration in declared_outputs(type(instance)).items():
        instance.__dict__[attribute] = declaration.entry(state, owner, parameters)


def _default_parameters(cls: type) -> Any:
    """The class's parameters at their defaults (what its modify values start at), or None."""
    try:
        parameters = getattr(cls, "Parameters", None)
        return parameters() if isinstance(parameters, type) else None
    except TypeError:  # a field without a default: those values appear when the module runs
        return None


def describe_outputs(modules: list[type]) -> list[str]:
    """Lines listing the declared debug outputs of ``modules`` by module (for ``tafel modules``)."""
    lines = []
    for cls in modules:
        declared = declared_outputs(cls)
        if declared:
            lines.append(f"debug outputs of {cls.__name__}:")
            lines.extend(f"  {line}" for d in declared.values() for line in d.describe().splitlines())
    return lines
