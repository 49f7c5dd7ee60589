"""The blackboard and the module manager that runs one context (cognition or motion) frame by frame."""

from __future__ import annotations

import logging
import time
import traceback
from collections.abc import Callable, Iterable, Iterator, Mapping, Sequence
from dataclasses import dataclass
from typing import Any, TypeVar

from tafel.core.framework.access import AccessMark, read_view, undo_writes, writer_view
from tafel.core.framework.errors import ModuleDefinitionError, UnknownModuleError
from tafel.core.framework.graph import Plan, build_plan, module_names, resolve_module
from tafel.core.framework.module import Module
from tafel.core.framework.naming import did_you_mean, snake_case
from tafel.core.framework.parameters import make_parameters
from tafel.core.framework.representation import reset

R = TypeVar("R")

#: frames over which mean and max execution times are computed
TIMING_WINDOW = 100


class Blackboard:
    """One instance of each representation of a context, looked up by class or by name.

    Instances are never replaced while modules run (modules hold views of them); values that arrive
    from outside are copied into them.
    """

    def __init__(self) -> None:
        self._by_type: dict[type, Any] = {}
        self._by_name: dict[str, type] = {}

    def __getitem__(self, rep: type[R]) -> R:
        try:
            return self._by_type[rep]
        except KeyError:
            name = getattr(rep, "__name__", repr(rep))
            raise KeyError(
                f"{name} is not on this blackboard; {did_you_mean(name, self._by_name)}"
            ) from None

    def __contains__(self, rep: object) -> bool:
        return rep in self._by_type

    def __iter__(self) -> Iterator[type]:
        return iter(self._by_type)

    def __len__(self) -> int:
        return len(self._by_type)

    def get(self, name: str) -> Any:
        """The instance of the representation named ``name``."""
        if name not in self._by_name:
            raise KeyError(f"no representation {name!r} on this blackboard; {did_you_mean(name, self._by_name)}")
        return self._by_type[self._by_name[name]]

    def find(self, name: str) -> Any:
        """The instance of the representation named ``name``, or None when the blackboard has none."""
        rep = self._by_name.get(name)
        return None if rep is None else self._by_type[rep]

    def names(self) -> list[str]:
        return sorted(self._by_name)

    def ensure(self, rep: type[R]) -> R:
        """The instance of ``rep``, created with its defaults if it is not there yet."""
        instance = self._by_type.get(rep)
        if instance is None:
            instance = self._by_type[rep] = rep()
            self._by_name[rep.__name__] = rep
        return instance

    def set(self, value: Any) -> None:
        """Copy the fields of ``value`` into this blackboard's instance of its class (shallow)."""
        self[type(value)].__dict__.update(value.__dict__)


@dataclass(frozen=True)
class ModuleTiming:
    """Execution time of one module in microseconds over the last ``TIMING_WINDOW`` frames."""

    last_us: float
    mean_us: float
    max_us: float
    frames: int
    errors: int


class _Slot:
    """Everything the manager keeps for one running module; plain slots keep the frame loop fast."""

    __slots__ = ("name", "cls", "instance", "run", "times", "first_frame", "errors", "last_error",
                 "undo", "read_marks", "write_marks", "chosen", "logged_at", "logged_errors")

    def __init__(self, cls: type[Module], frame: int) -> None:
        self.name = cls.__name__
        self.cls = cls
        self.instance: Any = None
        self.run: Callable[[], None] = lambda: None
        self.times = [0] * TIMING_WINDOW
        self.first_frame = frame
        self.errors = 0
        self.last_error = ""
        self.undo: list[tuple[Any, str, Any]] = []
        self.read_marks: list[tuple[str, AccessMark]] = []
        self.write_marks: list[tuple[str, AccessMark]] = []
        self.chosen: frozenset[type] = frozenset()
        self.logged_at = 0.0  # monotonic s of the last log line about this module's errors
        self.logged_errors = 0  # errors counted when that line was written


def _chosen_outputs(cls: type[Module], plan: Plan) -> frozenset[type]:
    """The representations ``cls`` writes to the blackboard under ``plan``."""
    return frozenset(r for r in cls.requirements().provides if plan.provider.get(r) is cls)


#: s between log lines about one module's repeated errors
ERROR_LOG_INTERVAL_S = 1.0


class ModuleManager:
    """Runs a list of module classes in dependency order on its own blackboard.

    ``external`` names the representations that something outside provides (a platform, the other
    context); ``providers`` picks a module where several provide one representation (by names). Broken
    configurations raise a ``ModuleGraphError`` subclass here and in ``set_provider``/``set_enabled``.
    With ``strict`` an exception in a module propagates out of ``execute``; otherwise it is logged,
    counted, and the frame goes on with the module's representations at their previous values.
    ``parameters`` maps module names to parameter values (see ``core.parameters``); ``disabled``
    names modules that start switched off.
    """

    def __init__(
        self,
        modules: Sequence[type[Module]],
        *,
        name: str = "cognition",
        external: Iterable[type] = (),
        providers: Mapping[str, str] | None = None,
        strict: bool = False,
        parameters: Mapping[str, Mapping[str, Any]] | None = None,
        disabled: Iterable[str] = (),
    ) -> None:
        self.name = name
        self.strict = strict
        self.frame = 0
        #: the module running now, "" between modules (read by the watchdog from another thread)
        self.running = ""
        self.blackboard = Blackboard()
        self.log = logging.getLogger(f"tafel.{name}")
        #: called before and after each frame (for example debug commands between frames)
        self.before_frame: list[Callable[[], None]] = []
        self.after_frame: list[Callable[[], None]] = []
        #: this context's debug outputs (``tafel.debug``'s ``DebugState``), made by the first module that
        #: declares some; core never looks inside
        self.debug: Any = None
        self._modules = list(modules)
        self._by_name = module_names(self._modules)
        # the module set is fixed for the manager's life: its declarations are read once (tools ask often)
        self._requirements = {m: m.requirements() for m in self._modules}
        self._alternatives: dict[str, list[str]] = {}
        for m, req in self._requirements.items():
            for rep in req.provides:
                self._alternatives.setdefault(rep.__name__, []).append(m.__name__)
        self._external = list(dict.fromkeys(external))
        self._providers = dict(providers or {})
        self._disabled: set[str] = set(disabled)
        self._parameters = {name: dict(values) for name, values in (parameters or {}).items()}
        for module_name in self._parameters:
            resolve_module(module_name, self._by_name)
        self._slots: list[_Slot] = []
        self._marks: list[AccessMark] = []
        #: module name -> [errors since the start, the last one]: kept when its instance goes (switched off,
        #: reloaded, rolled back), so a run's summary counts every failure
        self._error_totals: dict[str, list[Any]] = {}
        effective = {r: m for r, m in self._providers.items() if m not in self._disabled}
        plan = build_plan(self._modules, external=self._external, providers=effective, disabled=self._disabled)
        self._plan = self._apply(plan, {})

    # ------------------------------------------------------------------ running
    def execute(self) -> None:
        """Run one frame: every active module once, in order."""
        for hook in self.before_frame:
            hook()
        self.frame += 1
        for mark in self._marks:
            mark.touched = False
        clock = time.perf_counter_ns
        index = self.frame % TIMING_WINDOW
        last = clock()
        for slot in self._slots:
            self.running = slot.name
            try:
                slot.run()
            except Exception as exc:
                self._failed(slot, exc)
            else:
                if slot.undo:
                    slot.undo.clear()
            now = clock()
            slot.times[index] = now - last
            last = now
        self.running = ""
        for hook in self.after_frame:
            hook()

    def _failed(self, slot: _Slot, exc: Exception) -> None:
        undo_writes(slot.undo)
        if self.strict:
            raise exc
        slot.errors += 1
        slot.last_error = f"{type(exc).__name__}: {exc}"
        total = self._error_totals.setdefault(slot.name, [0, ""])
        total[0], total[1] = total[0] + 1, slot.last_error
        # The traceback once; after that at most one line a second with the count, so that a module
        # failing every frame cannot flood the log (or slow the loop down with logging).
        now = time.monotonic()
        if slot.errors == 1:
            self.log.error(
                "%s: module %s failed in frame %d: %s\n%s", self.name, slot.name, self.frame, slot.last_error,
                "".join(traceback.format_exception(exc)).rstrip(),
            )
        elif now - slot.logged_at < ERROR_LOG_INTERVAL_S:
            return
        else:
            self.log.error("%s: module %s failed %d more times (%d in all), last in frame %d: %s", self.name, slot.name,
                           slot.errors - slot.logged_errors, slot.errors, self.frame, slot.last_error)
        slot.logged_at, slot.logged_errors = now, slot.errors

    # ------------------------------------------------------------------ inspection
    @property
    def order(self) -> list[str]:
        """Names of the active modules in execution order."""
        return [slot.name for slot in self._slots]

    @property
    def modules(self) -> list[str]:
        """Names of all modules known to this manager, active or not."""
        return [m.__name__ for m in self._modules]

    @property
    def module_classes(self) -> list[type[Module]]:
        """All module classes known to this manager, active or not."""
        return list(self._modules)

    @property
    def external(self) -> list[type]:
        return list(self._external)

    def module_class(self, name: str) -> type[Module]:
        """The class of the configured module ``name`` (``UnknownModuleError`` with the closest names)."""
        return resolve_module(name, self._by_name)

    def module(self, name: str) -> Any:
        """The running instance of module ``name``."""
        for slot in self._slots:
            if slot.name == name:
                return slot.instance
        resolve_module(name, self._by_name)
        raise KeyError(f"module {name} is not running in {self.name} (disabled or not chosen as provider)")

    def is_enabled(self, name: str) -> bool:
        resolve_module(name, self._by_name)
        return name not in self._disabled

    def provider_of(self, rep_name: str) -> str | None:
        """Name of the module providing ``rep_name``; None when it comes from outside."""
        for rep, module in self._plan.provider.items():
            if rep.__name__ == rep_name:
                return module.__name__ if module else None
        raise UnknownModuleError(f"{rep_name} is not on the {self.name} blackboard; {did_you_mean(rep_name, self.blackboard.names())}")

    def alternatives(self, rep_name: str) -> list[str]:
        """Every module that could provide ``rep_name`` (enabled or not)."""
        return list(self._alternatives.get(rep_name, ()))

    def last_times_ms(self) -> tuple[list[str], list[float]]:
        """(module names, how long each ran in the last frame in ms), cheap enough for every frame."""
        index = self.frame % TIMING_WINDOW
        return [slot.name for slot in self._slots], [slot.times[index] / 1e6 for slot in self._slots]

    def timings(self) -> dict[str, ModuleTiming]:
        """Execution times per running module (window of the last ``TIMING_WINDOW`` frames)."""
        result = {}
        for slot in self._slots:
            runs = self.frame - slot.first_frame
            n = min(runs, TIMING_WINDOW)
            recent = [slot.times[(self.frame - i) % TIMING_WINDOW] for i in range(n)]
            result[slot.name] = ModuleTiming(
                last_us=recent[0] / 1e3 if recent else 0.0,
                mean_us=sum(recent) / n / 1e3 if n else 0.0,
                max_us=max(recent) / 1e3 if recent else 0.0,
                frames=runs,
                errors=slot.errors,
            )
        return result

    def p95_us(self, name: str) -> float:
        """95th percentile of a running module's execution time over the timing window (us)."""
        for slot in self._slots:
            if slot.name == name:
                n = min(self.frame - slot.first_frame, TIMING_WINDOW)
                if n <= 0:
                    return 0.0
                recent = sorted(slot.times[(self.frame - i) % TIMING_WINDOW] for i in range(n))
                return recent[int(0.95 * (n - 1))] / 1e3
        raise KeyError(f"module {name} is not running in {self.name}")

    def errors(self) -> dict[str, tuple[int, str]]:
        """Module name -> (error count, last error) for modules that failed at least once since the start,
        counting instances that no longer run (switched off, replaced by a hot reload, rolled back)."""
        return {name: (count, last) for name, (count, last) in self._error_totals.items()}

    def access(self) -> dict[str, dict[str, list[str]]]:
        """Per representation, which modules read it and which wrote it in the last frame."""
        result: dict[str, dict[str, list[str]]] = {
            rep.__name__: {"readers": [], "writers": []} for rep in self.blackboard
        }
        for slot in self._slots:
            for rep_name, mark in slot.read_marks:
                if mark.touched:
                    result[rep_name]["readers"].append(slot.name)
            for rep_name, mark in slot.write_marks:
                if mark.touched:
                    result[rep_name]["writers"].append(slot.name)
        return result

    def graph(self) -> dict[str, Any]:
        """The module graph as plain data (for tools, the debug server and ``tafel modules``)."""
        active = {slot.name for slot in self._slots}
        modules = []
        for m, req in self._requirements.items():
            modules.append({
                "name": m.__name__,
                "enabled": m.__name__ not in self._disabled,
                "active": m.__name__ in active,
                "requires": [r.__name__ for r in req.requires],
                "uses": [r.__name__ for r in req.uses],
                "provides": [r.__name__ for r in req.provides],
            })
        representations = {
            rep.__name__: {
                "provider": module.__name__ if module else None,
                "alternatives": self.alternatives(rep.__name__),
            }
            for rep, module in self._plan.provider.items()
        }
        return {
            "name": self.name,
            "order": self.order,
            "modules": modules,
            "representations": representations,
            "external": [r.__name__ for r in self._external],
        }

    def to_dot(self) -> str:
        """Graphviz DOT text of the graph: modules as boxes, representations as ellipses."""
        from tafel.core.framework.dot import manager_dot

        return manager_dot(self.graph())

    # ------------------------------------------------------------------ reconfiguration
    def set_provider(self, rep_name: str, module_name: str) -> None:
        """Make ``module_name`` the provider of ``rep_name`` (enabling it if it was disabled); raises
        and changes nothing if invalid."""
        name = resolve_module(module_name, self._by_name).__name__
        self._reconfigure({**self._providers, rep_name: name}, self._disabled - {name})

    def set_enabled(self, module_name: str, enabled: bool) -> None:
        """Enable or disable a module; raises and changes nothing if the graph would break.

        Provider choices are kept while their module is disabled, and apply again once it is enabled,
        so every sequence of switches can be undone.
        """
        name = resolve_module(module_name, self._by_name).__name__
        self._reconfigure(self._providers, self._disabled - {name} if enabled else self._disabled | {name})

    def _reconfigure(self, providers: Mapping[str, str], disabled: set[str]) -> None:
        effective = {r: m for r, m in providers.items() if m not in disabled}
        plan = build_plan(self._modules, external=self._external, providers=effective, disabled=disabled)
        self._plan = self._apply(plan, self._plan.provider)
        self._providers, self._disabled = dict(providers), set(disabled)

    @property
    def providers(self) -> dict[str, str]:
        """The explicit provider choices (representation name -> module name)."""
        return dict(self._providers)

    @property
    def disabled(self) -> set[str]:
        return set(self._disabled)

    def replace_module(self, new_cls: type[Module], parameters: Mapping[str, Any] | None = None,
                       slot: _Slot | None = None) -> _Slot | None:
        """Run ``new_cls`` instead of the module class of the same name, keeping the blackboard: hot reload.

        ``parameters`` are the new instance's values (names the new class lacks are the caller's to drop);
        ``slot`` brings back a slot taken out before (its instance, with its state: a rollback). Returns
        the slot taken out. Raises, and changes nothing, when the graph would break or the constructor fails.
        """
        old_cls = resolve_module(new_cls.__name__, self._by_name)
        modules = [new_cls if m is old_cls else m for m in self._modules]
        effective = {r: m for r, m in self._providers.items() if m not in self._disabled}
        plan = build_plan(modules, external=self._external, providers=effective, disabled=self._disabled)
        saved = (self._modules, self._by_name, self._requirements, self._parameters)
        self._modules, self._by_name = modules, module_names(modules)
        self._requirements = {m: m.requirements() for m in modules}
        if parameters is not None:
            self._parameters = {**self._parameters, new_cls.__name__: dict(parameters)}
        taken = next((s for s in self._slots if s.cls is old_cls), None)
        old_provider = {rep: (new_cls if m is old_cls else m) for rep, m in self._plan.provider.items()}
        try:
            self._plan = self._apply(plan, old_provider, keep=[slot] if slot is not None else ())
        except BaseException:
            self._modules, self._by_name, self._requirements, self._parameters = saved
            raise
        self._alternatives = {}
        for m, req in self._requirements.items():
            for rep in req.provides:
                self._alternatives.setdefault(rep.__name__, []).append(m.__name__)
        return taken

    def slot_of(self, name: str) -> _Slot | None:
        """The running slot of the module ``name`` (None while it is disabled or idle)."""
        return next((s for s in self._slots if s.name == name), None)

    # ------------------------------------------------------------------ internals
    def _apply(self, plan: Plan, old_provider: Mapping[type, type[Module] | None], keep: Iterable[_Slot] = ()) -> Plan:
        """Switch to a checked plan: keep running instances, create new ones, reset changed outputs.

        New instances are built before anything changes, so a failing constructor leaves the running
        graph as it was. ``keep`` are slots to run again that are not running now (a rollback).
        """
        for rep in plan.provider:
            self.blackboard.ensure(rep)
        for m in plan.order:
            for rep in m.requirements().reads():
                self.blackboard.ensure(rep)
        kept = {slot.cls: slot for slot in (*self._slots, *keep)}
        slots = []
        for m in plan.order:
            slot = kept.get(m)
            if slot is None or slot.chosen != _chosen_outputs(m, plan):
                slot = _Slot(m, self.frame)
                self._instantiate(slot, plan)
            slots.append(slot)
        for rep, module in plan.provider.items():
            if rep in old_provider and old_provider[rep] is not module:
                reset(self.blackboard[rep])
        self._slots = slots
        self._marks = [mark for s in slots for _, mark in (*s.read_marks, *s.write_marks)]
        return plan

    def _instantiate(self, slot: _Slot, plan: Plan) -> None:
        cls = slot.cls
        instance = cls.__new__(cls)
        req = cls.requirements()
        for rep in req.reads():
            mark = AccessMark()
            object.__setattr__(instance, snake_case(rep.__name__), read_view(self.blackboard[rep], cls.__name__, mark))
            slot.read_marks.append((rep.__name__, mark))
        for rep in req.provides:
            # A module running as provider of something else writes unchosen outputs to a private copy.
            target = self.blackboard[rep] if plan.provider.get(rep) is cls else rep()
            mark = AccessMark()
            object.__setattr__(instance, snake_case(rep.__name__), writer_view(target, mark, slot.undo, cls.__name__))
            slot.write_marks.append((rep.__name__, mark))
        object.__setattr__(instance, "parameters", make_parameters(cls, self._parameters.get(cls.__name__)))
        attach = getattr(cls, "__tafel_attach__", None)
        if attach is not None:  # class-level declarations that take this context's values (tafel.debug's outputs)
            attach(instance, self)
        try:
            cls.__init__(instance)
        except Exception as exc:
            rule = " (a module's constructor takes no arguments)" if isinstance(exc, TypeError) else ""
            raise ModuleDefinitionError(f"constructing {cls.__name__} failed{rule}: {exc}") from exc
        slot.chosen = _chosen_outputs(cls, plan)
        slot.instance = instance
        slot.run = instance.execute


def make_module(cls: type[Module], **attributes: Any) -> Module:
    """A module instance wired to plain objects, bypassing the blackboard (for baselines and tools)."""
    instance = cls.__new__(cls)
    for name, value in attributes.items():
        object.__setattr__(instance, name, value)
    cls.__init__(instance)
    return instance
