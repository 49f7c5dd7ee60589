"""The program a run is made of: the modules discovered, the configuration layers, the platform and the context plans."""

from __future__ import annotations

import argparse
import importlib
import pkgutil
import sys
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from tafel.core.framework.config import check_config, edit_modules, load_config
from tafel.core.framework.extensions import load_modules
from tafel.core.framework.module import find_module
from tafel.core.framework.representation import registered_representations
from tafel.core.runtime.platform import Platform, load_platform
from tafel.core.runtime.program import ContextPlan, plan_program
from tafel.tools.launch.defaults import DEFAULT_CONFIG, FALLBACK_PLATFORM
from tafel.tools.launch.errors import fail


def discover_modules(module_paths: Sequence[str | Path] = ()) -> None:
    """Import every file under ``representations/`` and ``modules/`` so configuration and logs can name
    them, then the installed packages of modules (entry point group ``tafel.modules``) and the module
    files in each of ``module_paths`` (``--module-path DIR``)."""
    import tafel.modules as modules
    from tafel.representations import load_all

    load_all()
    for info in pkgutil.walk_packages(modules.__path__, prefix="tafel.modules."):
        importlib.import_module(info.name)
    load_modules(module_paths)


def check_module_edits(add: Sequence[str], remove: Sequence[str], platform: str = "dummy") -> None:
    """``--add-module`` and ``--remove-module`` checked before anything runs (for the batch commands, whose
    runs would otherwise each fail alike): ``ConfigError`` for a malformed one or a module that is not in the
    list, ``UnknownModuleError`` for a module nobody defined, both with the closest names."""
    if not add and not remove:
        return
    edit_modules(load_config(DEFAULT_CONFIG, platform), add, remove)
    for text in add:
        find_module(text.partition(":")[2])


def config_dirs(args: argparse.Namespace) -> list[Path]:
    """The shipped defaults, then ``--config DIR`` on top."""
    return [DEFAULT_CONFIG] + ([args.config] if args.config is not None else [])


def store_dir(args: argparse.Namespace) -> Path:
    """Where ``*:store`` writes its private layer: the user's folder, else the shipped one."""
    return args.config if args.config is not None else DEFAULT_CONFIG


def resolve_platform(args: argparse.Namespace) -> type[Platform]:
    name = args.platform
    if name is None:
        general = load_config(config_dirs(args), "", None, args.overrides)
        name = general.get("runtime", {}).get("default_platform", FALLBACK_PLATFORM)
        args.platform = name
    return load_platform(name)


def prepare(args: argparse.Namespace, extra: Sequence[str]) -> tuple[Platform, dict[str, Any], dict[str, ContextPlan], dict[str, Any]]:
    """Platform, platform options, context plans and configuration for ``run`` and ``modules``."""
    platform_class = resolve_platform(args)
    platform_parser = argparse.ArgumentParser(prog=f"tafel {args.command} --platform {platform_class.name}", add_help=False)
    platform_class.add_arguments(platform_parser)
    options, unknown = platform_parser.parse_known_args(list(extra))
    if unknown:
        known = [a for action in platform_parser._actions for a in action.option_strings]
        hint = f"; options of platform {platform_class.name}: {', '.join(known)}" if known else ""
        fail(f"unrecognized arguments: {' '.join(unknown)}{hint}")
    discover_modules(args.module_path)
    platform = platform_class(vars(options))
    overrides = [f"runtime.{context}_hz={hz}" for context, hz in (platform.rates() or {}).items()]
    config = load_config(config_dirs(args), platform.config_layers(), args.robot, [*overrides, *args.overrides])
    config = edit_modules(config, args.add_module, args.remove_module)
    check_config(config, platform_class.config_sections, registered_representations())
    platform.configure(config)
    plans = plan_program(config, platform, strict=args.strict)
    return platform, platform.options, plans, config



def report_pruned(plans: dict[str, ContextPlan]) -> None:
    for plan in plans.values():
        if not plan.runs:
            print(f"{plan.name}: not running: the platform provides nothing to it", file=sys.stderr)
            continue
        for module, reps in plan.replaced.items():
            print(f"{plan.name}: {module} replaced, the platform provides {', '.join(reps)}", file=sys.stderr)
        for module, missing in plan.pruned.items():
            print(f"{plan.name}: {module} disabled: nothing provides {', '.join(missing)} on this platform", file=sys.stderr)


