"""``tafel platforms`` and ``tafel modules``: what there is to run on, and how a program is wired, without running it."""

from __future__ import annotations

import argparse
from collections.abc import Sequence

from tafel.core.framework.dot import contexts_dot
from tafel.core.runtime.platform import available_platforms, load_platform
from tafel.debug.outputs import describe_outputs
from tafel.tools.launch.program import prepare


# ----------------------------------------------------------------------------------- platforms
def command_platforms(args: argparse.Namespace, extra: Sequence[str]) -> int:
    for name in sorted(available_platforms()):
        try:
            cls = load_platform(name)
        except Exception as exc:  # noqa: BLE001 - one broken platform must not hide the others
            print(f"{name}: cannot load ({type(exc).__name__}: {exc})")
            continue
        print(f"{name}: {cls.description} [{cls.clock} clock]")
        for context in ("cognition", "motion"):
            provided = ", ".join(r.__name__ for r in cls.provides.get(context, ())) or "-"
            consumed = ", ".join(r.__name__ for r in cls.consumes.get(context, ())) or "-"
            print(f"  {context}: provides {provided}; consumes {consumed}")
        if args.verbose:
            options = argparse.ArgumentParser(prog=f"tafel run --platform {name}", add_help=False)
            cls.add_arguments(options)
            for action in options._actions:
                print(f"  option {', '.join(action.option_strings)}: {action.help}")
    return 0


# ------------------------------------------------------------------------------------- modules
def command_modules(args: argparse.Namespace, extra: Sequence[str]) -> int:
    platform, _options, plans, _config = prepare(args, extra)
    platform_class = type(platform)
    managers = {name: plan.build_manager() for name, plan in plans.items() if plan.runs}
    if args.dot:
        handovers = [(rep.__name__, plan.name, other) for other, p in plans.items() if p.runs
                     for plan in plans.values() if plan.name != other for rep in p.handover_in]
        print(contexts_dot([m.graph() for m in managers.values()], handovers), end="")
        return 0
    print(f"platform {platform_class.name}")
    for name, plan in plans.items():
        manager = managers.get(name)
        print(f"\n{name} ({plan.rate_hz:g} Hz)")
        if manager is None:
            print("  not running: the platform provides nothing to it")
            continue
        print("  order: " + (" -> ".join(manager.order) or "(no modules)"))
        graph = manager.graph()
        for rep, info in sorted(graph["representations"].items()):
            if info["provider"] and len(info["alternatives"]) > 1:
                others = [a for a in info["alternatives"] if a != info["provider"]]
                print(f"  provider {rep}: {info['provider']} (alternatives: {', '.join(others)})")
        print("  from runtime: " + ", ".join(r.__name__ for r in plan.runtime_provides))
        if plan.platform_provides:
            print("  from platform: " + ", ".join(r.__name__ for r in plan.platform_provides))
        if plan.platform_consumes:
            print("  to platform: " + ", ".join(r.__name__ for r in plan.platform_consumes))
        other = "motion" if name == "cognition" else "cognition"
        for rep in plan.handover_in:
            print(f"  hand-over in: {rep.__name__} from {other}")
        for rep in plan.handover_out:
            print(f"  hand-over out: {rep.__name__} to {other}")
        for module, missing in plan.pruned.items():
            print(f"  pruned: {module} (missing {', '.join(missing)})")
        for module, reps in plan.replaced.items():
            print(f"  replaced: {module} (the platform provides {', '.join(reps)})")
        for rep in plan.unfed:
            print(f"  warning: the platform consumes {rep}, but no module provides it (defaults are sent)")
        for module in sorted(set(plan.disabled)):
            print(f"  disabled by configuration: {module}")
        for line in describe_outputs(manager.module_classes):  # what debug clients can switch, pin and watch
            print(f"  {line}")
    return 0


