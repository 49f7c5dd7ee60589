"""Debug commands: what each context answers, and how answers of both contexts are combined.

Every context command takes an optional ``-context cognition|motion`` to ask only that context.

A ``ContextDebug`` answers the commands about one context (its modules, blackboard, parameters and
the debug data its modules produced). It runs in the thread or process of that context, between
frames. A ``DebugRouter`` asks every context and combines the answers: lists are merged with a
heading per context; a command about one name takes the answer of the context that has it, so names
(modules, representations, requests) can be used without saying which context they are in.
"""

from __future__ import annotations

import copy
import dataclasses
import json
import statistics
import time
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from tafel.core.framework.contexts import Context
from tafel.core.framework.errors import TafelError
from tafel.core.framework.manager import ModuleManager
from tafel.core.framework.naming import did_you_mean
from tafel.core.framework.parameters import ParameterError, make_parameters, parameter_values, set_parameter
from tafel.core.framework.reload import ModuleReloader
from tafel.core.framework.representation import fields_of
from tafel.core.framework.validation import ValueCheckError, check_field, check_instance
from tafel.core.framework.values import convert
from tafel.core.logs.serialization import SerializationError, deserialize, serialize
from tafel.debug.concepts import CANVASES, DebugState
from tafel.debug.outputs import debug_state
from tafel.debug.protocol import Command
from tafel.debug.values import (
    CommandError,
    _coerce_like,
    _short,
    frame_number,
    frame_time_ns,
    jpeg_bytes,
    json_value,
    parse_bool,
    parse_field_text,
    pretty,
    representation_message,
)


class NotHere(TafelError):
    """The name a command refers to does not exist in this context (another context may have it)."""

    def __init__(self, kind: str, name: str, known: Iterable[str]) -> None:
        super().__init__(kind, name)
        self.kind, self.name, self.known = kind, name, sorted(set(known))


@dataclass(frozen=True)
class CommandSpec:
    name: str
    summary: str
    usage: str
    #: "merge": every context answers, combined under headings; "first": the context that has the name;
    #: "lines": the lines of every context that has something, without headings (for tools)
    routing: str = "merge"


SPECS: dict[str, CommandSpec] = {}


def _spec(name: str, summary: str, usage: str = "", routing: str = "merge") -> None:
    SPECS[name] = CommandSpec(name, summary, usage or name, routing)


_spec("modules:list", "per context: execution order, enabled, providers and alternatives, mean and max time",
      "modules:list [-format json]")
_spec("modules:set", "enable or disable a module", "modules:set -module NAME -enabled true|false", "first")
_spec("module:reload", "import a module's source file again and run the new code from the next frame, keeping the "
      "blackboard and parameters (rolled back if it raises in its first frames)", "module:reload -module NAME", "first")
_spec("modules:provider", "choose the module that provides a representation", "modules:provider -representation NAME -module NAME", "first")
_spec("representation:list", "the representations of both contexts and who provides them", "representation:list [-format json]")
_spec("representation:print", "a representation's current value as readable text (or JSON)", "representation:print -name NAME [-format json]", "first")
_spec("representation:get", "a representation's current value as protobuf bytes (use +representation:get for base64)", "+representation:get -name NAME", "first")
_spec("representation:set", "set a representation from protobuf bytes or one field", "representation:set -name NAME +data BASE64 | -field FIELD -value VALUE", "first")
_spec("representation:override", "keep a representation at a value before every frame until representation:release (remote control)",
      "representation:override -name NAME [-fields JSON] [+data BASE64]", "first")
_spec("representation:release", "end an override: the representation's provider writes it again",
      "representation:release -name NAME", "first")
_spec("debug_request:list", "debug requests, on or off", "debug_request:list [-format json]")
_spec("debug_request:set", "switch a debug request on or off", "debug_request:set -name NAME -value on|off", "first")
_spec("modify:list", "published modify values, and which are pinned", "modify:list [-format json]")
_spec("modify:set", "pin a modify value", "modify:set -name NAME -value VALUE", "first")
_spec("modify:release", "unpin a modify value", "modify:release -name NAME", "first")
_spec("stopwatch:list", "per module and named stopwatch: last, mean, max, p95 (us), per context, and loop frequency",
      "stopwatch:list [-format json]")
_spec("plot:get", "a plot's recent values (frame value per line); without -name the plot names", "plot:get [-name NAME] [-count N]", "lines")
_spec("drawings:get", "the last frame's drawings of both contexts as JSON lines", "drawings:get [-canvas field|image:top|image:bottom]", "lines")
_spec("parameter:list", "modules with parameters and their values", "parameter:list [-format json]")
_spec("image:get", "a camera image as JPEG (use +image:get for base64)", "+image:get -name CameraImageTop|CameraImageBottom [-quality 1..100]",
      "first")
_spec("parameter:get", "a module's parameters", "parameter:get -module NAME", "first")
_spec("parameter:set", "change a parameter; the module sees it next frame", "parameter:set -module NAME -name PARAMETER -value VALUE", "first")


def argument(command: Command, *names: str, positional: bool = True, required: bool = True) -> str:
    """A string argument by name (``-name value``), or the first empty argument (``print BallModel``)."""
    for name in names:
        value = command.args.get(name)
        if isinstance(value, str) and value != "":
            return value
    if positional:
        for key, value in command.args.items():
            if value == "" and key not in names:
                return key
    if required:
        raise CommandError(f"{command.name} needs -{names[0]}; usage: {SPECS[command.name].usage if command.name in SPECS else command.name}")
    return ""


def wants_json(command: Command) -> bool:
    """``-format json`` (for tools and the web page) or ``-format text`` (the default)."""
    wanted = command.args.get("format", "")
    if wanted in ("", "text"):
        return False
    if wanted == "json":
        return True
    raise CommandError(f"-format takes text or json, got {wanted!r}")


class ContextDebug:
    """Answers debug commands about one context; call ``execute`` between that context's frames."""

    def __init__(self, context: str, manager: ModuleManager, *, rate: Callable[[], float] | None = None) -> None:
        self.context = context
        self.manager = manager
        self.state: DebugState = debug_state(manager)  # the context's own debug outputs
        self.rate = rate or (lambda: 0.0)
        self.handlers: dict[str, Callable[[Command], str | bytes]] = {
            name: getattr(self, "cmd_" + name.replace(":", "_")) for name in SPECS
        }
        #: representation name -> the value put on the blackboard before every frame (representation:override)
        self.overrides: dict[str, Any] = {}
        manager.before_frame.append(self._apply_overrides)
        self.reloader = ModuleReloader(manager)

    def _apply_overrides(self) -> None:
        for value in self.overrides.values():
            self.manager.blackboard.set(copy.deepcopy(value))

    def execute(self, command: Command) -> tuple[str, str | bytes]:
        """("ok", text), ("error", message) or ("missing", json of kind, name, known)."""
        handler = self.handlers.get(command.name)
        if handler is None:
            return "error", f"{command.name} is not a context command"
        if "context" in command.args:
            try:
                wanted = Context.of(command.args["context"], "-context", CommandError)
            except CommandError as exc:
                return "error", str(exc)
            if wanted != self.context:
                return "missing", json.dumps(["context", wanted, [self.context]])
        try:
            return "ok", handler(command)
        except NotHere as missing:
            return "missing", json.dumps([missing.kind, missing.name, missing.known])
        except (CommandError, ParameterError, SerializationError, ValueCheckError, TafelError) as exc:
            return "error", str(exc)
        except Exception as exc:  # noqa: BLE001 - a handler bug must not take the loop down
            return "error", f"{command.name} failed: {type(exc).__name__}: {exc}"

    def execute_batch(self, commands: Sequence[Command], budget_s: float | None = None) -> list[tuple[str, str | bytes]]:
        """Answers for the commands in order; with a budget, for as many as fit (at least one)."""
        if budget_s is None:
            return [self.execute(c) for c in commands]
        deadline = time.perf_counter() + budget_s
        answers = []
        for command in commands:
            answers.append(self.execute(command))
            if time.perf_counter() > deadline:
                break
        return answers

    # ------------------------------------------------------------------------------ modules
    def _module_name(self, command: Command) -> str:
        name = argument(command, "module", "name")
        if name not in self.manager.modules:
            raise NotHere("module", name, self.manager.modules)
        return name

    def cmd_modules_list(self, command: Command) -> str:
        timings = self.manager.timings()
        if wants_json(command):
            graph = self.manager.graph()
            errors = self.manager.errors()
            for module in graph["modules"]:
                timing = timings.get(module["name"])
                module.update(mean_us=timing.mean_us if timing else None, max_us=timing.max_us if timing else None,
                              errors=errors.get(module["name"], (0, ""))[0], last_error=errors.get(module["name"], (0, ""))[1])
            return json.dumps(graph)
        lines = [f"order: {' -> '.join(self.manager.order) or '(none)'}"]
        for name in self.manager.modules:
            state = "on" if self.manager.is_enabled(name) else "off"
            timing = timings.get(name)
            if timing:
                lines.append(f"  {name:<28} {state:<3} running  mean {timing.mean_us:8.1f} us  max {timing.max_us:8.1f} us  errors {timing.errors}")
            else:
                lines.append(f"  {name:<28} {state:<3} {'idle (not chosen as provider)' if state == 'on' else 'disabled'}")
        for rep, info in sorted(self.manager.graph()["representations"].items()):
            if len(info["alternatives"]) > 1:
                lines.append(f"  provider {rep}: {info['provider']} (alternatives: {', '.join(info['alternatives'])})")
        return "\n".join(lines)

    def cmd_modules_set(self, command: Command) -> str:
        name = self._module_name(command)
        enabled = parse_bool(argument(command, "enabled", "value", positional=False), "-enabled")
        self.manager.set_enabled(name, enabled)
        return f"{name} {'enabled' if enabled else 'disabled'} in {self.context}; order: {' -> '.join(self.manager.order)}"

    def cmd_module_reload(self, command: Command) -> str:
        return self.reloader.reload(self._module_name(command))

    def cmd_modules_provider(self, command: Command) -> str:
        rep = argument(command, "representation", "name")
        module = argument(command, "module", positional=False)
        if not self.manager.alternatives(rep):
            raise NotHere("representation", rep, self.manager.blackboard.names())
        self.manager.set_provider(rep, module)
        return f"{rep} is provided by {module} in {self.context}"

    def graph(self) -> dict[str, Any]:
        return self.manager.graph()

    # ------------------------------------------------------------------------ representations
    def _representation(self, command: Command) -> Any:
        name = argument(command, "name", "representation")
        if name not in self.manager.blackboard.names():
            raise NotHere("representation", name, self.manager.blackboard.names())
        return self.manager.blackboard.get(name)

    def cmd_representation_list(self, command: Command) -> str:
        providers = {}
        for name in self.manager.blackboard.names():
            try:
                providers[name] = self.manager.provider_of(name) or "from outside (platform or other context)"
            except TafelError:
                providers[name] = "read only here"
        if wants_json(command):
            return json.dumps([{"name": name, "provider": provider} for name, provider in providers.items()])
        return "\n".join(f"  {name:<28} {provider}" for name, provider in providers.items())

    def cmd_representation_print(self, command: Command) -> str:
        rep = self._representation(command)
        if wants_json(command):
            return json.dumps(representation_message(rep, self.context, frame_number(self.manager), frame_time_ns(self.manager)))
        return f"{type(rep).__name__} ({self.context}, frame {self.manager.frame}):\n{pretty(rep, '  ')}"

    def cmd_image_get(self, command: Command) -> bytes:
        name = argument(command, "name", "camera")
        rep = self._representation(command)
        if not isinstance(getattr(rep, "image", None), np.ndarray) or rep.image.ndim != 3:
            raise CommandError(f"{name} holds no camera image; image:get takes a CameraImage such as CameraImageTop")
        text = argument(command, "quality", positional=False, required=False) or "80"
        quality = convert(text, int, where="-quality", bounds=(1, 100), text=True, error=CommandError)
        return jpeg_bytes(rep.image, quality)

    def cmd_representation_get(self, command: Command) -> bytes:
        return serialize(self._representation(command))

    def cmd_representation_set(self, command: Command) -> str:
        rep = self._representation(command)
        data = command.args.get("data")
        if isinstance(data, bytes):
            value = deserialize(type(rep), data)
            check_instance(value)  # finite, the declared shapes and ranges: or nothing changes
            self.manager.blackboard.set(value)
            return f"{type(rep).__name__} set from {len(data)} bytes"
        path = argument(command, "field", positional=False)
        *parents, name = path.split(".")
        owner = rep
        for part in parents:  # -field ball.x: a field of a nested dataclass
            if part not in {f.name for f in fields_of(type(owner))} or not dataclasses.is_dataclass(getattr(owner, part)):
                raise CommandError(f"{type(owner).__name__} has no nested field {part!r}; the fields are "
                                   f"{', '.join(f.name for f in fields_of(type(owner)))}")
            owner = getattr(owner, part)
        infos = {f.name: f for f in fields_of(type(owner))}
        if name not in infos:
            raise CommandError(f"{type(owner).__name__} has no field {name!r}; {did_you_mean(name, infos)}")
        where = f"{type(rep).__name__}.{path}"
        value = check_field(type(owner), name, parse_field_text(infos[name], argument(command, "value", positional=False), where), where)
        setattr(owner, name, value)
        return f"{where} = {_short(value)}"

    def cmd_representation_override(self, command: Command) -> str:
        rep = self._representation(command)
        cls = type(rep)
        data = command.args.get("data")
        if isinstance(data, bytes):
            value = deserialize(cls, data)
        else:
            text = argument(command, "fields", positional=False, required=False) or "{}"
            try:
                fields = json.loads(text)
            except json.JSONDecodeError as exc:
                raise CommandError(f"-fields takes a JSON object of field names and values, e.g. "
                                   f'{{"walk_x": 200}}; {exc.msg} at column {exc.colno}') from None
            if not isinstance(fields, dict):
                raise CommandError('-fields takes a JSON object of field names and values, e.g. {"walk_x": 200}')
            value = cls()
            infos = {f.name: f for f in fields_of(cls)}
            for name, raw in fields.items():
                if name not in infos:
                    raise CommandError(f"{cls.__name__} has no field {name!r}; {did_you_mean(name, infos)}")
                setattr(value, name, check_field(cls, name, raw, f"{cls.__name__}.{name}"))  # enums by name
        check_instance(value)
        self.overrides[cls.__name__] = value
        self._apply_overrides()
        return f"{cls.__name__} overridden in {self.context} until representation:release -name {cls.__name__}"

    def cmd_representation_release(self, command: Command) -> str:
        name = argument(command, "name", "representation")
        if name not in self.manager.blackboard.names():
            raise NotHere("representation", name, self.manager.blackboard.names())
        if self.overrides.pop(name, None) is None:
            raise CommandError(f"{name} is not overridden in {self.context}")
        return f"{name} released in {self.context}"

    # --------------------------------------------------------------------- debug concepts
    def _named(self, command: Command, items: Mapping[str, Any], kind: str) -> Any:
        """The entry ``-name`` of this context (its modules' declarations, or used in its frames)."""
        name = argument(command, "name")
        if name not in items:
            raise NotHere(kind, name, items)
        return items[name]

    def cmd_debug_request_list(self, command: Command) -> str:
        requests = self.state.requests
        if wants_json(command):
            return json.dumps([{"name": name, "on": r.on, "description": r.description} for name, r in sorted(requests.items())])
        return "\n".join(f"  {'on ' if r.on else 'off'} {name}  {r.description}" for name, r in sorted(requests.items())) or "  (none yet)"

    def cmd_debug_request_set(self, command: Command) -> str:
        found = self._named(command, self.state.requests, "debug request")
        found.on = parse_bool(argument(command, "value", "on", positional=False), "-value")
        return f"{found.name} {'on' if found.on else 'off'}"

    def cmd_modify_list(self, command: Command) -> str:
        modifies = self.state.modifies
        if wants_json(command):
            return json.dumps([{"name": name, "value": json_value(m.value), "pinned": m.pinned,
                                "pinned_value": json_value(m.pinned_value) if m.pinned else None}
                               for name, m in sorted(modifies.items())])
        return "\n".join(
            f"  {name} = {_short(m.value)}" + (f"  (pinned to {_short(m.pinned_value)})" if m.pinned else "")
            for name, m in sorted(modifies.items())
        ) or "  (none yet)"

    def cmd_modify_set(self, command: Command) -> str:
        found = self._named(command, self.state.modifies, "modify")
        value = _coerce_like(found.value, argument(command, "value", positional=False), found.name)
        if found.bounds is not None and isinstance(value, (int, float)) and not found.bounds[0] <= value <= found.bounds[1]:
            low, high = found.bounds
            raise CommandError(f"{found.name} takes a number from {low:g} to {high:g} (the parameter's declared range), got {value:g}; "
                               "nothing pinned")
        found.pinned_value = value
        found.pinned = True
        return f"{found.name} pinned to {_short(found.pinned_value)}"

    def cmd_modify_release(self, command: Command) -> str:
        found = self._named(command, self.state.modifies, "modify")
        found.pinned = False
        return f"{found.name} released"

    def cmd_stopwatch_list(self, command: Command) -> str:
        if wants_json(command):
            return json.dumps(self._stopwatches())
        lines = [f"loop: {self.rate():.1f} Hz, frame {self.manager.frame}"]
        lines.append(f"  {'module':<32} {'last':>9} {'mean':>9} {'max':>9} {'p95':>9}  (us)")
        for name, timing in self.manager.timings().items():
            lines.append(f"  {name:<32} {timing.last_us:9.1f} {timing.mean_us:9.1f} {timing.max_us:9.1f} {self.manager.p95_us(name):9.1f}")
        for name, watch in sorted(self.state.stopwatches.items()):
            times = [t / 1000 for t in watch.times_ns]
            if times:
                p95 = sorted(times)[int(0.95 * (len(times) - 1))]
                lines.append(f"  {name:<32} {times[-1]:9.1f} {statistics.fmean(times):9.1f} {max(times):9.1f} {p95:9.1f}")
        return "\n".join(lines)

    def _stopwatches(self) -> dict[str, Any]:
        rows = [{"name": name, "last_us": t.last_us, "mean_us": t.mean_us, "max_us": t.max_us, "p95_us": self.manager.p95_us(name)}
                for name, t in self.manager.timings().items()]
        for name, watch in sorted(self.state.stopwatches.items()):
            times = sorted(t / 1000 for t in watch.times_ns)
            if times:
                rows.append({"name": name, "last_us": watch.times_ns[-1] / 1000, "mean_us": statistics.fmean(times),
                             "max_us": times[-1], "p95_us": times[int(0.95 * (len(times) - 1))]})
        return {"rate_hz": self.rate(), "frame": self.manager.frame, "stopwatches": rows}

    def cmd_plot_get(self, command: Command) -> str:
        plots = self.state.plots
        if not argument(command, "name", required=False):  # the plots with values (declared ones list in tafel modules)
            return "\n".join(f"{name} ({len(p.values)} values, {self.context})" for name, p in sorted(plots.items()) if p.values)
        found = self._named(command, self.state.plots, "plot")
        count = int(argument(command, "count", positional=False, required=False) or len(found.values))
        return "\n".join(f"{frame} {value:.6g}" for frame, value in list(found.values)[-count:])

    def cmd_drawings_get(self, command: Command) -> str:
        canvas = argument(command, "canvas", required=False)
        drawings = self.state.drawings_last
        known = list(dict.fromkeys([*CANVASES, *(d["canvas"] for d in drawings)]))
        if canvas and canvas not in known:
            raise CommandError(f"there is no canvas {canvas!r}; {did_you_mean(canvas, known)}; the canvases are {', '.join(known)}")
        drawings = [d for d in drawings if not canvas or d["canvas"] == canvas]
        return "\n".join(json.dumps({"context": self.context, **d}) for d in drawings)

    # ------------------------------------------------------------------------- parameters
    def _parameters(self, command: Command) -> tuple[str, Any]:
        name = argument(command, "module")
        try:
            instance = self.manager.module(name)
        except (KeyError, TafelError):
            raise NotHere("module", name, self._parameter_modules()) from None
        if instance.parameters is None:
            raise CommandError(f"{name} has no parameters")
        return name, instance.parameters

    def _parameter_modules(self) -> list[str]:
        return [n for n in self.manager.order if getattr(self.manager.module(n), "parameters", None) is not None]

    def cmd_parameter_list(self, command: Command) -> str:
        if wants_json(command):
            return json.dumps({name: json_value(parameter_values(self.manager.module(name).parameters)) for name in self._parameter_modules()})
        lines = []
        for name in self._parameter_modules():
            values = parameter_values(self.manager.module(name).parameters)
            lines.append(f"  {name}: " + ", ".join(f"{k}={_short(v)}" for k, v in values.items()))
        return "\n".join(lines) or "  (no running module has parameters)"

    def cmd_parameter_get(self, command: Command) -> str:
        name, parameters = self._parameters(command)
        return "\n".join(f"{k} = {_short(v)}" for k, v in parameter_values(parameters).items())

    def cmd_parameter_set(self, command: Command) -> str:
        module, parameters = self._parameters(command)
        parameter = argument(command, "name", "parameter", positional=False)
        value = set_parameter(module, parameters, parameter, argument(command, "value", positional=False), client=True)
        return f"{module}.{parameter} = {_short(value)}"

    def parameter_values(self, module: str) -> dict[str, Any] | None:
        """A module's parameters as plain data, checked to load again (for ``parameter:store``)."""
        try:
            instance = self.manager.module(module)
        except (KeyError, TafelError):
            return None
        if instance.parameters is None:
            return None
        values = parameter_values(instance.parameters)
        try:
            make_parameters(type(instance), values)  # what would not load at the next start is not stored
        except ParameterError as exc:
            raise CommandError(f"not stored: {exc}") from None
        return values

    def choices(self) -> dict[str, Any]:
        """Provider choices and disabled modules, for ``modules:store``."""
        return {"providers": self.manager.providers, "disabled": sorted(self.manager.disabled)}


