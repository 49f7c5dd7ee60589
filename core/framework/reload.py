"""Hot reload: a module's new code replaces the running instance at a frame boundary, keeping the blackboard.

``ModuleReloader`` belongs to one context's ``ModuleManager``. ``reload(name)`` runs between frames
(debug commands do): it imports the module's source file again, checks what the new code declares and
swaps the instance (``ModuleManager.replace_module``). Parameters carry over where their names still
exist. What cannot run is refused and the old code keeps running:

- a file that fails to import (a syntax error, an exception at import);
- a module graph that breaks (new requirements without a provider, a cycle) or a constructor that fails;
- a representation defined in that file whose fields changed: instances of the old class are on the
  blackboard and in the other context, so that needs a restart.

A new version that raises in its first ``probation_frames`` frames is rolled back: the old instance,
with its state, runs again from the next frame. Every outcome is in ``events`` (and the log).
"""

from __future__ import annotations

import dataclasses
import importlib
import importlib.util
import logging
import sys
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from tafel.core.framework.errors import TafelError
from tafel.core.framework.module import _KNOWN, Module
from tafel.core.framework.representation import _REGISTRY, fields_of, is_representation

log = logging.getLogger("tafel.reload")

#: frames a reloaded module must run without an exception before it is kept
PROBATION_FRAMES = 10


class ReloadError(TafelError):
    """A reload that was refused; the old code keeps running. The message says why."""


@dataclass
class Probation:
    """A reloaded module on trial: the old slot comes back if the new one fails."""

    name: str
    old_slot: Any
    errors_before: int
    until_frame: int


@dataclass
class ModuleReloader:
    """Reloads the modules of one context's manager from their source files, with rollback."""

    manager: Any
    probation_frames: int = PROBATION_FRAMES
    #: what happened, newest last: "reloaded X ...", "rolled back X: ...", "refused X: ..."
    events: list[str] = field(default_factory=list)
    on_event: Callable[[str], None] | None = None
    _probations: dict[str, Probation] = field(default_factory=dict)

    def __post_init__(self) -> None:
        self.manager.after_frame.append(self._judge)

    def reload(self, name: str) -> str:
        """Import the module ``name``'s file again and run its new class from the next frame; returns
        what was done. Call between frames. ``ReloadError`` when refused (the old code keeps running)."""
        old_cls = self.manager.module_class(name)
        source = sys.modules.get(old_cls.__module__)
        if source is None or getattr(source, "__file__", None) is None:
            raise self._refuse(name, f"{old_cls.__module__} has no source file to read again")
        started = time.perf_counter()
        new_cls = self._import_again(name, source, old_cls)
        old_slot = self.manager.slot_of(name)
        carried, dropped = self._parameters(old_slot, new_cls)
        try:
            taken = self.manager.replace_module(new_cls, carried if carried is not None else None)
        except Exception as exc:  # noqa: BLE001 - the graph's and the constructor's errors alike
            _KNOWN[name] = old_cls
            raise self._refuse(name, f"{type(exc).__name__}: {exc}") from None
        new_slot = self.manager.slot_of(name)
        if taken is not None and new_slot is not None:
            self._probations[name] = Probation(name, taken, new_slot.errors, self.manager.frame + self.probation_frames)
        kept = ", ".join(sorted(carried or {})) or "none"
        message = (f"reloaded {name} from {source.__file__} in {(time.perf_counter() - started) * 1e3:.1f} ms at frame "
                   f"{self.manager.frame}; parameters kept: {kept}"
                   + (f"; dropped (no longer declared): {', '.join(dropped)}" if dropped else "")
                   + (f"; on probation for {self.probation_frames} frames" if name in self._probations else ""))
        return self._event(message)

    # ------------------------------------------------------------------------------------ internals
    def _import_again(self, name: str, source: Any, old_cls: type) -> type:
        """The module file imported anew; its representations kept as they were (or the reload refused)."""
        old_reps = {n: c for n, c in _REGISTRY.items() if c.__module__ == source.__name__}
        old_modules = {n: c for n, c in _KNOWN.items() if c.__module__ == source.__name__}
        try:
            # a file edited twice within its modification time's resolution would load a stale cache
            Path(importlib.util.cache_from_source(source.__file__)).unlink(missing_ok=True)
        except (NotImplementedError, ValueError, OSError):
            pass
        def restore() -> None:
            """The registries as they were before the import: nothing of a refused version stays known."""
            for registry, old in ((_REGISTRY, old_reps), (_KNOWN, old_modules)):
                for added in [n for n, c in registry.items() if c.__module__ == source.__name__ and n not in old]:
                    del registry[added]
                registry.update(old)
            for restored in (*old_reps.values(), *old_modules.values()):
                setattr(source, restored.__name__, restored)

        try:
            importlib.reload(source)
        except BaseException as exc:  # noqa: BLE001 - a user's file may raise anything, even SystemExit
            restore()
            raise self._refuse(name, f"{source.__file__} does not import: {type(exc).__name__}: {exc}") from None
        changed = []
        for rep_name, old in old_reps.items():
            new = _REGISTRY.get(rep_name)
            if new is not None and new is not old and _shape(new) != _shape(old):
                changed.append(rep_name)
        if changed:
            restore()
            raise self._refuse(name, f"the fields of {', '.join(changed)} changed; a representation's shape cannot change "
                                     "while the program runs: restart it")
        _REGISTRY.update(old_reps)  # the blackboards hold the old classes: everyone keeps using them
        for value in list(vars(source).values()):
            if isinstance(value, type) and is_representation(value) and value.__name__ in old_reps:
                setattr(source, value.__name__, old_reps[value.__name__])
        new_cls = getattr(source, old_cls.__name__, None)
        if not (isinstance(new_cls, type) and issubclass(new_cls, Module)) or new_cls is old_cls:
            restore()
            raise self._refuse(name, f"{source.__file__} no longer defines the module class {name}")
        _rebind(new_cls, old_reps)
        return new_cls

    def _parameters(self, old_slot: Any, new_cls: type) -> tuple[dict[str, Any] | None, list[str]]:
        """The running parameter values the new class still declares, and the names it dropped."""
        old = getattr(old_slot.instance, "parameters", None) if old_slot is not None else None
        new_type = getattr(new_cls, "Parameters", None)
        if old is None or new_type is None or not dataclasses.is_dataclass(new_type):
            return None, []
        declared = {f.name for f in dataclasses.fields(new_type)}
        values = {f.name: getattr(old, f.name) for f in dataclasses.fields(old)}
        return {k: v for k, v in values.items() if k in declared}, sorted(set(values) - declared)

    def _judge(self) -> None:
        """After each frame: a module on probation that raised goes back to its old version."""
        for name, trial in list(self._probations.items()):
            slot = self.manager.slot_of(name)
            if slot is not None and slot.errors > trial.errors_before:
                del self._probations[name]
                error = slot.last_error
                try:
                    _KNOWN[name] = trial.old_slot.cls
                    self.manager.replace_module(trial.old_slot.cls, slot=trial.old_slot)
                except Exception as exc:  # noqa: BLE001 - should not happen: the old graph ran a frame ago
                    self._event(f"rolling back {name} failed: {exc}; the new version keeps running", error=True)
                    continue
                self._event(f"rolled back {name} at frame {self.manager.frame}: the new version raised {error}; the old "
                            "one runs again with its state", error=True)
            elif self.manager.frame >= trial.until_frame:
                del self._probations[name]

    def _refuse(self, name: str, why: str) -> ReloadError:
        return ReloadError(self._event(f"refused to reload {name}: {why}; the old version keeps running", error=True))

    def _event(self, message: str, error: bool = False) -> str:
        self.events.append(message)
        (log.error if error else log.info)(message)
        if self.on_event is not None:
            self.on_event(message)
        return message


def _shape(cls: type) -> list[tuple[str, str]]:
    return [(f.name, repr(f)) for f in fields_of(cls)]


def _rebind(cls: type, reps: dict[str, type]) -> None:
    """Point the module's declarations, and its class-level annotations (made from the file's new classes where
    the file defines a representation and has no ``from __future__ import annotations``), at the representation
    classes already on the blackboards."""
    for kind in ("requires", "uses", "provides"):
        attribute = f"__tafel_{kind}__"
        if attribute in cls.__dict__:
            setattr(cls, attribute, tuple(reps.get(r.__name__, r) for r in cls.__dict__[attribute]))
    annotations = cls.__dict__.get("__annotations__", {})
    for name, hint in annotations.items():
        if isinstance(hint, type) and is_representation(hint) and hint.__name__ in reps:
            annotations[name] = reps[hint.__name__]
