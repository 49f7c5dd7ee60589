"""Layered TOML configuration: general -> platform/<name> -> robot/<name> -> private -> --set.

The layers are read from one or more configuration folders in order: the defaults that ship inside the
package first, then each folder given with ``--config DIR``, each folder with all four layers.

Each layer is optional and overrides what came before, table by table; lists are replaced whole.
A layer edits the module lists it inherits with ``add`` and ``remove`` (applied where the layer is
read, after its own ``modules`` if it has one; ``--set cognition.add=[...]`` too)::

    [cognition]
    add = ["MyBallModeler"]          # appended (once) to the list of the layers before
    remove = ["SimpleBallModeler"]   # must be in that list: a misspelt name is an error

A configuration file looks like::

    [runtime]
    cognition_hz = 30
    motion_hz = 100

    [cognition]
    modules = ["BallDetector", "KalmanBallModeler", "SimpleBallModeler"]
    disabled = []
    [cognition.providers]
    BallModel = "KalmanBallModeler"

    [parameters.KalmanBallModeler]
    friction = 0.5
"""

from __future__ import annotations

import copy
import math
import tomllib
from collections.abc import Iterable, Mapping, Sequence
from pathlib import Path
from typing import Any

import tomlkit

from tafel.core.framework.contexts import CONTEXT_NAMES, Context
from tafel.core.framework.errors import TafelError
from tafel.core.framework.naming import did_you_mean
from tafel.core.framework.values import INT_RANGE, Range, convert, refusal

#: the contexts' sections, as names (``Context`` converts a name from outside)
CONTEXTS = CONTEXT_NAMES
PRIVATE_FILE = "private/private.toml"


class ConfigError(TafelError, ValueError):
    """A configuration file or override that cannot be used as written."""


def config_folders(config_dirs: Path | Sequence[Path]) -> list[Path]:
    """One folder or several, as a list in override order."""
    return [Path(config_dirs)] if isinstance(config_dirs, (str, Path)) else [Path(d) for d in config_dirs]


def layer_paths(config_dirs: Path | Sequence[Path], platform: str | Sequence[str], robot: str | None) -> list[Path]:
    """The layer files in override order (only those that exist are read).

    ``platform`` may name several platform layers, read in order (a log replays with the layer of
    the platform it was recorded on, then its own).
    """
    platforms = [platform] if isinstance(platform, str) else list(platform)
    paths = []
    for config_dir in config_folders(config_dirs):
        paths.append(config_dir / "general.toml")
        paths += [config_dir / "platform" / f"{name}.toml" for name in platforms if name]
        if robot:
            paths.append(config_dir / "robot" / f"{robot}.toml")
        paths.append(config_dir / PRIVATE_FILE)
    return paths


def read_toml(path: Path) -> dict[str, Any]:
    try:
        with path.open("rb") as handle:
            return tomllib.load(handle)
    except tomllib.TOMLDecodeError as exc:
        raise ConfigError(f"{path}: not valid TOML: {exc}") from None
    except UnicodeDecodeError as exc:
        raise ConfigError(f"{path}: not UTF-8 text (byte {exc.start} is 0x{exc.object[exc.start]:02x}); "
                          "TOML files must be saved as UTF-8") from None
    except RecursionError:
        raise ConfigError(f"{path}: nested too deeply to be configuration (arrays or tables inside each other "
                          "hundreds of levels deep); configuration needs a few levels at most") from None
    except OSError as exc:
        raise ConfigError(f"{path}: cannot read: {exc.strerror}") from None


def merge(base: dict[str, Any], layer: Mapping[str, Any]) -> dict[str, Any]:
    """``layer`` merged into a copy of ``base``: tables recursively, everything else replaced."""
    result = copy.deepcopy(base)
    for key, value in layer.items():
        if isinstance(value, Mapping) and isinstance(result.get(key), dict):
            result[key] = merge(result[key], value)
        else:
            result[key] = copy.deepcopy(value)
    return result


#: levels of tables and lists configuration may have (parameters.Module.name = [[1, 2]] has four)
MAX_DEPTH = 8
#: the largest magnitude of a whole number in configuration (a signed 64-bit integer)
MAX_INT = INT_RANGE[1]


def parse_override(text: str) -> tuple[list[str], Any]:
    """``runtime.cognition_hz=15`` -> (["runtime", "cognition_hz"], 15). Values are TOML, else strings."""
    key, sep, raw = text.partition("=")
    key = key.strip()
    if not sep or not key or any(not part for part in key.split(".")):
        raise ConfigError(f"--set takes KEY=VALUE with a dotted key, e.g. runtime.cognition_hz=15; got {_short(text)!r}")
    if key.count(".") >= MAX_DEPTH:
        raise ConfigError(f"--set {_short(key)}: a key of {key.count('.') + 1} parts; configuration keys have at most {MAX_DEPTH}")
    raw = raw.strip()
    try:
        value = tomllib.loads(f"v = {raw}")["v"]
    except tomllib.TOMLDecodeError:
        value = raw
    except RecursionError:
        raise ConfigError(f"--set {key}: the value is nested too deeply; configuration has {MAX_DEPTH} levels at most") from None
    except ValueError:  # a number past Python's digit limit (4300 digits)
        raise ConfigError(f"--set {key}: a number of {len(raw)} characters; whole numbers in configuration fit 64 bits "
                          f"(at most {MAX_INT})") from None
    check_value(value, f"--set {key}", depth=key.count(".") + 1)
    return key.split("."), value


def _short(text: str, limit: int = 80) -> str:
    return text if len(text) <= limit else text[:limit] + f"... ({len(text)} characters)"


def check_value(value: Any, where: str, depth: int = 0) -> None:
    """Values configuration can hold: at most ``MAX_DEPTH`` levels deep, whole numbers within 64 bits."""
    if depth > MAX_DEPTH:
        raise ConfigError(f"{where}: nested more than {MAX_DEPTH} levels deep; configuration needs a few levels at most")
    if isinstance(value, int) and not isinstance(value, bool):
        convert(value, int, where=where, text=False, error=ConfigError)  # a TOML integer fits 64 bits; Python's need not
    children = value.values() if isinstance(value, Mapping) else value if isinstance(value, list) else ()
    for child in children:
        check_value(child, where, depth + 1)


#: the top-level tables of the configuration: what each holds
SECTIONS: dict[str, str] = {
    "runtime": "rates and timeouts", "cognition": "cognition's modules", "motion": "motion's modules",
    "parameters": "module parameters by module name", "game": "team, player number and network",
    "status": "the status line", "recording": "what --record records", "foxglove": "Foxglove's channels",
    "debug": "the debug server's aliases", "blackbox": "the black-box recorder",
}


def check_config(config: Mapping[str, Any], platform_sections: Iterable[str] = (), representations: Iterable[str] | None = None) -> None:
    """The whole configuration's shape: known top-level tables (``SECTIONS`` and the platform's own),
    each a table, the lists that name representations naming known ones (when ``representations``
    is given). ``ConfigError`` with what would be right; the modules' own tables are checked where they
    are used (parameters by their modules, [game] by the network, [runtime] by ``check_runtime``)."""
    known = dict(SECTIONS, **{name: "the platform's options" for name in platform_sections})
    for key, value in config.items():
        if key.startswith("_"):
            continue
        if key not in known:
            raise ConfigError(f"[{key}] is not a section of the configuration; {did_you_mean(key, known)}; the sections are "
                              + ", ".join(f"{name} ({what})" for name, what in known.items()))
        if not isinstance(value, Mapping):
            raise refusal(key, f"a table ([{key}] in a file)", value, ConfigError)
        check_value(value, f"[{key}]", depth=1)
    names = set(representations) if representations is not None else None
    for section, key in (("recording", "representations"), ("status", "show")):
        table = config.get(section, {})
        unknown = sorted(set(table) - {key})
        if unknown:
            raise ConfigError(f"[{section}] {unknown[0]} is not a setting; [{section}] has only {key}")
        if key not in table:
            continue
        value = convert(table[key], list[str], where=f"{section}.{key}", text=False, error=ConfigError,
                        expected='a list of representation names, e.g. ["BallModel"]')
        for entry in value:
            prefix, slash, name = entry.rpartition("/") if section == "recording" else ("", "", entry)
            if slash:  # a topic: "motion/FrameInfo" records that context's only
                Context.of(prefix, f"{section}.{key}: {entry!r}: the context before /", ConfigError)
            if names is not None and name not in names:
                raise ConfigError(f"{section}.{key}: no representation named {name!r}; {did_you_mean(name, names)}")
    debug = config.get("debug", {})
    aliases = debug.get("aliases", {})
    convert(aliases, dict[str, dict[str, Any]], where="debug.aliases", text=False, error=ConfigError,
            expected='tables, one per alias ([debug.aliases."motion:walk"] with command = ...)')
    for section in CONTEXTS:
        context_section(config, section)


def apply_overrides(config: dict[str, Any], overrides: Iterable[str]) -> dict[str, Any]:
    result = copy.deepcopy(config)
    for text in overrides:
        path, value = parse_override(text)
        node = result
        for part in path[:-1]:
            child = node.setdefault(part, {})
            if not isinstance(child, dict):
                raise ConfigError(f"--set {text}: {part} is a value, not a table")
            node = child
        node[path[-1]] = value
    return result


def load_config(
    config_dirs: Path | Sequence[Path], platform: str | Sequence[str], robot: str | None = None, overrides: Iterable[str] = ()
) -> dict[str, Any]:
    """The merged configuration for a platform (and robot), with ``--set`` overrides applied last.

    ``config_dirs`` is one folder or several, read in order, later ones overriding earlier ones.
    """
    folders = config_folders(config_dirs)
    for config_dir in folders:
        if not config_dir.is_dir():
            raise ConfigError(f"configuration folder {config_dir} does not exist; pass --config DIR with an existing folder")
    if robot and not any((d / "robot" / f"{robot}.toml").is_file() for d in folders):
        known = sorted({p.stem for d in folders for p in (d / "robot").glob("*.toml")})
        raise ConfigError(f"--robot {robot}: no file robot/{robot}.toml in {', '.join(map(str, folders))}; "
                          + (f"known robots: {', '.join(known)}" if known else "there are no robot files yet"))
    config: dict[str, Any] = {}
    sources = []
    for path in layer_paths(folders, platform, robot):
        if path.is_file():
            layer = read_toml(path)
            check_value(layer, str(path))
            config = apply_module_edits(merge(config, layer), str(path))
            sources.append(str(path))
    config = apply_module_edits(apply_overrides(config, overrides), "--set")
    check_runtime(config)
    config["_sources"] = sources
    return config


#: the rates (Hz) a context may run at: above this no platform keeps up and no timer is that fine
MAX_RATE_HZ = 1000.0
#: a rate of a context: above 0 Hz, at most ``MAX_RATE_HZ``
RATE = Range(0.0, MAX_RATE_HZ, low_open=True)
#: a time in seconds: above 0
SECONDS = Range(0.0, low_open=True)
#: [runtime] key -> (its type, its range, its unit)
RUNTIME_KEYS: dict[str, tuple[type, Range | None, str]] = {
    "cognition_hz": (float, RATE, "Hz"), "motion_hz": (float, RATE, "Hz"), "stall_timeout_s": (float, SECONDS, "seconds"),
    "shutdown_grace_s": (float, SECONDS, "seconds"), "stuck_timeout_s": (float, SECONDS, "seconds"), "default_platform": (str, None, ""),
}


def check_runtime(config: Mapping[str, Any]) -> None:
    """``[runtime]`` holds only known keys, each of its kind; ``ConfigError`` with what would be right."""
    runtime = config.get("runtime", {})
    if not isinstance(runtime, Mapping):
        raise refusal("runtime", "a table of settings (runtime.motion_hz=100 and the like)", runtime, ConfigError)
    for key, value in runtime.items():
        if key not in RUNTIME_KEYS:
            raise ConfigError(f"runtime.{key} is not a setting; {did_you_mean(key, RUNTIME_KEYS)}; "
                              f"the settings are {', '.join(sorted(RUNTIME_KEYS))}")
        kind, bounds, unit = RUNTIME_KEYS[key]
        if kind is str and value == "":
            raise refusal(f"runtime.{key}", "a name", value, ConfigError)
        convert(value, kind, where=f"runtime.{key}", bounds=bounds, unit=unit, text=False, error=ConfigError)


#: the settings of a ``[cognition]`` or ``[motion]`` table
CONTEXT_KEYS = ("modules", "disabled", "providers", "add", "remove", "disable", "enable")


def apply_module_edits(config: dict[str, Any], where: str) -> dict[str, Any]:
    """Each context's ``add`` and ``remove`` applied to its module list, and ``disable`` and ``enable`` to its
    ``disabled`` list, and dropped: the layer ``where`` (a file, or ``--set``) edits the lists it inherits, and the
    next layer sees the edited lists. (``modules:store`` writes ``disable`` and ``enable``: the private layer then
    keeps what a platform's layer disables there, on every platform.)"""
    for context in CONTEXTS:
        section = config.get(context)
        if not isinstance(section, dict):
            continue  # context_section says what is wrong with it
        for key in section:
            if key not in CONTEXT_KEYS:
                raise ConfigError(f"{where}: [{context}] {key} is not a setting; {did_you_mean(key, CONTEXT_KEYS)}; "
                                  f"the settings are {', '.join(CONTEXT_KEYS)}")
        switches = {key: section.pop(key) for key in ("disable", "enable") if key in section}  # enable wins
        if switches:
            disabled = convert(section.get("disabled", []), list[Any], where=f"{where}: [{context}] disabled", text=False,
                               expected="a list of module names", error=ConfigError)
            for key, names in switches.items():
                for name in convert(names, list[str], where=f"{where}: [{context}] {key}", text=False, error=ConfigError,
                                    expected=f'a list of module names, e.g. {key} = ["GoalPostDetector"]'):
                    if key == "disable" and name not in disabled:
                        disabled.append(name)
                    elif key == "enable" and name in disabled:
                        disabled.remove(name)
            section["disabled"] = disabled
        edits = {key: section.pop(key) for key in ("remove", "add") if key in section}
        if not edits:
            continue
        modules = convert(section.get("modules", []), list[Any], where=f"{where}: [{context}] modules", text=False,
                          expected=f"a list of module names to {' and '.join(edits)} modules", error=ConfigError)
        for key, names in edits.items():
            names = convert(names, list[str], where=f"{where}: [{context}] {key}", text=False, error=ConfigError,
                            expected=f'a list of module names, e.g. {key} = ["SimpleBallModeler"]')
            for name in names:
                if key == "add" and name not in modules:
                    modules.append(name)
                elif key == "remove":
                    if name not in modules:
                        raise ConfigError(f"{where}: [{context}] remove: {name} is not in the module list of the layers "
                                          f"before; {did_you_mean(name, modules)} (where a layer before dropped it already, leave it out here)")
                    modules.remove(name)
        section["modules"] = modules
    return config


def edit_modules(config: dict[str, Any], add: Iterable[str] = (), remove: Iterable[str] = ()) -> dict[str, Any]:
    """``--add-module cognition:NAME`` and ``--remove-module motion:NAME`` on the module lists."""
    result = copy.deepcopy(config)
    for text, adding in [*((t, True) for t in add), *((t, False) for t in remove)]:
        context, sep, name = str(text).partition(":")
        option = "--add-module" if adding else "--remove-module"
        if not sep or not name:
            raise refusal(option, "CONTEXT:MODULE with CONTEXT cognition or motion, e.g. cognition:BallDetector", str(text), ConfigError)
        context = Context.of(context, f"{option} {text}: CONTEXT", ConfigError).value
        section = result.setdefault(context, {})
        modules = list(section.get("modules", []))
        if adding:
            if name not in modules:
                modules.append(name)
        elif name in modules:
            modules.remove(name)
        else:
            raise ConfigError(f"{option} {text}: {name} is not in [{context}] modules; {did_you_mean(name, modules)}")
        section["modules"] = modules
    return result


def context_section(config: Mapping[str, Any], context: str) -> dict[str, Any]:
    """The ``[cognition]`` or ``[motion]`` table with checked types."""
    section = config.get(context, {})
    if not isinstance(section, Mapping):
        raise refusal(f"[{context}]", "a table", section, ConfigError)
    modules, disabled = (convert(section.get(key, []), list[str], where=f"{context}.{key}", text=False, error=ConfigError,
                                 expected="a list of module names") for key in ("modules", "disabled"))
    providers = convert(section.get("providers", {}), dict[str, str], where=f"{context}.providers", text=False, error=ConfigError,
                        expected="a table of representation names to module names")
    return {"modules": modules, "disabled": disabled, "providers": providers}


def private_section(config_dir: Path, context: str) -> dict[str, Any]:
    """The ``[context]`` table of the private layer as it is on disk (empty where there is none)."""
    target = config_dir / PRIVATE_FILE
    section = read_toml(target).get(context, {}) if target.is_file() else {}
    return dict(section) if isinstance(section, Mapping) else {}


def store_private(config_dir: Path, path: list[str], value: Any) -> Path:
    """Write one value into the private layer (``config/private/private.toml``), keeping the rest of the
    file as the user wrote it: comments, order and layout stay (tomlkit edits the document in place)."""
    target = config_dir / PRIVATE_FILE
    before = target.read_text(encoding="utf-8") if target.is_file() else ""
    read_toml(target) if target.is_file() else None  # a broken file is reported as any layer is
    document = tomlkit.parse(before)
    node: Any = document
    for part in path[:-1]:
        if part not in node or not isinstance(node[part], Mapping):
            node[part] = tomlkit.table()
        node = node[part]
    if _has_nan(value):
        raise ConfigError(f"cannot store {'.'.join(path)} = {value!r}: TOML configuration holds finite numbers only")
    try:
        node[path[-1]] = value
    except (TypeError, ValueError) as exc:
        raise ConfigError(f"cannot store {'.'.join(path)} = {value!r} in TOML ({exc})") from None
    text = tomlkit.dumps(document)
    try:  # never write what would not load again: the next start would fail on it
        loaded = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ConfigError(f"cannot store {'.'.join(path)} = {value!r}: it would not read back as TOML ({exc})") from None
    stored: Any = loaded
    for part in path:
        stored = stored[part]
    if stored != (list(value) if isinstance(value, tuple) else value):
        raise ConfigError(f"cannot store {'.'.join(path)} = {value!r}: it would not read back as the same value")
    target.parent.mkdir(parents=True, exist_ok=True)
    temporary = target.with_name(target.name + ".tmp")
    temporary.write_text(text, encoding="utf-8")
    temporary.replace(target)  # whole or not at all, also when the disk is full or the program dies
    return target


def _has_nan(value: Any) -> bool:
    if isinstance(value, float):
        return not math.isfinite(value)
    if isinstance(value, Mapping):
        return any(_has_nan(v) for v in value.values())
    if isinstance(value, (list, tuple)):
        return any(_has_nan(v) for v in value)
    return False


def dump_toml(data: Mapping[str, Any]) -> str:
    """Configuration data as TOML text (tomlkit)."""
    return tomlkit.dumps(data)
