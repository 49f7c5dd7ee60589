"""Scenario files (TOML): the situation to try, what counts as success, and how much to vary the start.

A file is checked completely when it is read. A wrong key, a wrong type or an unknown predicate is a
``ScenarioError`` that names the file and the line and says what would be right; nothing runs.
The format is documented in the README ("Scenarios and batch replay") and by the shipped files in
``config/scenarios/``.
"""

from __future__ import annotations

import math
import re
import tomllib
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from tafel.core.framework.config import ConfigError, apply_overrides, check_config
from tafel.core.framework.contexts import CONTEXT_NAMES, Context
from tafel.core.framework.naming import did_you_mean
from tafel.core.framework.representation import fields_of, get_representation
from tafel.core.framework.values import Range, ValueCheckError, convert, refusal
from tafel.platforms.realism import LEVELS as REALISM_LEVELS
from tafel.representations.field import BORDER_STRIP, LENGTH, WIDTH
from tafel.tools.simulation.scenario_predicates import PREDICATES, REQUIRED, TIMING, Parameter

PLATFORMS = ("mujoco", "pybullet")
CONTEXTS = CONTEXT_NAMES
#: predicates that judge what the robot perceived: a scenario with one of them and cameras renders with
#: ``realism = "mild"`` unless its file says otherwise (a camera's light, noise, blur and compression,
#: the hall, without shadows: ``full`` is for judging the detectors, where today's recall is 0.34)
PERCEPTION_PREDICATES = ("ball_model_accurate",)
#: N of a push: more throws the robot off the field instead of testing a fall (the simulators' limit)
MAX_PUSH_N = 500.0
#: s a scenario may last at the most (an hour of simulated time)
MAX_DURATION_S = 3600.0
#: mm from the centre to the carpet's edge: robots and the ball start on it
CARPET_X_MM, CARPET_Y_MM = LENGTH / 2 + BORDER_STRIP, WIDTH / 2 + BORDER_STRIP


class ScenarioError(ValueError):
    """A scenario file that cannot be run: ``file:line: what is wrong; what would be right``."""


@dataclass(frozen=True)
class Condition:
    """One ``[[success]]`` entry: a predicate, its parameters and when it is checked (s of the run)."""

    predicate: str
    parameters: dict[str, Any]
    after_s: float
    within_s: float
    for_s: float

    @property
    def when(self) -> str:
        return PREDICATES[self.predicate].when

    def describe(self) -> str:
        shown = ", ".join(f"{k}={v}" for k, v in self.parameters.items() if v is not None)
        return f"{self.predicate}({shown})" if shown else self.predicate


@dataclass(frozen=True)
class Push:
    """``[[events]]``: push the torso at ``at_s`` for 0.1 s with ``force_n`` (N, field frame)."""

    at_s: float
    force_n: tuple[float, float]


@dataclass(frozen=True)
class Perturbation:
    """How far each run's start may differ from the file's (uniform, plus or minus)."""

    robot_x_mm: float = 0.0
    robot_y_mm: float = 0.0
    robot_rotation_deg: float = 0.0
    ball_x_mm: float = 0.0
    ball_y_mm: float = 0.0
    ball_velocity_mm_s: float = 0.0
    #: the range of the sensors' noise factor (1: the NAO's noise)
    sensor_noise: tuple[float, float] = (1.0, 1.0)


@dataclass(frozen=True)
class Scenario:
    """A situation to try many times. Positions in field coordinates (mm), rotations in degrees."""

    name: str
    path: str
    duration_s: float
    required_success_rate: float
    robot_start: tuple[float, float, float]
    ball: tuple[float, float]
    success: tuple[Condition, ...]
    #: the localization is told the start pose (the known pose), as a team tells a robot it placed by hand
    #: for a drill; without it a start the rules never give (the opponent half in PLAYING) is taken for its twin
    told_pose: bool = False
    description: str = ""
    platform: str = "mujoco"
    cameras: bool = True
    #: the simulator's --realism level (off, mild, full)
    realism: str = "off"
    ball_velocity_mm_s: tuple[float, float] = (0.0, 0.0)
    overrides: tuple[str, ...] = ()
    perturbation: Perturbation = field(default_factory=Perturbation)
    events: tuple[Push, ...] = ()


# ----------------------------------------------------------------------------------------- kinds
#: kind -> (what a file must write, check) for the values of scenario files
KINDS: dict[str, str] = {
    "number": "a number",
    "spread": "a spread (plus or minus), 0 or more",
    "positive": "a number above 0",
    "rate": "a number from 0 to 1",
    "string": "a string in quotes",
    "bool": "true or false",
    "pair": "[x, y], two numbers",
    "pose": "[x_mm, y_mm, rotation_deg], three numbers, x and y on the carpet",
    "place": "[x_mm, y_mm], two numbers on the carpet",
    "duration": f"a number of seconds above 0 and at most {MAX_DURATION_S:g}",
    "range": "[low, high], two numbers with low <= high",
    "strings": 'a list of strings, e.g. ["parameters.Striker.kick_distance=200"]',
    "value": "a number, true or false, or a string",
}


#: kind -> the type its values convert to (``convert``) and the range of its numbers
TYPES: dict[str, tuple[Any, Range | None]] = {
    "number": (float, None), "positive": (float, Range(0.0, low_open=True)), "rate": (float, Range(0.0, 1.0)),
    "spread": (float, Range(0.0)), "string": (str, None), "bool": (bool, None), "pair": (tuple[float, float], None),
    "pose": (tuple[float, float, float], None), "place": (tuple[float, float], None),
    "duration": (float, Range(0.0, MAX_DURATION_S, low_open=True)), "range": (tuple[float, float], None),
    "strings": (tuple[str, ...], None), "value": (Any, None),
}


def _on_carpet(x: float, y: float) -> bool:
    return abs(x) <= CARPET_X_MM and abs(y) <= CARPET_Y_MM


def _convert(kind: str, value: Any, where: str) -> Any:
    """``value`` of a scenario file as ``kind`` says (``TYPES``), else ``ValueCheckError`` in the one wording."""
    kind_type, bounds = TYPES[kind]
    expected = KINDS[kind]
    if kind == "value":  # as written: a number, true or false, or a string
        if not isinstance(value, (bool, str)):
            convert(value, float, where=where, text=False, expected=expected)
        return value
    result = convert(value, kind_type, where=where, bounds=bounds, text=False, expected=expected)
    if (kind in ("pose", "place") and not _on_carpet(*result[:2])) or (kind == "range" and result[0] > result[1]):
        raise refusal(where, expected, value)
    return result


# ---------------------------------------------------------------------------------------- reading
class _File:
    """The text and data of one file, and errors that point at its lines."""

    def __init__(self, path: Path) -> None:
        self.path = path
        try:
            self.text = path.read_text(encoding="utf-8")
        except FileNotFoundError:
            raise ScenarioError(f"{path}: no such scenario file") from None
        except (OSError, UnicodeDecodeError) as exc:
            raise ScenarioError(f"{path}: cannot be read ({exc})") from None
        try:
            self.data = tomllib.loads(self.text)
        except RecursionError:
            raise ScenarioError(f"{path}: nested too deeply to be a scenario (tables or arrays inside each other hundreds "
                                "of levels deep); a scenario needs three levels at most") from None
        except tomllib.TOMLDecodeError as exc:
            found = re.search(r"\(at line (\d+), column \d+\)", str(exc))
            line = found.group(1) if found else "1"
            raise ScenarioError(f"{path}:{line}: not TOML: {exc}") from None

    def error(self, table: tuple[Any, ...], key: str | None, message: str) -> ScenarioError:
        return ScenarioError(f"{self.path}:{self.line_of(table, key)}: {message}")

    def line_of(self, table: tuple[Any, ...], key: str | None) -> int:
        """The line that sets ``key`` in ``table`` (``()`` for the top, ``("success", 1)`` for the second
        ``[[success]]``), else the table's header, else 1."""
        current: tuple[Any, ...] = ()
        counts: dict[str, int] = {}
        header = 1
        for number, raw in enumerate(self.text.splitlines(), 1):
            line = raw.strip()
            array = re.match(r"^\[\[\s*([\w.-]+)\s*\]\]", line)
            single = re.match(r"^\[\s*([\w.-]+)\s*\]", line)
            if array:
                name = array.group(1)
                counts[name] = counts.get(name, -1) + 1
                current = (name, counts[name])
            elif single:
                current = (single.group(1),)
            if array or single:
                if current == table:
                    header = number
                continue
            if current == table and key is not None and re.match(rf'^"?{re.escape(key)}"?\s*=', line):
                return number
        return header

    def take(self, table: tuple[Any, ...], values: dict[str, Any], key: str, kind: str, default: Any = REQUIRED) -> Any:
        where = _table_name(table)
        if key not in values:
            if default is REQUIRED:
                raise self.error(table, None, f"{where} needs {key} ({KINDS[kind]})")
            return default
        try:
            return _convert(kind, values[key], f"{key} in {where}")
        except ValueCheckError as exc:
            raise self.error(table, key, str(exc)) from None

    def refuse(self, table: tuple[Any, ...], key: str, expected: str, value: Any) -> ScenarioError:
        """The error for ``key`` of ``table`` that does not fit: ``<key> takes <expected>, got <value>``, at its line."""
        return self.error(table, key, str(refusal(key, expected, value)))

    def only(self, table: tuple[Any, ...], values: dict[str, Any], known: list[str]) -> None:
        for key in values:
            if key not in known:
                raise self.error(table, key, f"{_table_name(table)} has no key {key!r}; {did_you_mean(key, known)}")


def _table_name(table: tuple[Any, ...]) -> str:
    if not table:
        return "the file's top level"
    if len(table) == 2:
        return f"[[{table[0]}]] number {table[1] + 1}"
    return f"[{table[0]}]"


TOP_KEYS = ["name", "description", "platform", "cameras", "realism", "duration_s", "required_success_rate", "set",
            "robots", "ball", "perturbation", "events", "success"]
PERTURBATION_KINDS = {"robot_x_mm": "spread", "robot_y_mm": "spread", "robot_rotation_deg": "spread", "ball_x_mm": "spread",
                      "ball_y_mm": "spread", "ball_velocity_mm_s": "spread", "sensor_noise": "range"}


def load_scenario(path: str | Path) -> Scenario:
    """Read and check one scenario file; ``ScenarioError`` says what is wrong and where."""
    f = _File(Path(path))
    top = f.data
    f.only((), top, TOP_KEYS)
    duration = f.take((), top, "duration_s", "duration")
    platform = f.take((), top, "platform", "string", "mujoco")
    if platform not in PLATFORMS:
        raise f.refuse((), "platform", " or ".join(PLATFORMS), platform)
    overrides = f.take((), top, "set", "strings", ())
    try:
        check_config(apply_overrides({}, overrides))
    except ConfigError as exc:
        raise f.error((), "set", f"set: {exc}") from None
    robots = _tables(f, top, "robots")
    if len(robots) != 1:
        raise f.error(("robots", 0) if robots else (), None,
                      f"a scenario has exactly one [[robots]] table with start = [x_mm, y_mm, rotation_deg], got {len(robots)}")
    f.only(("robots", 0), robots[0], ["start", "told_pose"])
    ball = top.get("ball", {})
    if not isinstance(ball, dict):
        raise f.error((), "ball", "ball is a table: [ball] with position = [x_mm, y_mm] and velocity = [vx, vy] (mm/s)")
    f.only(("ball",), ball, ["position", "velocity"])
    success = _tables(f, top, "success")
    if not success:
        raise f.error((), None, "a scenario needs at least one [[success]] table with a predicate; "
                                f"predicates: {', '.join(PREDICATES)}")
    conditions = tuple(_condition(f, ("success", i), entry, duration) for i, entry in enumerate(success))
    cameras = f.take((), top, "cameras", "bool", True)
    judges_perception = cameras and any(c.predicate in PERCEPTION_PREDICATES for c in conditions)
    realism = f.take((), top, "realism", "string", "mild" if judges_perception else "off")
    if realism not in REALISM_LEVELS:
        raise f.refuse((), "realism", "one of " + ", ".join(REALISM_LEVELS), realism)
    return Scenario(
        name=f.take((), top, "name", "string", f.path.stem),
        path=str(f.path),
        description=f.take((), top, "description", "string", ""),
        platform=platform,
        cameras=cameras,
        realism=realism,
        duration_s=duration,
        required_success_rate=f.take((), top, "required_success_rate", "rate"),
        overrides=overrides,
        robot_start=f.take(("robots", 0), robots[0], "start", "pose"),
        told_pose=f.take(("robots", 0), robots[0], "told_pose", "bool", False),
        ball=f.take(("ball",), ball, "position", "place", (0.0, 0.0)),
        ball_velocity_mm_s=f.take(("ball",), ball, "velocity", "pair", (0.0, 0.0)),
        perturbation=_perturbation(f, top),
        events=tuple(_push(f, ("events", i), event, duration) for i, event in enumerate(_tables(f, top, "events"))),
        success=conditions,
    )


def _tables(f: _File, top: dict[str, Any], key: str) -> list[dict[str, Any]]:
    tables = top.get(key, [])
    if not (isinstance(tables, list) and all(isinstance(t, dict) for t in tables)):
        raise f.error((), key, f"{key} is a list of tables: write each as [[{key}]]")
    return tables


def _perturbation(f: _File, top: dict[str, Any]) -> Perturbation:
    table = ("perturbation",)
    values = top.get("perturbation", {})
    if not isinstance(values, dict):
        raise f.error((), "perturbation", "perturbation is a table: [perturbation]")
    f.only(table, values, list(PERTURBATION_KINDS))
    taken = {key: f.take(table, values, key, kind, getattr(Perturbation(), key)) for key, kind in PERTURBATION_KINDS.items()}
    low, high = taken["sensor_noise"]
    if low < 0 or high > 100:
        raise f.refuse(table, "sensor_noise", "[low, high] factors from 0 to 100 (1: the NAO's noise)", [low, high])
    return Perturbation(**taken)


def _push(f: _File, table: tuple[Any, ...], values: dict[str, Any], duration: float) -> Push:
    f.only(table, values, ["at_s", "push_n"])
    force = f.take(table, values, "push_n", "pair")
    if math.hypot(*force) > MAX_PUSH_N:
        raise f.refuse(table, "push_n", f"[fx, fy] up to {MAX_PUSH_N:g} N", list(force))
    at = f.take(table, values, "at_s", "number")
    if not 0 <= at < duration:
        raise f.refuse(table, "at_s", f"a time within the run, from 0 to below {duration:g} s", at)
    return Push(at_s=at, force_n=force)


def _condition(f: _File, table: tuple[Any, ...], values: dict[str, Any], duration: float) -> Condition:
    name = f.take(table, values, "predicate", "string")
    if name not in PREDICATES:
        raise f.error(table, "predicate", f"no predicate {name!r}; {did_you_mean(name, PREDICATES)} (all: {', '.join(PREDICATES)})")
    kind = PREDICATES[name]
    f.only(table, values, ["predicate", *kind.parameters, *TIMING])
    parameters = {key: _parameter(f, table, values, key, spec) for key, spec in kind.parameters.items()}
    timing = {key: _parameter(f, table, values, key, spec) for key, spec in TIMING.items()}
    within = min(timing["within_s"], duration)
    if not 0 <= timing["after_s"] < within:
        raise f.refuse(table, "after_s", f"a time from 0 to below within_s ({within:g} s)", timing["after_s"])
    if timing["for_s"] < 0:
        raise f.refuse(table, "for_s", "a time of 0 s or more", timing["for_s"])
    if name == "ball_in_goal" and parameters["goal"] not in ("opponent", "own"):
        raise f.refuse(table, "goal", "opponent or own", parameters["goal"])
    if name == "representation":
        _check_representation(f, table, parameters)
    return Condition(name, parameters, timing["after_s"], within, timing["for_s"])


def _parameter(f: _File, table: tuple[Any, ...], values: dict[str, Any], key: str, spec: Parameter) -> Any:
    return f.take(table, values, key, spec.kind, spec.default)


def _check_representation(f: _File, table: tuple[Any, ...], p: dict[str, Any]) -> None:
    from tafel.tools.launch.program import discover_modules  # the representations register as their modules are imported

    discover_modules()
    try:
        cls = get_representation(p["name"])
    except KeyError as exc:
        raise f.error(table, "name", str(exc.args[0])) from None
    names = [info.name for info in fields_of(cls)]
    first = p["field"].split(".")[0]
    if first not in names:
        raise f.error(table, "field", f"{p['name']} has no field {first!r}; {did_you_mean(first, names)}")
    try:
        p["context"] = Context.of(p["context"], "context").value
    except ValueCheckError as exc:
        raise f.error(table, "context", str(exc)) from None
    if all(p[k] is None for k in ("equals", "at_least", "at_most")):
        raise f.error(table, None, "a representation predicate needs equals, at_least or at_most")
