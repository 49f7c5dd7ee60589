"""A robot program: the contexts, their modules and what crosses between them and the platform.

``plan_program`` turns a merged configuration and a platform class into one ``ContextPlan`` per
context: the module classes, provider choices and parameters, what the platform provides and
consumes, what the runtime itself provides (``FrameInfo`` everywhere, ``CognitionStatus`` in motion),
which representations are handed over from the other context, and which modules had to be
pruned because nothing can provide what they read. Plans are plain picklable data, so the concurrent
runtime can send them to the processes that run the contexts.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

from tafel.core.framework.config import CONTEXTS, RATE, ConfigError, context_section
from tafel.core.framework.errors import ConflictingProvidersError, MissingProviderError
from tafel.core.framework.frame_info import FrameInfo
from tafel.core.framework.graph import build_plan
from tafel.core.framework.manager import ModuleManager
from tafel.core.framework.module import Module, find_module
from tafel.core.framework.values import convert, refusal
from tafel.core.runtime.platform import Platform
from tafel.core.runtime.status import CognitionStatus

DEFAULT_RATES = {"cognition": 30.0, "motion": 100.0}


@dataclass
class ContextPlan:
    """Everything needed to build one context's manager, in this or another process."""

    name: str
    rate_hz: float
    modules: list[type[Module]]
    providers: dict[str, str]
    disabled: list[str]
    parameters: dict[str, dict[str, Any]]
    platform_provides: list[type]
    platform_consumes: list[type]
    handover_in: list[type] = field(default_factory=list)
    handover_out: list[type] = field(default_factory=list)
    #: module name -> representations it reads that nothing can provide here
    pruned: dict[str, list[str]] = field(default_factory=dict)
    #: representations the platform consumes but no module provides (the platform gets defaults)
    unfed: list[str] = field(default_factory=list)
    #: module name -> representations it would provide that come from the platform instead
    replaced: dict[str, list[str]] = field(default_factory=dict)
    #: the platform feeds this context even if it provides no representation of it (``provides`` names
    #: the context with an empty tuple: a log that holds only the frame clock of a context)
    fed: bool = False

    @property
    def runtime_provides(self) -> list[type]:
        """What the runtime writes itself: the frame clock (``FrameInfo``) in a context it runs, and
        cognition's status in motion."""
        clock: list[type] = [FrameInfo] if self.runs else []
        return [*clock, CognitionStatus] if self.name == "motion" else clock

    @property
    def external(self) -> list[type]:
        """What comes from outside the context's modules: the runtime's, the platform's, the other context's."""
        clock: list[type] = [FrameInfo] if self.runs else []
        status: list[type] = [CognitionStatus] if self.name == "motion" else []  # the order blackboards always had
        return list(dict.fromkeys([*clock, *self.platform_provides, *self.handover_in, *status]))

    @property
    def runs(self) -> bool:
        """A context runs when the platform feeds it: its frames are driven by the platform's data."""
        return self.fed or bool(self.platform_provides)

    def representations(self) -> set[type]:
        """Every representation the context's blackboard may hold: from outside, and what its modules
        read or provide (disabled ones included: they may be switched on)."""
        reps = set(self.external)
        for module in self.modules:
            requirements = module.requirements()
            reps.update(requirements.reads(), requirements.provides)
        return reps

    def active_modules(self) -> list[type[Module]]:
        off = set(self.disabled) | set(self.pruned) | set(self.replaced)
        return [m for m in self.modules if m.__name__ not in off]

    def build_manager(self, strict: bool = False) -> ModuleManager:
        parameters = {m: v for m, v in self.parameters.items() if m in {c.__name__ for c in self.modules}}
        return ModuleManager(
            self.modules,
            name=self.name,
            external=self.external,
            providers=self.effective_providers(),
            strict=strict,
            parameters=parameters,
            disabled=self.effective_disabled(),
        )

    def effective_providers(self) -> dict[str, str]:
        """Provider choices for the modules that run here (a choice of a module another layer removed,
        or of a representation the platform provides instead, does not apply)."""
        running = {m.__name__ for m in self.active_modules()}
        from_platform = {r.__name__ for r in self.platform_provides}
        return {r: m for r, m in self.providers.items() if m in running and r not in from_platform}

    def effective_disabled(self) -> list[str]:
        listed = {m.__name__ for m in self.modules}
        return [name for name in (*self.disabled, *self.pruned, *self.replaced) if name in listed]


def plan_program(config: Mapping[str, Any], platform: type[Platform] | Platform, *, strict: bool = False) -> dict[str, ContextPlan]:
    """Context plans for ``config`` on ``platform``; raises ``ModuleGraphError``/``ConfigError`` if broken.

    ``platform`` is a class, or an instance where what it provides depends on its options (a log).
    A module whose outputs all come from the platform instead (a replayed ``BallPercept``) is switched
    off and reported as replaced. With ``strict``, a module that the platform cannot feed is an error
    instead of being pruned.
    """
    runtime = config.get("runtime", {})
    parameters = config.get("parameters", {})
    if not isinstance(parameters, Mapping):
        raise refusal("parameters", "a table of module tables ([parameters.BallDetector] and the like)", parameters, ConfigError)
    plans: dict[str, ContextPlan] = {}
    for context in CONTEXTS:
        section = context_section(config, context)
        modules = [find_module(name) for name in section["modules"]]
        for name in section["disabled"]:
            find_module(name)
        rate = float(convert(runtime.get(f"{context}_hz", DEFAULT_RATES[context]), float, where=f"runtime.{context}_hz",
                             bounds=RATE, unit="Hz", text=False, error=ConfigError))
        plans[context] = ContextPlan(
            name=context,
            rate_hz=rate,
            modules=modules,
            providers=section["providers"],
            disabled=section["disabled"],
            parameters={k: dict(v) for k, v in parameters.items() if isinstance(v, Mapping)},
            # the runtime writes the frame clock: a platform that still lists it does not provide it
            platform_provides=[r for r in platform.provides.get(context, ()) if r is not FrameInfo],
            platform_consumes=list(platform.consumes.get(context, ())),
            fed=context in platform.provides,
        )
    for module_name, values in parameters.items():  # after the module lists, which import modules given by path
        find_module(module_name)  # a misspelt module must not silently lose its parameters
        if not isinstance(values, Mapping):
            raise refusal(f"parameters.{module_name}", "a table of parameter values", values, ConfigError)
    for plan in plans.values():
        from_platform = set(plan.platform_provides)
        for module in plan.modules:
            outputs = module.requirements().provides
            if module.__name__ not in plan.disabled and outputs and any(r in from_platform for r in outputs):
                plan.replaced[module.__name__] = [r.__name__ for r in outputs if r in from_platform]
    for plan in plans.values():
        for module_name in plan.providers.values():
            find_module(module_name)
    _check_single_provider(plans)
    _route(plans)
    _check_missing_providers(plans, platform)
    for plan in plans.values():  # the graph of each context must hold before any process starts
        build_plan(plan.modules, external=plan.external, providers=plan.effective_providers(), disabled=plan.effective_disabled())
    if strict:
        problems = [
            f"{plan.name}: {module} needs {', '.join(missing)}"
            for plan in plans.values()
            for module, missing in plan.pruned.items()
        ]
        if problems:
            raise MissingProviderError(
                f"platform {platform.name!r} cannot feed these modules (--strict): " + "; ".join(problems)
                + ". Remove them from the configuration of this platform, or run without --strict to prune them."
            )
    return plans


def _check_missing_providers(plans: Mapping[str, ContextPlan], platform: type[Platform] | Platform) -> None:
    """A module is pruned quietly only for what this platform lacks: a representation that some
    platform provides, or that a configured module would compute were its own inputs there. One that
    nothing at all provides is a configuration error, and is reported as the missing provider it is."""
    computed = {r for plan in plans.values() for m in plan.modules for r in m.requirements().provides}
    missing = {(plan.name, module, rep) for plan in plans.values() for module, reps in plan.pruned.items() for rep in reps}
    suspects = {rep for _c, _m, rep in missing if rep not in {r.__name__ for r in computed}}
    if not suspects:
        return
    from_platforms = _provided_by_any_platform(platform)
    for context, module, rep in sorted(missing):
        if rep in suspects and rep not in from_platforms:
            raise MissingProviderError(
                f"{context}: {module} requires {rep}, but no module in the configuration provides it and no platform "
                f"does; add the module that provides {rep} to [{context}] modules (or [{_other(context)}] modules), "
                f"or remove {module}"
            )


def _provided_by_any_platform(current: type[Platform] | Platform) -> set[str]:
    """Names of the representations that some registered platform provides (platforms load lazily), and
    the frame clock, which the runtime writes in every context a platform feeds."""
    from tafel.core.runtime.platform import available_platforms

    names = {FrameInfo.__name__, *(r.__name__ for reps in current.provides.values() for r in reps)}
    for entry in available_platforms().values():
        try:
            cls = entry.load()
        except Exception:  # noqa: BLE001 - a platform that cannot load provides nothing here
            continue
        names |= {r.__name__ for reps in getattr(cls, "provides", {}).values() for r in reps}
    return names


def _provided(modules: list[type[Module]]) -> set[type]:
    return {rep for m in modules for rep in m.requirements().provides}


def _check_single_provider(plans: Mapping[str, ContextPlan]) -> None:
    cognition, motion = plans["cognition"], plans["motion"]
    both = _provided(cognition.active_modules()) & _provided(motion.active_modules())
    if both:
        names = ", ".join(sorted(r.__name__ for r in both))
        raise ConflictingProvidersError(
            f"{names} is provided in both contexts, by cognition and by motion modules; a representation "
            "has one provider in one context and is handed over to the other. Remove one provider."
        )


def _route(plans: Mapping[str, ContextPlan]) -> None:
    """Decide hand-overs and prune modules whose inputs nobody provides, until nothing changes.

    Only what modules compute crosses between contexts; platform and runtime data stay in the context
    they are given to (each context has its own clock in ``FrameInfo``, for example).
    """
    pruned: dict[str, dict[str, list[str]]] = {c: {} for c in plans}
    while True:
        remaining = {c: [m for m in p.modules if m.__name__ not in {*p.disabled, *p.replaced, *pruned[c]}] for c, p in plans.items()}
        computed = {c: _provided(remaining[c]) for c in plans}
        local = {c: {*plans[c].runtime_provides, *plans[c].platform_provides} | computed[c] for c in plans}
        changed = False
        for context in plans:
            available = local[context] | computed[_other(context)]
            for module in remaining[context]:
                # only what a module requires prunes it; what it uses keeps its defaults when missing
                missing = [r.__name__ for r in module.requirements().requires if r not in available]
                if missing:
                    pruned[context][module.__name__] = missing
                    changed = True
        if not changed:
            break
    for context, plan in plans.items():
        plan.pruned = pruned[context]
        reads = {r for m in plan.active_modules() for r in m.requirements().reads()}
        plan.handover_in = sorted(
            (r for r in reads if r not in local[context] and r in computed[_other(context)]), key=lambda r: r.__name__
        )
        provided = _provided(plan.active_modules())
        plan.unfed = sorted(r.__name__ for r in plan.platform_consumes if r not in provided)
    for context, plan in plans.items():
        plan.handover_out = list(plans[_other(context)].handover_in)


def _other(context: str) -> str:
    return "motion" if context == "cognition" else "cognition"
