"""Modules: the executable units. They declare what they read and write, and nothing else.

    @requires(BallPercept)
    @provides(BallModel)
    class SimpleBallModeler(Module):
        def execute(self) -> None:
            self.ball_model.x_mm = self.ball_percept.x_mm

``requires`` gives read access and orders the module after the provider; ``uses`` gives read access
without an ordering edge (the previous frame's value when the provider runs later: feedback loops);
``provides`` gives write access. Each representation is reached as the snake_case attribute of its
class name. The declarations are static: ``SimpleBallModeler.requirements()`` reads them without
running anything.

For type checkers a module may annotate, in its class body, what it reads and writes and its parameters
(``ball_percept: BallPercept``, ``parameters: Parameters``). The annotations are optional, but the ones
given are checked against the decorators when the class is made, so the two cannot drift: an annotated
representation must be declared, under its own attribute name, and ``parameters`` must name the class's
``Parameters``. Whether every annotated representation is declared at all is known only after the last
decorator, so that is checked when the declarations are first read (``requirements()``: by the manager,
the harness, ``tafel modules``).
"""

from __future__ import annotations

import sys
import weakref
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, TypeVar

from tafel.core.framework.errors import ModuleDefinitionError
from tafel.core.framework.naming import snake_case
from tafel.core.framework.parameters import parameters_class
from tafel.core.framework.representation import is_representation

M = TypeVar("M", bound=type)

_KINDS = ("requires", "uses", "provides")


@dataclass(frozen=True)
class Requirements:
    """What a module class declares, in declaration order."""

    requires: tuple[type, ...]
    uses: tuple[type, ...]
    provides: tuple[type, ...]

    def attribute_names(self) -> dict[str, type]:
        """Attribute name on the module -> representation class, for everything declared."""
        return {snake_case(r.__name__): r for r in (*self.requires, *self.uses, *self.provides)}

    def reads(self) -> tuple[type, ...]:
        return self.requires + self.uses


class Module:
    """Base class of all modules. Subclasses implement ``execute``; the constructor takes no arguments."""

    __tafel_requires__: tuple[type, ...] = ()
    __tafel_uses__: tuple[type, ...] = ()
    __tafel_provides__: tuple[type, ...] = ()

    def __init_subclass__(cls, **kwargs: Any) -> None:
        super().__init_subclass__(**kwargs)
        previous = _KNOWN.get(cls.__name__)
        if previous is not None and (previous.__module__, previous.__qualname__) != (cls.__module__, cls.__qualname__):
            raise ModuleDefinitionError(
                f"two module classes are named {cls.__name__!r}: {previous.__module__}.{previous.__qualname__} and "
                f"{cls.__module__}.{cls.__qualname__}; module names must be unique because configuration, logs and "
                "debug commands refer to modules by name. Rename one of them."
            )
        _KNOWN[cls.__name__] = cls
        _check_annotations(cls, complete=False)

    def execute(self) -> None:
        """Called once per frame, after every module whose representations this one requires."""
        raise NotImplementedError(f"{type(self).__name__} must implement execute(self)")

    @classmethod
    def requirements(cls) -> Requirements:
        """The representations this class (and its base classes) requires, uses and provides.

        The first call also checks that every representation the class annotates is declared.
        """
        declared = _declared(cls)
        if cls not in _CHECKED:
            _check_annotations(cls, complete=True)
            _CHECKED.add(cls)
        return declared

    def __setattr__(self, name: str, value: Any) -> None:
        reps = _attribute_names(type(self))
        if name in reps:
            raise AttributeError(
                f"{type(self).__name__}.{name} is the blackboard's {reps[name].__name__} and cannot be "
                f"replaced; assign its fields instead (self.{name}.field = value)"
            )
        object.__setattr__(self, name, value)



class _Unbound:
    """Class-level placeholder for a declared representation; the manager's instance value hides it.

    A non-data descriptor, so reading the bound attribute costs nothing extra.
    """

    def __init__(self, rep: type) -> None:
        self.rep = rep

    def __set_name__(self, owner: type, name: str) -> None:
        self.name = name

    def __get__(self, instance: Any, owner: type) -> Any:
        if instance is None:
            return self
        raise AttributeError(
            f"{owner.__name__}.{snake_case(self.rep.__name__)} is not connected to a blackboard: modules "
            "get their representations from a ModuleManager; in tests use the run_module fixture or "
            "tafel.core.testing.ModuleHarness"
        )


_ATTRIBUTE_NAMES: dict[type, dict[str, type]] = {}
_KNOWN: dict[str, type[Module]] = {}
#: module classes whose annotations were checked against their complete declarations
_CHECKED: weakref.WeakSet[type] = weakref.WeakSet()
_UNRESOLVED = object()


def _declared(cls: type) -> Requirements:
    """What ``cls`` and its base classes declare so far (no annotation check: decorators call it midway)."""
    collected: dict[str, list[type]] = {k: [] for k in _KINDS}
    for klass in reversed(cls.__mro__):
        for kind in _KINDS:
            for rep in klass.__dict__.get(f"__tafel_{kind}__", ()):
                if rep not in collected[kind]:
                    collected[kind].append(rep)
    return Requirements(*(tuple(collected[k]) for k in _KINDS))


def _class_annotations(cls: type) -> dict[str, tuple[Any, type]]:
    """name -> (annotation, class that wrote it) for the class-level annotations of ``cls`` and its bases
    below ``Module``; a subclass's annotation hides its base's."""
    found: dict[str, tuple[Any, type]] = {}
    for klass in cls.__mro__:
        if klass is Module or klass is object:
            continue
        for name, annotation in klass.__dict__.get("__annotations__", {}).items():
            found.setdefault(name, (annotation, klass))
    return found


def _resolve(annotation: Any, owner: type) -> Any:
    """The object an annotation names (``from __future__ import annotations`` makes it a string), looked up
    like ``typing.get_type_hints`` does: the defining file's globals, then the class body; ``_UNRESOLVED``
    if it cannot be evaluated (a name imported only for type checking, a class local to a function)."""
    if not isinstance(annotation, str):
        return annotation
    module = sys.modules.get(owner.__module__)
    try:
        return eval(annotation, vars(module) if module else {}, dict(vars(owner)))  # as typing.get_type_hints does
    except Exception:
        return _UNRESOLVED


def _names(annotation: Any, resolved: Any, expected: type) -> bool:
    """True if the annotation is ``expected``, or, unresolvable, spells its class name (``"BallModel"``,
    ``"representations.BallModel"``): a representation defined inside a test function is still accepted."""
    if resolved is _UNRESOLVED:
        return isinstance(annotation, str) and annotation.rsplit(".", 1)[-1] == expected.__name__
    return resolved is expected


def _check_annotations(cls: type, *, complete: bool) -> None:
    """Raise ``ModuleDefinitionError`` where a class-level annotation contradicts the declarations.

    ``complete``: all decorators have run, so an annotated representation that is not declared is an error.
    """
    declared = _declared(cls)
    kinds = {snake_case(rep.__name__): (rep, kind) for kind in _KINDS for rep in getattr(declared, kind)}
    for name, (annotation, owner) in _class_annotations(cls).items():
        resolved = _resolve(annotation, owner)
        shown = annotation if isinstance(annotation, str) else getattr(annotation, "__name__", repr(annotation))
        if name == "parameters":
            expected = parameters_class(cls)
            if expected is None:
                raise ModuleDefinitionError(
                    f"{cls.__name__} annotates parameters: {shown} but has no Parameters dataclass; declare "
                    "`@dataclass class Parameters:` in the class body or remove the annotation")
            fits = isinstance(resolved, type) and issubclass(expected, resolved)  # a base's Parameters is a safe view
            if not (fits or _names(annotation, resolved, expected)):
                raise ModuleDefinitionError(
                    f"{cls.__name__} annotates parameters: {shown} but its parameters are "
                    f"{expected.__qualname__}; annotate parameters: Parameters")
        elif name in kinds:
            rep, kind = kinds[name]
            if not _names(annotation, resolved, rep):
                unresolved = " (which cannot be resolved at run time)" if resolved is _UNRESOLVED else ""
                raise ModuleDefinitionError(
                    f"{cls.__name__} annotates {name}: {shown}{unresolved} but {name} is the {rep.__name__} it "
                    f"declares in @{kind}; annotate {name}: {rep.__name__}, imported at module level")
        elif isinstance(resolved, type) and is_representation(resolved):
            attribute = snake_case(resolved.__name__)
            if name != attribute:
                raise ModuleDefinitionError(
                    f"{cls.__name__} annotates {name}: {resolved.__name__}, but a module reaches {resolved.__name__} "
                    f"as {attribute}; annotate {attribute}: {resolved.__name__}")
            if complete:
                raise ModuleDefinitionError(
                    f"{cls.__name__} annotates {name}: {resolved.__name__} but does not @requires/@uses/@provides "
                    f"{resolved.__name__}; add @requires({resolved.__name__}) or remove the annotation")


def find_module(name: str) -> type[Module]:
    """The module class called ``name`` (or ``package.module:ClassName``), with suggestions if unknown.

    Every Module subclass registers itself by class name when it is defined (the newest definition of a
    name wins); ``tools`` imports the ``modules`` package so that all of them are known. A name of the
    form ``package.module:ClassName`` is imported on demand.
    """
    from tafel.core.framework.errors import UnknownModuleError
    from tafel.core.framework.naming import did_you_mean

    if ":" in name:
        import importlib

        path, _, attribute = name.partition(":")
        try:
            cls = getattr(importlib.import_module(path), attribute)
        except (ImportError, AttributeError) as exc:
            raise UnknownModuleError(f"cannot import module class {name!r}: {exc}") from None
        if not (isinstance(cls, type) and issubclass(cls, Module)):
            raise UnknownModuleError(f"{name!r} is not a Module subclass")
        return cls
    if name in _KNOWN:
        return _KNOWN[name]
    raise UnknownModuleError(f"unknown module {name!r}: {did_you_mean(name, _KNOWN)}")


def _attribute_names(cls: type[Module]) -> dict[str, type]:
    names = _ATTRIBUTE_NAMES.get(cls)
    if names is None:
        names = _ATTRIBUTE_NAMES[cls] = cls.requirements().attribute_names()
    return names


def _declare(kind: str, reps: tuple[type, ...]) -> Callable[[M], M]:
    for rep in reps:
        if not is_representation(rep):
            raise ModuleDefinitionError(
                f"@{kind}() takes representation classes (decorated with @representation), got {rep!r}"
            )

    def decorate(cls: M) -> M:
        if not (isinstance(cls, type) and issubclass(cls, Module)):
            raise ModuleDefinitionError(f"@{kind} decorates Module subclasses, not {cls!r}")
        own = list(cls.__dict__.get(f"__tafel_{kind}__", ()))
        current = _declared(cls)
        for rep in reps:
            for other in _KINDS:
                if other != kind and rep in getattr(current, other):
                    raise ModuleDefinitionError(
                        f"{cls.__name__} declares {rep.__name__} both in @{kind} and in @{other}; "
                        "a module requires or uses what others provide, or provides it itself, not both"
                    )
            if rep not in own:
                own.append(rep)
        for rep in reps:
            attribute = snake_case(rep.__name__)
            clash = getattr(cls, attribute, None)
            if clash is not None and not isinstance(clash, _Unbound):
                raise ModuleDefinitionError(
                    f"{cls.__name__}.{attribute} is already defined, but it is also the attribute name of "
                    f"{rep.__name__}; rename the method or attribute"
                )
            setattr(cls, attribute, _Unbound(rep))
        setattr(cls, f"__tafel_{kind}__", tuple(own))
        _ATTRIBUTE_NAMES.clear()
        _CHECKED.discard(cls)
        _check_annotations(cls, complete=False)
        return cls

    return decorate


def requires(*reps: type) -> Callable[[M], M]:
    """Read access to ``reps``; the module runs after their providers."""
    return _declare("requires", reps)


def uses(*reps: type) -> Callable[[M], M]:
    """Read access to ``reps`` without an ordering edge (last frame's value if the provider runs later)."""
    return _declare("uses", reps)


def provides(*reps: type) -> Callable[[M], M]:
    """Write access to ``reps``; this module computes them."""
    return _declare("provides", reps)
