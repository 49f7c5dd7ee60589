"""The debug server of one program run and its program-wide commands (``ProgramDebug``): recording,
configuration stores, the module graph of both contexts, the field's geometry. The executors that
reach each context live in ``tafel.debug.executors``.
"""

from __future__ import annotations

import json
import string
from collections.abc import Mapping
from pathlib import Path
from typing import Any, Literal

from tafel.core.framework.config import PRIVATE_FILE, private_section, store_private
from tafel.core.framework.contexts import Context
from tafel.core.framework.dot import contexts_dot
from tafel.core.framework.errors import TafelError
from tafel.core.framework.values import convert
from tafel.core.logs import LogExistsError
from tafel.core.logs.recording import Recorder
from tafel.core.runtime.program import ContextPlan
from tafel.debug.commands import CommandError, argument
from tafel.debug.protocol import Command, parse
from tafel.debug.router import DebugRouter
from tafel.debug.server import DebugServer
from tafel.debug.session import IDLE_TIMEOUT
from tafel.tools.viewers.field import field_geometry


def recording_path(folder: Path, name: str) -> Path:
    """Where ``log:start -file NAME`` records: a plain file name inside the recordings folder.

    A client must never choose where the robot writes: a path, ``..``, or a name that is not an
    ``.mcap`` file is refused with what would be right. (``--record FILE`` on the command line stays
    free: the user typed it.)
    """
    if not name or name != Path(name).name or name in (".", "..") or "/" in name or "\\" in name or "\0" in name:
        raise CommandError(f"log:start takes a plain file name such as run.mcap, not {name!r}; "
                           f"recordings go into the recordings folder {folder} (--record-dir)")
    if not name.endswith(".mcap"):
        raise CommandError(f"log:start records MCAP files: name it {name}.mcap")
    folder.mkdir(parents=True, exist_ok=True)
    path = (folder / name).resolve()
    if path.parent != folder.resolve():  # a symbolic link out of the folder, say
        raise CommandError(f"{name} would leave the recordings folder {folder}")
    return path


class ProgramDebug:
    """The debug server of one program run, with the program-wide commands."""

    def __init__(self, *, host: str, port: int, token: str | None, config_dir: Path, recorder: Recorder | None,
                 record_path_default: Path | None = None, record_dir: Path = Path("logs"), max_connections: int = 32,
                 idle_timeout: float | None = IDLE_TIMEOUT) -> None:
        self.router = DebugRouter()
        self.server = DebugServer(self.router, host, port, token=token, max_connections=max_connections, idle_timeout=idle_timeout)
        self.config_dir = config_dir
        self.recorder = recorder
        self.executors: dict[str, Any] = {}
        #: context -> the plan it started with: what the configuration chose (``modules:store`` stores the rest)
        self.plans: dict[str, ContextPlan] = {}
        self.private_at_start: dict[str, dict[str, Any]] = {}
        self.record_default = record_path_default or Path("tafel.mcap")
        #: the only folder clients may record into (``--record-dir``)
        self.record_dir = record_dir
        router = self.router
        router.register("modules:graph", "Graphviz DOT of both contexts and their hand-overs", "modules:graph", self._graph)
        router.register("modules:store", "write provider choices and disabled modules to config/private/private.toml", "modules:store", self._store_modules)
        router.register("parameter:store", "write a module's parameters to config/private/private.toml", "parameter:store -module NAME", self._store_parameters)
        router.register("log:start", "start recording", "log:start [-file FILE.mcap]", self._log_start)
        router.register("log:stop", "stop recording and finish the file", "log:stop", self._log_stop)
        router.register("log:status", "whether and where recording goes, with counts", "log:status", self._log_status)
        router.register("field:geometry", "the field's lines, circle, marks and goal posts as JSON (mm, field frame)", "field:geometry",
                        lambda command: json.dumps(field_geometry()))
        self.handovers: list[tuple[str, str, str]] = []

    def add_aliases(self, aliases: Mapping[str, Any]) -> None:
        """Commands defined in configuration (``[debug.aliases]``) as a template of another command.

        Each names its ``command`` with ``$argument`` places, its ``arguments`` with defaults (a number:
        the argument takes finite numbers; a list: one of its words, the first by default), and a
        ``summary``. ``motion:walk -x 200`` is how people drive the robot by hand, written as data.
        """
        for name, spec in aliases.items():
            if not isinstance(spec, Mapping) or not isinstance(spec.get("command"), str):
                raise TafelError(f"debug alias {name!r} needs command = 'COMMAND LINE with $ARGUMENTS'")
            arguments = dict(spec.get("arguments", {}))
            template = string.Template(spec["command"])
            try:  # the template must expand to a command that exists, with the defaults
                probe = parse(template.substitute({k: _default(v) for k, v in arguments.items()}))
            except (KeyError, ValueError) as exc:
                raise TafelError(f"debug alias {name!r}: its command does not expand to a command line ({exc})") from None
            if probe.name not in self.router.names():
                raise TafelError(f"debug alias {name!r} runs {probe.name!r}, which is no command")
            usage = name + "".join(f" [-{k} {'|'.join(v) if isinstance(v, list) else 'NUMBER'}]" for k, v in arguments.items())
            self.router.register(name, str(spec.get("summary", f"runs {probe.name}")), usage,
                                 lambda command, t=template, a=arguments, n=name: self._run_alias(n, t, a, command))

    def _run_alias(self, name: str, template: string.Template, arguments: Mapping[str, Any], command: Command) -> str | bytes:
        values = {}
        for key, default in arguments.items():
            given = command.args.get(key)
            text = given if isinstance(given, str) and given != "" else _default(default)
            if isinstance(default, list):  # one of its words, as written
                values[key] = convert(text, Literal[tuple(map(str, default))], where=f"{name}: -{key}", text=False,
                                      expected=" or ".join(map(str, default)), error=CommandError)
            else:
                values[key] = repr(convert(text, float, where=f"{name}: -{key}", text=True, error=CommandError))
        unknown = set(command.args) - set(arguments) - {"context"}
        if unknown:
            raise CommandError(f"{name} has no argument -{sorted(unknown)[0]}; usage: {self.router.globals[name].usage}")
        expanded = parse(template.substitute(values))
        if "context" in command.args:  # the alias's command runs in that context; a context it names itself must be the same
            wanted = Context.of(command.args["context"], f"{name}: -context", CommandError)
            own = str(expanded.args.setdefault("context", wanted.value))
            if own != wanted:
                raise CommandError(f"{name} runs in {own}: leave -context out or give -context {own}")
        ((is_error, answer),) = self.router.handle_batch([expanded])
        if is_error:
            raise CommandError(str(answer))
        return answer

    def add_context(self, name: str, executor: Any, plan: ContextPlan | None = None) -> None:
        self.executors[name] = executor
        if plan is not None:
            self.plans[name] = plan
        try:  # what the private layer said when the program started: modules:store edits from there
            self.private_at_start[name] = private_section(self.config_dir, name)
        except TafelError:
            self.private_at_start[name] = {}
        names = None
        if plan is not None:
            names = {m.__name__ for m in plan.modules} | {r.__name__ for r in plan.representations()}
        self.router.add_context(name, executor, names)

    def add_platform_commands(self, platform: Any) -> None:
        """Replay stepping for the log platform, and whatever commands a platform offers."""
        if all(hasattr(platform, m) for m in ("play", "pause", "step", "goto", "timeline")):
            self.router.register("log:play", "replay: run", "log:play", lambda c: (platform.play(), "playing")[1])
            self.router.register("log:pause", "replay: pause", "log:pause", lambda c: (platform.pause(), "paused")[1])
            self.router.register("log:step", "replay: step N frames (negative: back) and pause", "log:step [-count N]",
                                 lambda c: self._replay_step(platform, c))
            self.router.register("log:goto", "replay: pause at a frame of the main context", "log:goto -frame N",
                                 lambda c: self._replay_goto(platform, c))
            self.router.register("log:position", "replay: where it is, as JSON (frame of the main context, its range, paused)",
                                 "log:position", lambda c: json.dumps(platform.timeline()))
        for name, (summary, handler) in platform.commands().items():
            self.router.register(name, summary, name, lambda c, h=handler: h(dict(c.args)))

    @staticmethod
    def _replay_step(platform: Any, command: Command) -> str:
        count: int = convert(argument(command, "count", required=False) or "1", int, where="-count", text=True, error=CommandError)
        platform.step(count)
        return f"stepping {count}"

    @staticmethod
    def _replay_goto(platform: Any, command: Command) -> str:
        frame: int = convert(argument(command, "frame"), int, where="-frame", text=True, error=CommandError)
        try:
            platform.goto(frame)
        except TafelError as exc:
            raise CommandError(str(exc)) from None
        return f"seeking frame {frame}: replay pauses there (log:position says when)"

    def _graph(self, command: Command) -> str:
        graphs = [executor.internal("graph") for executor in self.executors.values()]
        return contexts_dot(graphs, self.handovers)

    def _store_modules(self, command: Command) -> str:
        """The choices made while the program runs, not what its configuration's layers chose: a platform's
        layer (dummy disables the perception) must not reach every platform through the private layer. Modules
        switched off or on since the start go to the private layer's ``disable`` and ``enable``, which edit the
        layers' ``disabled`` lists wherever they are read."""
        stored = []
        path = self.config_dir / PRIVATE_FILE
        for context, executor in self.executors.items():
            choices, plan = executor.internal("choices"), self.plans.get(context)
            chosen = plan.effective_providers() if plan is not None else {}
            for rep, module in choices["providers"].items():
                if chosen.get(rep) != module:
                    path = store_private(self.config_dir, [context, "providers", rep], module)
                    stored.append(f"{context}.providers.{rep}={module}")
            started = set(plan.effective_disabled()) if plan is not None else set()
            now = set(choices["disabled"])
            private = self.private_at_start.get(context, {})
            disable = sorted((set(private.get("disable", [])) | (now - started)) - (started - now))
            enable = sorted((set(private.get("enable", [])) | (started - now)) - (now - started))
            on_disk = private_section(self.config_dir, context)
            for key, names in (("disable", disable), ("enable", enable)):
                if sorted(on_disk.get(key, [])) != names:
                    path = store_private(self.config_dir, [context, key], names)
                    stored.append(f"{context}.{key}={names}")
        if not stored:
            return "nothing to store: the providers and modules are as the configuration chose them"
        return f"stored in {path}: " + ", ".join(stored)

    def _store_parameters(self, command: Command) -> str:
        module = argument(command, "module")
        for executor in self.executors.values():
            values = executor.internal("parameters", module)
            if values is not None:
                path = None
                try:
                    for name, value in values.items():
                        path = store_private(self.config_dir, ["parameters", module, name], value)
                except TafelError as exc:
                    raise CommandError(str(exc)) from None
                return f"stored {len(values)} parameters of {module} in {path}"
        raise CommandError(f"no running module {module!r} with parameters")

    def _log_start(self, command: Command) -> str:
        if self.recorder is None:
            raise CommandError("this run cannot record (no representations selected)")
        name = argument(command, "file", required=False) or self.record_default.name
        path = recording_path(self.record_dir, name)
        # A client never replaces a file (the user's --record, an older game): it gets the next free name.
        for candidate in [path, *(path.with_name(f"{path.stem}-{n}{path.suffix}") for n in range(1, 1000))]:
            if candidate.exists():
                continue
            try:
                self.recorder.start(candidate, exclusive=True)
            except LogExistsError:  # created meanwhile
                continue
            return f"recording to {candidate}" + (f" ({path.name} exists and is kept)" if candidate != path else "")
        raise CommandError(f"{path} and {path.stem}-1 to -999{path.suffix} exist; choose another name with -file NAME.mcap")

    def _log_stop(self, command: Command) -> str:
        if self.recorder is None or not self.recorder.recording:
            raise CommandError("not recording")
        status = self.recorder.stop()
        return f"stopped recording {status['file']}: {status['messages']} messages, {status['dropped']} dropped"

    def _log_status(self, command: Command) -> str:
        if self.recorder is None:
            return "recording: not available"
        return json.dumps(self.recorder.status())


def _default(value: Any) -> str:
    return str(value[0]) if isinstance(value, list) else repr(float(value))


def handovers_of(plans: Mapping[str, ContextPlan]) -> list[tuple[str, str, str]]:
    return [(rep.__name__, other, name) for name, plan in plans.items() for other in plans if other != name
            for rep in plan.handover_in]
