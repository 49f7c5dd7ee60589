"""The module graph: who provides what, which modules run, and in which order.

Pure functions over module classes; the ``ModuleManager`` builds a ``Plan`` whenever its configuration
changes and only swaps it in when it is valid, so a broken change never touches the running graph.
"""

from __future__ import annotations

import heapq
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass

from tafel.core.framework.errors import (
    ConflictingProvidersError,
    DependencyCycleError,
    MissingProviderError,
    ModuleDefinitionError,
    UnknownModuleError,
)
from tafel.core.framework.module import Module, Requirements
from tafel.core.framework.naming import did_you_mean
from tafel.core.framework.representation import is_representation


@dataclass
class Plan:
    """A valid configuration: active modules in execution order and the provider of each representation."""

    order: list[type[Module]]
    #: representation class -> providing module class, or None when it comes from outside
    provider: dict[type, type[Module] | None]


def module_names(modules: Sequence[type[Module]]) -> dict[str, type[Module]]:
    """Module classes by name; rejects non-modules and duplicate names."""
    by_name: dict[str, type[Module]] = {}
    for cls in modules:
        if not (isinstance(cls, type) and issubclass(cls, Module)):
            raise ModuleDefinitionError(f"module lists take Module subclasses, got {cls!r}")
        other = by_name.get(cls.__name__)
        if other is not None and other is not cls:
            raise ModuleDefinitionError(
                f"two modules are named {cls.__name__}: {other.__module__} and {cls.__module__}; "
                "module names must be unique within a manager"
            )
        by_name[cls.__name__] = cls
    return by_name


def resolve_module(name: str, by_name: Mapping[str, type[Module]], what: str = "module") -> type[Module]:
    try:
        return by_name[name]
    except KeyError:
        raise UnknownModuleError(f"unknown {what} {name!r}: {did_you_mean(name, by_name)}") from None


def build_plan(
    modules: Sequence[type[Module]],
    *,
    external: Iterable[type] = (),
    providers: Mapping[str, str] | None = None,
    disabled: Iterable[str] = (),
) -> Plan:
    """Check a configuration and compute its execution order; raise a ``ModuleGraphError`` if broken."""
    by_name = module_names(modules)
    external = list(dict.fromkeys(external))
    for rep in external:
        if not is_representation(rep):
            raise ModuleDefinitionError(f"external representations must be representation classes, got {rep!r}")
    disabled = set(disabled)
    for name in disabled:
        resolve_module(name, by_name)
    enabled = [m for m in modules if m.__name__ not in disabled]
    declared = {m: m.requirements() for m in modules}

    candidates: dict[type, list[type[Module]]] = {}
    for m in enabled:
        for rep in declared[m].provides:
            candidates.setdefault(rep, []).append(m)

    chosen = _choose_providers(modules, by_name, enabled, declared, candidates, external, providers or {})
    provider: dict[type, type[Module] | None] = {rep: None for rep in external}
    provider.update(chosen)

    active = [m for m in enabled if not declared[m].provides or any(chosen.get(r) is m for r in declared[m].provides)]
    _check_missing(active, declared, provider, modules, disabled, candidates)
    order = _topological_order(active, declared, provider)
    return Plan(order=order, provider=provider)


def _choose_providers(
    modules: Sequence[type[Module]],
    by_name: Mapping[str, type[Module]],
    enabled: list[type[Module]],
    declared: Mapping[type[Module], Requirements],
    candidates: dict[type, list[type[Module]]],
    external: list[type],
    providers: Mapping[str, str],
) -> dict[type, type[Module]]:
    all_reps = {r.__name__: r for m in modules for r in declared[m].provides}
    choices: dict[type, type[Module]] = {}
    for rep_name, module_name in providers.items():
        if rep_name not in all_reps:
            raise UnknownModuleError(
                f"providers names {rep_name!r}, but no module in this manager provides a representation "
                f"of that name: {did_you_mean(rep_name, all_reps)}"
            )
        rep = all_reps[rep_name]
        module = resolve_module(module_name, by_name)
        able = [m.__name__ for m in modules if rep in declared[m].provides]
        if module.__name__ not in able:
            raise UnknownModuleError(
                f"providers chooses {module_name} for {rep_name}, but {module_name} does not provide "
                f"{rep_name}; modules that do: {', '.join(able)}"
            )
        if module not in enabled:
            raise ConflictingProvidersError(
                f"providers chooses {module_name} for {rep_name}, but {module_name} is disabled; enable it "
                f"or choose one of {', '.join(m.__name__ for m in candidates.get(rep, [])) or 'nothing else'}"
            )
        choices[rep] = module

    chosen: dict[type, type[Module]] = {}
    for rep, modules_able in candidates.items():
        if rep in external:
            raise ConflictingProvidersError(
                f"{rep.__name__} is provided from outside this manager (platform, runtime or other context) and by "
                f"{', '.join(m.__name__ for m in modules_able)}; disable the module, or stop providing "
                f"{rep.__name__} externally"
            )
        if rep in choices:
            chosen[rep] = choices[rep]
        elif len(modules_able) == 1:
            chosen[rep] = modules_able[0]
        else:
            names = [m.__name__ for m in modules_able]
            raise ConflictingProvidersError(
                f"{rep.__name__} is provided by {' and '.join(names)}; choose one with "
                f'providers={{"{rep.__name__}": "{names[0]}"}} (in configuration: '
                f'{rep.__name__} = "{names[0]}" under [cognition.providers] or [motion.providers]), or disable the others'
            )
    return chosen


def _check_missing(
    active: list[type[Module]],
    declared: Mapping[type[Module], Requirements],
    provider: Mapping[type, type[Module] | None],
    modules: Sequence[type[Module]],
    disabled: set[str],
    candidates: Mapping[type, list[type[Module]]],
) -> None:
    problems = []
    for m in active:
        req = declared[m]
        # what a module only uses may be missing: it then reads the representation's defaults
        for rep in req.requires:
            if rep in provider:
                continue
            off = [o.__name__ for o in modules if o.__name__ in disabled and rep in declared[o].provides]
            hint = f" ({', '.join(off)} would, but is disabled)" if off else ""
            problems.append(
                f"{m.__name__} requires {rep.__name__}, but no module provides it{hint} and it is not "
                "provided from outside"
            )
    if problems:
        raise MissingProviderError(
            "; ".join(problems)
            + ". Add a module that provides it, enable the one that does, or let the platform provide it."
        )


def _topological_order(active: list[type[Module]], declared: Mapping[type[Module], Requirements],
                       provider: Mapping[type, type[Module] | None]) -> list[type[Module]]:
    index = {m: i for i, m in enumerate(active)}
    successors: dict[type[Module], list[tuple[type[Module], type]]] = {m: [] for m in active}
    indegree = {m: 0 for m in active}
    for m in active:
        for rep in declared[m].requires:
            source = provider.get(rep)
            if source is not None and source is not m and source in index:
                successors[source].append((m, rep))
                indegree[m] += 1
    ready = [(index[m], m.__name__) for m in active if indegree[m] == 0]
    heapq.heapify(ready)
    by_name = {m.__name__: m for m in active}
    order: list[type[Module]] = []
    while ready:
        _, name = heapq.heappop(ready)
        m = by_name[name]
        order.append(m)
        for succ, _rep in successors[m]:
            indegree[succ] -= 1
            if indegree[succ] == 0:
                heapq.heappush(ready, (index[succ], succ.__name__))
    if len(order) < len(active):
        remaining = [m for m in active if m not in order]
        raise _cycle_error(remaining, successors)
    return order


def _cycle_error(remaining: list[type[Module]], successors: Mapping[type[Module], list[tuple[type[Module], type]]]) -> DependencyCycleError:
    """Find one cycle among the modules left over by the sort and describe it as a path.

    Every left-over module still has a left-over predecessor (that is why it was left over), so walking
    predecessors must come back to a module already visited; that loop is a cycle.
    """
    left = set(remaining)
    predecessors: dict[type[Module], tuple[type[Module], type]] = {}
    for source in remaining:
        for target, rep in successors[source]:
            if target in left:
                predecessors.setdefault(target, (source, rep))
    walk: list[type[Module]] = []
    seen_at: dict[type[Module], int] = {}
    node = remaining[0]
    while node not in seen_at:
        seen_at[node] = len(walk)
        walk.append(node)
        node = predecessors[node][0]
    loop = list(reversed(walk[seen_at[node]:]))  # in edge direction: loop[i] provides to loop[i + 1]
    first = min(range(len(loop)), key=lambda i: remaining.index(loop[i]))
    loop = loop[first:] + loop[:first]
    cycle = [(m, predecessors[loop[(i + 1) % len(loop)]][1]) for i, m in enumerate(loop)]
    text = " -> ".join(f"{m.__name__}.{rep.__name__}" for m, rep in cycle) + f" -> {cycle[0][0].__name__}"
    return DependencyCycleError(
        f"dependency cycle: {text} (each module provides the representation that the next one requires). "
        "Break it by declaring one of these requirements with @uses instead of @requires (the module "
        "then reads the previous frame's value), or by choosing another provider.",
        [(m.__name__, rep.__name__) for m, rep in cycle],
    )


def prune_unsatisfiable(
    modules: Sequence[type[Module]], external: Iterable[type], disabled: Iterable[str] = ()
) -> dict[str, list[str]]:
    """Modules that cannot run because something they read is provided by nobody, transitively.

    Returns module name -> names of the representations it misses. A webcam platform, for example,
    provides no joint data, so every module that needs joints (and everything downstream) is pruned.
    """
    available_external = set(external)
    off = set(disabled)
    pruned: dict[str, list[str]] = {}
    remaining = [m for m in modules if m.__name__ not in off]
    while True:
        available = set(available_external)
        for m in remaining:
            available.update(m.requirements().provides)
        newly = {}
        for m in remaining:
            missing = [r.__name__ for r in m.requirements().reads() if r not in available]
            if missing:
                newly[m.__name__] = missing
        if not newly:
            return pruned
        pruned.update(newly)
        remaining = [m for m in remaining if m.__name__ not in newly]
