"""The ``tafel`` command line: the one place that wires core, platforms, modules and debugging together."""

from __future__ import annotations

import argparse
import datetime
import errno
import importlib
import ipaddress
import logging
import os
import pkgutil
import re
import sys
import threading
import time
from collections.abc import Callable, Mapping, Sequence
from importlib.metadata import version
from pathlib import Path
from typing import Any, NoReturn

from tafel.core.framework.config import check_config, edit_modules, load_config
from tafel.core.framework.dot import contexts_dot
from tafel.core.framework.errors import TafelError
from tafel.core.framework.extensions import load_modules
from tafel.core.framework.representation import registered_representations
from tafel.core.logs.blackbox import MAX_MB, SECONDS, BlackBox, conditions_from_config
from tafel.core.logs.recording import Recorder, select
from tafel.core.runtime import (
    ConcurrentRuntime,
    ContextStats,
    Limits,
    LockstepRuntime,
    clock,
    install_signal_handlers,
    program_fingerprint,
    recorder_hook,
)
from tafel.core.runtime.platform import Platform, PlatformError, PlatformOptionError, available_platforms, load_platform
from tafel.core.runtime.program import ContextPlan, plan_program
from tafel.core.runtime.watchdog import STUCK_TIMEOUT_S
from tafel.debug.executors import (
    DEBUG_REPRESENTATIONS,
    LocalExecutor,
    RemoteExecutor,
    concurrent_pipes,
    context_debug,
    worker_debug_setup,
    worker_setups,
)
from tafel.debug.values import frame_number
from tafel.tools.arguments import (
    add_console_command,
    add_deploy_commands,
    add_log_commands,
    add_match_command,
    add_module_path_argument,
    add_replay_batch_command,
    add_scenario_commands,
    add_team_command,
    parse_speed,
    port_number,
    positive,
)
from tafel.tools.debugging import ProgramDebug, handovers_of
from tafel.tools.live_feed import forward

#: the default configuration, shipped inside the package (the repository's config/ folder)
DEFAULT_CONFIG = Path(__file__).resolve().parent.parent / "config"
FALLBACK_PLATFORM = "dummy"
DEFAULT_DEBUG_PORT = 5401
DEFAULT_FOXGLOVE_PORT = 8765
DEFAULT_WEB_PORT = 5480


class UsageError(Exception):
    """Wrong names or arguments: exit status 2 with a message saying what would have been right."""


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


def add_program_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--platform", help="where to run (see 'tafel platforms'); default from configuration")
    parser.add_argument("--config", type=Path, metavar="DIR",
                        help="a configuration folder whose layers go on top of the shipped defaults; "
                             "parameter:store and modules:store write into DIR/private/private.toml")
    parser.add_argument("--robot", help="robot layer config/robot/NAME.toml")
    parser.add_argument("--set", dest="overrides", action="append", default=[], metavar="KEY=VALUE",
                        help="override a configuration value, e.g. runtime.cognition_hz=15 (repeatable)")
    parser.add_argument("--strict", action="store_true",
                        help="modules the platform cannot feed are an error instead of being pruned")
    parser.add_argument("--add-module", action="append", default=[], metavar="CONTEXT:MODULE",
                        help="add a module to a context's list, e.g. cognition:SimpleBallModeler (repeatable)")
    parser.add_argument("--remove-module", action="append", default=[], metavar="CONTEXT:MODULE",
                        help="remove a module from a context's list (repeatable)")
    add_module_path_argument(parser)


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="tafel", description="Run and inspect Tafel robot control programs.")
    commands = parser.add_subparsers(dest="command", metavar="COMMAND")
    commands.required = True

    run = commands.add_parser("run", help="run the program on a platform",
                              epilog="Each platform has options of its own: tafel platforms --verbose lists them.")
    add_program_arguments(run)
    limit = run.add_mutually_exclusive_group()
    limit.add_argument("--seconds", type=positive(float), help="stop after this much platform time")
    limit.add_argument("--frames", type=positive(int), help="stop after N frames of the main context (motion, else cognition)")
    run.add_argument("--speed", type=parse_speed, default=1.0, help="pace against the wall clock: a factor, or 'max'")
    run.add_argument("--concurrent", action="store_true", help="run the contexts in parallel processes")
    run.add_argument("--status-interval", type=positive(float), default=2.0, metavar="S",
                     help="seconds between status lines (default: %(default)s)")
    run.add_argument("-v", "--verbose", action="store_true", help="log informational messages")
    run.add_argument("--record", type=Path, metavar="FILE.mcap", help="record representations into an MCAP log")
    run.add_argument("--record-dir", type=Path, default=Path("logs"), metavar="DIR",
                     help="the only folder debug clients may record into with log:start (default: %(default)s)")
    run.add_argument("--record-reps", metavar="A,B",
                     help="what to record besides the sensor data (default: [recording] representations; 'all': everything)")
    run.add_argument("--debug-port", type=port_number, default=None, metavar="P", help=f"debug server port (default {DEFAULT_DEBUG_PORT}; 0 takes a free one)")
    run.add_argument("--debug-host", default="127.0.0.1", metavar="H", help="debug server address (default: %(default)s)")
    token = run.add_mutually_exclusive_group()
    token.add_argument("--debug-token", metavar="T", help="clients must send 'auth T' first")
    token.add_argument("--debug-token-file", type=Path, metavar="F",
                       help="read the token from a file (it then does not show in ps); a trailing newline is dropped")
    run.add_argument("--debug-max-connections", type=positive(int), default=32, metavar="N",
                     help="debug connections served at once; more get an error line (default: %(default)s)")
    run.add_argument("--debug-idle-timeout", type=positive(float), default=30.0, metavar="S",
                     help="close a debug connection that has not authenticated (without a token: sent no command) "
                          "within S seconds (default: %(default)s)")
    run.add_argument("--no-debug", action="store_true", help="run without the debug server (and without the web view)")
    run.add_argument("--web-port", type=port_number, default=DEFAULT_WEB_PORT, metavar="P",
                     help="serve RobotControl in the browser on the debug server's address at this port "
                          "(default %(default)s; 0 takes a free one)")
    run.add_argument("--no-web", action="store_true", help="run without the web view")
    run.add_argument("--watch", action="store_true",
                     help="reload a module into the running program when its source file changes (keeps the blackboard)")
    run.add_argument("--foxglove", nargs="?", const=f"127.0.0.1:{DEFAULT_FOXGLOVE_PORT}", metavar="[HOST:]PORT",
                     help=f"serve Foxglove and Lichtblick live over WebSocket (default 127.0.0.1:{DEFAULT_FOXGLOVE_PORT}; "
                          "with --debug-token clients must give it: ws://HOST:PORT/?token=T)")

    # the tools' command lines only: each tool's code (MuJoCo for match, protobuf for logs) loads when it runs
    add_log_commands(commands)
    add_console_command(commands)
    add_match_command(commands)
    add_team_command(commands)
    add_scenario_commands(commands)
    add_replay_batch_command(commands)
    add_deploy_commands(commands)

    platforms = commands.add_parser("platforms", help="list the platforms and what they provide and consume")
    platforms.add_argument("--verbose", "-v", action="store_true", help="also list each platform's options")

    view = commands.add_parser("view", help="RobotControl in the browser for a recorded log: play, pause, step and scrub",
                               epilog="The recorded representations are shown as recorded; modules whose outputs the log "
                                      "does not hold run again on the recorded data.")
    view.add_argument("file", type=Path, metavar="FILE.mcap")
    view.add_argument("--web-port", type=port_number, default=DEFAULT_WEB_PORT, metavar="P",
                      help="serve the page at this port (default %(default)s; 0 takes a free one)")
    view.add_argument("--debug-port", type=port_number, default=0, metavar="P", help="debug server port (default: a free one)")
    view.add_argument("--debug-host", default="127.0.0.1", metavar="H", help="the address of both (default: %(default)s)")
    view.add_argument("--debug-token", metavar="T", help="clients and the page must send 'auth T' first")
    view.add_argument("--speed", type=parse_speed, default=1.0, help="playing speed: a factor, or 'max'")
    add_module_path_argument(view)

    modules = commands.add_parser("modules", help="show the module graph of both contexts")
    add_program_arguments(modules)
    modules.add_argument("--dot", action="store_true", help="print Graphviz DOT of both contexts and their hand-overs")
    return parser


def fail(message: str) -> NoReturn:
    raise UsageError(message)


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


# ----------------------------------------------------------------------------------------- run
#: s behind the wall clock, for s of wall time, before a run is called slower than real time
LAG_S, LAG_FOR_S = 1.0, 2.0


class StatusLine:
    """The status line of a run: rates over the last interval, and what ``[status] show`` names.

    Which representations appear is configuration, not code: each shows its ``status_text()`` where
    it has one, and its scalar fields otherwise.
    """

    def __init__(self, platform: str, config: dict[str, Any]) -> None:
        self.platform = platform
        show = config.get("status", {}).get("show", []) if isinstance(config.get("status"), dict) else []
        self.show = [str(name) for name in show] if isinstance(show, list) else []
        self._last: dict[str, tuple[int, float]] = {}
        self._lagging_since: tuple[float, float] | None = None  # (wall s, platform s) since the loop lags
        self._said_slower = False

    def rates(self, stats: dict[str, ContextStats], now: float) -> dict[str, float]:
        """Frames per second of each context since the previous line (since the start for the first)."""
        rates = {}
        for name, s in stats.items():
            frames, then = self._last.get(name, (0, now - s.wall_s))
            rates[name] = (s.frames - frames) / (now - then) if now > then else 0.0
            self._last[name] = (s.frames, now)
        return rates

    def format(self, elapsed_s: float, stats: dict[str, ContextStats], now: float, runners: dict[str, Any] | None = None,
               notices: Sequence[str] = (), dead: Mapping[str, str] | None = None) -> str:
        parts = [f"[tafel] {self.platform} t={elapsed_s:.1f}s"]
        rates = self.rates(stats, now)
        for name, s in stats.items():
            if dead and name in dead:
                parts.append(f"{name} DEAD ({dead[name]}) after {s.frames} frames")
                continue
            state = " FAILED" if s.failure else ""
            parts.append(f"{name} {rates[name]:.1f} Hz {s.frames} frames{state}")
        parts.append(f"module errors {sum(s.module_errors for s in stats.values())}")
        parts.extend(self.shown(runners or {}))
        parts.extend(notices)
        return " | ".join(parts)

    def event(self, elapsed_s: float, text: str) -> str:
        """A line of its own for something that happened (a goal): it is printed when it happens."""
        return f"[tafel] {self.platform} t={elapsed_s:.1f}s {text}"

    def pace(self, now: float, platform_s: float, behind_s: float, speed: float | None) -> str | None:
        """Once, when the run cannot keep the pace asked for: its real-time factor, which is why the rates
        are low. Said when the loop has been ``LAG_S`` behind the wall clock for ``LAG_FOR_S`` and went
        on losing ground meanwhile; a single stall that the loop makes up again is not slowness."""
        if self._said_slower or speed is None:
            return None
        if behind_s < LAG_S:
            self._lagging_since = None
            return None
        if self._lagging_since is None:
            self._lagging_since = (now, platform_s)
            return None
        wall, platform = now - self._lagging_since[0], platform_s - self._lagging_since[1]
        if wall < LAG_FOR_S:
            return None
        factor = platform / wall
        if factor >= 0.98 * speed:  # keeping the pace again, only late from before
            self._lagging_since = (now, platform_s)
            return None
        self._said_slower = True
        slower = "slower than real time" if speed == 1.0 else f"slower than --speed {speed:g} asks"
        return self.event(platform_s, f"{slower}: {factor:.2f}x real time; a frame's work takes longer than its period, "
                                      "so the rates are below the configured ones (said once)")

    def shown(self, runners: dict[str, Any]) -> list[str]:
        texts = []
        for name in self.show:
            for runner in runners.values():
                blackboard = runner.manager.blackboard
                if name in blackboard.names():
                    texts.append(describe(blackboard.get(name)))
                    break
        return texts


def describe(value: Any) -> str:
    """A representation in a few words: its ``status_text()``, else its scalar fields."""
    if hasattr(value, "status_text"):
        return str(value.status_text())
    scalars = [f"{k}={v:.4g}" if isinstance(v, float) else f"{k}={v}" for k, v in vars(value).items()
               if isinstance(v, (bool, int, float, str))]
    return f"{type(value).__name__} " + " ".join(scalars[:6])


def stop_reason(signals: Sequence[str], end_reason: str) -> str:
    """The summary's words for why a run ended: the signal that stopped it (``stopped by SIGINT``), else
    what the runtime says (``stopped after 500 motion frames``); "" when nothing is known."""
    if signals:
        return f"stopped by {signals[0]}"
    if end_reason in ("", "stopped"):  # "stopped": a stop asked for by other means (a debug client)
        return end_reason
    return f"stopped after {end_reason}"


def print_summary(platform: str, mode: str, stats: dict[str, ContextStats], wall_s: float, ran_s: float, reason: str,
                  *, simulated: bool, notes: Sequence[str] = ()) -> None:
    """The summary of a run, all on standard output: ``ran`` is the run's length (platform time covered
    with a simulated clock, the loops' running time otherwise), never the clock's end value; ``reason`` is
    the whole phrase (``stop_reason``)."""
    out = sys.stdout
    time_text = f"{ran_s:.3f} s of platform time" if simulated else f"{ran_s:.3f} s"
    print(f"platform {platform} ({mode}): ran {time_text}" + (f", {reason}" if reason else ""), file=out)
    for note in notes:
        print(f"  {note}", file=out)
    for name, s in stats.items():
        errors = ", ".join(f"{m} {n}" for m, n in sorted(s.errors_by_module.items())) or "none"
        line = f"  {name}: {s.frames} frames, module errors: {errors}"
        if s.failure:
            line += f", FAILED: {s.failure}"
        print(line, file=out)
        if s.period_errors:
            timing = s.period_error_percentiles()
            print(f"    timing: period error p50 {timing['p50_ms']:.2f} ms, p99 {timing['p99_ms']:.2f} ms, "
                  f"max {timing['max_ms']:.2f} ms, missed_periods={s.missed_periods}"
                  + (f", frames_without_cognition={s.frames_without_cognition}" if name == "motion" else ""), file=out)
    fingerprint = program_fingerprint(stats)
    if fingerprint:
        print(f"fingerprint {fingerprint} (the state of every representation; equal runs and faithful replays print the same)", file=out)
    rates = ", ".join(f"{n} {s.rate_hz:.1f} Hz" for n, s in stats.items())
    print(f"wall time {wall_s:.2f} s ({rates})", file=out, flush=True)


def command_run(args: argparse.Namespace, extra: Sequence[str]) -> int:
    logging.basicConfig(level=logging.INFO if args.verbose else logging.WARNING, format="%(name)s %(levelname)s: %(message)s")
    if args.foxglove is not None:
        foxglove_address(args.foxglove)  # a wrong address fails before anything starts
    if args.watch and args.no_debug:
        fail("--watch reloads modules through the debug server; leave out --no-debug (--no-web is fine)")
    if args.record_dir.exists() and not args.record_dir.is_dir():
        fail(f"--record-dir {args.record_dir} is a file; it takes a folder (created when a client records)")
    platform, options, plans, config = prepare(args, extra)
    report_pruned(plans)
    recorder = make_recorder(args, plans, config, platform)
    limits = Limits(frames=args.frames, seconds=args.seconds, speed=args.speed)
    if args.concurrent or type(platform).clock == "own":
        return run_concurrent(args, platform, options, plans, config, recorder, limits)
    return run_lockstep(args, platform, plans, recorder, limits, config)


def start_debug(args: argparse.Namespace, recorder: Recorder | None, plans: dict[str, ContextPlan],
                config: dict[str, Any]) -> ProgramDebug | None:
    """The debug server of this run, not yet listening; None with --no-debug."""
    if args.no_debug:
        return None
    port = DEFAULT_DEBUG_PORT if args.debug_port is None else args.debug_port
    token = debug_token(args)
    if token is None and not is_loopback(args.debug_host):
        print(f"warning: the debug server listens on {args.debug_host} without a token: anybody on that network can "
              "steer this program and record on it; give one with --debug-token-file F (or --debug-token T)",
              file=sys.stderr, flush=True)
    debug = ProgramDebug(host=args.debug_host, port=port, token=token, config_dir=store_dir(args), recorder=recorder,
                         record_dir=args.record_dir, max_connections=args.debug_max_connections,
                         idle_timeout=args.debug_idle_timeout)
    started = datetime.datetime.now().astimezone().isoformat(timespec="seconds")
    debug.router.identity = f"tafel {version('tafel')}: platform {args.platform}, pid {os.getpid()}, started {started}"
    debug.handovers = handovers_of(plans)
    aliases = config.get("debug", {}).get("aliases", {}) if isinstance(config.get("debug"), dict) else {}
    try:
        debug.add_aliases(aliases)
    except TafelError as exc:
        fail(f"configuration: {exc}")
    return debug


def debug_token(args: argparse.Namespace) -> str | None:
    """The token from ``--debug-token`` or ``--debug-token-file``; an empty one is an error, never 'no token'."""
    if args.debug_token_file is not None:
        try:
            token = args.debug_token_file.read_text(encoding="utf-8").rstrip("\r\n")
        except (OSError, UnicodeDecodeError) as exc:
            fail(f"--debug-token-file {args.debug_token_file}: cannot read it ({getattr(exc, 'strerror', None) or exc})")
        if not token.strip():
            fail(f"--debug-token-file {args.debug_token_file} is empty; put the token in it, or leave the option out")
        if "\n" in token or "\r" in token:
            fail(f"--debug-token-file {args.debug_token_file} holds several lines; the token is one line")
        return token
    if args.debug_token is not None and not args.debug_token.strip():
        fail("--debug-token is empty, which would let anybody in; give a token, or leave the option out")
    return args.debug_token


def is_loopback(host: str) -> bool:
    """Whether ``host`` is reachable only from this machine (127.0.0.0/8, ::1, localhost)."""
    if host == "localhost":
        return True
    try:
        return ipaddress.ip_address(host).is_loopback
    except ValueError:
        return False


def watch_sources(args: argparse.Namespace, debug: ProgramDebug | None, plans: Mapping[str, ContextPlan]) -> Any:
    """``--watch``: reload changed module files through the debug server (None without ``--watch``)."""
    if not args.watch or debug is None:
        return None
    from tafel.tools.source_watch import SourceWatcher, module_files

    classes = [cls for plan in plans.values() for cls in plan.modules]
    return SourceWatcher(module_files(classes), lambda line: debug.server.ask(line, timeout=10.0), status_print).start()


def listen(args: argparse.Namespace, debug: ProgramDebug | None) -> None:
    if debug is None:
        return
    try:
        host, port = debug.server.start()
    except OSError as exc:
        # Going on without the server would let the console talk to whatever program holds the port.
        wanted = DEFAULT_DEBUG_PORT if args.debug_port is None else args.debug_port
        reason = "is taken (another tafel run?)" if exc.errno == errno.EADDRINUSE else f"cannot be opened ({exc.strerror or exc})"
        fail(f"debug port {args.debug_host}:{wanted} {reason}; choose another with --debug-port P, "
             "take a free one with --debug-port 0, or run without it with --no-debug")
    print(f"debug server listening on {host}:{port}", flush=True)


def foxglove_address(text: str) -> tuple[str, int]:
    """``--foxglove`` as (host, port): ``PORT`` or ``HOST:PORT``; wrong values exit with status 2."""
    host, _, port = text.rpartition(":")
    try:
        number = int(port)
    except ValueError:
        number = -1
    if not 0 <= number <= 65535:
        fail(f"--foxglove takes [HOST:]PORT with a port from 0 to 65535, e.g. --foxglove {DEFAULT_FOXGLOVE_PORT}; got {text!r}")
    return host.strip("[]") or "127.0.0.1", number


def start_foxglove(args: argparse.Namespace, debug: ProgramDebug | None, config: dict[str, Any], flags: Any = None) -> Any:
    """The live Foxglove server with ``--foxglove``, listening; None without. The caller feeds it."""
    if args.foxglove is None:
        return None
    from tafel.tools.foxglove_live import FoxgloveLive

    host, port = foxglove_address(args.foxglove)
    token = debug_token(args)
    if token is None and not is_loopback(host):
        print(f"warning: the Foxglove server listens on {host} without a token: anybody on that network can watch and "
              "steer this program; give one with --debug-token-file F", file=sys.stderr, flush=True)
    live = FoxgloveLive(host, port, ask=debug.server.ask if debug is not None else None, jpeg_quality=jpeg_quality(config), token=token,
                        flags=flags, origins=foxglove_origins(config))
    try:
        host, port = live.start()
    except Exception as exc:  # noqa: BLE001 - the SDK reports a taken port as a plain RuntimeError
        fail(f"Foxglove server: cannot listen on {host}:{port} ({exc}); choose another port with --foxglove PORT (0: a free one)")
    print(f"foxglove server listening on ws://{host}:{port}", flush=True)
    return live


def web_representations(plans: Mapping[str, ContextPlan]) -> list[type]:
    """Every representation of the program: what the web page may subscribe to."""
    return sorted({rep for plan in plans.values() for rep in plan.representations()}, key=lambda rep: rep.__name__)


def start_web(args: argparse.Namespace, debug: ProgramDebug | None, plans: Mapping[str, ContextPlan], config: dict[str, Any],
              flags: Any = None) -> Any:
    """The web view on the debug server's address, listening; None with --no-web or --no-debug."""
    if debug is None or args.no_web:
        return None
    from tafel.tools.web import WebView

    web = WebView(debug.server, web_representations(plans), host=args.debug_host, port=args.web_port,
                  jpeg_quality=jpeg_quality(config), flags=flags)
    try:
        web.start()
    except OSError as exc:
        reason = "is taken (another tafel run?)" if exc.errno == errno.EADDRINUSE else f"cannot be opened ({exc.strerror or exc})"
        fail(f"web port {args.debug_host}:{args.web_port} {reason}; choose another with --web-port P, "
             "take a free one with --web-port 0, or run without it with --no-web")
    print(f"web view at {web.url()}" + (" (the page asks for the token)" if debug.server.token else ""), flush=True)
    return web


def concurrent_feed(wanted: bool, reps: Sequence[type], setups: list[Any]) -> tuple[Any, Any]:
    """For contexts in other processes: the shared flags and queue of one viewer, and the context
    processes' set-up that feeds them; (None, None) when the viewer is off."""
    if not wanted:
        return None, None
    from tafel.tools.live_feed import feed_order, shared_feed, worker_feed_setup

    names = [rep.__name__ for rep in feed_order(reps)]
    flags, feed = shared_feed(len(names))
    setups.append((worker_feed_setup, {"names": names, "flags": flags, "queue": feed}))
    return flags, feed


def shutdown_grace(config: dict[str, Any]) -> float:
    return float(config.get("runtime", {}).get("shutdown_grace_s", 15.0))


def stuck_timeout(config: dict[str, Any]) -> float:
    """``[runtime] stuck_timeout_s``: s one module may run without returning before its context ends."""
    return float(config.get("runtime", {}).get("stuck_timeout_s", STUCK_TIMEOUT_S))


def run_lockstep(args: argparse.Namespace, platform: Platform, plans: dict[str, ContextPlan], recorder: Recorder | None,
                 limits: Limits, config: dict[str, Any]) -> int:
    # The loops share the interpreter with the debug server's network thread: hand the lock over within
    # 1 ms instead of the default 5 ms, so a busy server delays a frame by a millisecond at the most.
    sys.setswitchinterval(0.001)
    runtime = LockstepRuntime(plans, platform, strict=args.strict, recorder=recorder, stuck_timeout_s=stuck_timeout(config))
    box = make_blackbox(args, plans, config, platform)
    if box is not None:
        for runner in runtime.runners.values():
            runner.after_step.append(recorder_hook(box[1]))
        trigger = blackbox_triggers(box[0])
        runtime.after_tick.append(lambda rt: trigger(rt.time_ns, {n: r.stats(0.0) for n, r in rt.runners.items()}
                                                     if rt.ticks % 10 == 0 else None))
    debug = start_debug(args, recorder, plans, config)
    add_blackbox_commands(debug, box)
    if debug is not None:
        recorded = debug_recorded(recorder, [] if args.no_web else list(plans))
        for name, runner in runtime.runners.items():
            debug.add_context(name, LocalExecutor(context_debug(name, runner.manager, recorded.get(name, ()))), plans[name])
        debug.add_platform_commands(platform)
        # between ticks half a millisecond of commands; while the loop is behind, one (no client starves)
        runtime.after_tick.append(lambda rt: debug.server.process_pending(budget_s=0.0005 if rt.behind_s < 0.001 else 0.0,
                                                                         chunk=8 if rt.behind_s < 0.001 else 1))
        runtime.idle = debug.server.serve_while_idle
    elif recorder is not None:  # no server, but recorded debug data (drawings, module times) is still filled in
        recorded = debug_recorded(recorder)
        for name, runner in runtime.runners.items():
            context_debug(name, runner.manager, recorded.get(name, ()))
    signals = install_signal_handlers(runtime.stop, grace_s=shutdown_grace(config))
    listen(args, debug)
    watcher = watch_sources(args, debug, plans)
    web = start_web(args, debug, plans, config)
    live = start_foxglove(args, debug, config)
    for viewer in (web, live):
        if viewer is not None:
            for runner in runtime.runners.values():
                runner.after_step.append(lambda r, feed=viewer.feed: feed.after_frame(r.name, r.manager.blackboard, r.time_ns, frame_number(r.manager)))
    started = time.monotonic()
    last = [started]
    line = StatusLine(type(platform).name, config)

    def status(rt: LockstepRuntime) -> None:
        now = time.monotonic()
        for event in platform.take_events():
            status_print(line.event(rt.time_ns * 1e-9, event))
        slower = line.pace(now, rt.time_ns * 1e-9, rt.behind_s, limits.speed)
        if slower:
            status_print(slower)
        if now - last[0] >= args.status_interval:
            last[0] = now
            stats = {name: r.stats(now - started) for name, r in rt.runners.items()}
            status_print(line.format(rt.time_ns * 1e-9, stats, now, rt.runners, recording_notices(recorder)))

    runtime.after_tick.append(status)
    try:
        stats = runtime.run(limits)
    finally:
        for viewer in (live, web, watcher):
            if viewer is not None:
                viewer.stop()
        if debug is not None:
            debug.server.stop()
    print_summary(type(platform).name, "lockstep", stats, runtime.wall_s, runtime.time_ns * 1e-9, stop_reason(signals, runtime.end_reason),
                  simulated=True)
    report_recording(recorder)
    if box is not None:
        box[0].finish()
        print(box[0].status(), flush=True)
    return 1 if any(s.failure for s in stats.values()) else 0


def run_concurrent(args: argparse.Namespace, platform: Platform, options: dict[str, Any], plans: dict[str, ContextPlan],
                   config: dict[str, Any], recorder: Recorder | None, limits: Limits) -> int:
    platform.stop()  # each context process makes its own
    platform_class = type(platform)
    debug = start_debug(args, recorder, plans, config)
    setups: list[tuple[Callable[..., None], dict[str, Any]]] = []
    if debug is not None:
        running = [name for name, plan in plans.items() if plan.runs]
        ours, theirs = concurrent_pipes(running)
        setups.append((worker_debug_setup, {"connections": theirs, "recorded": debug_recorded(recorder, [] if args.no_web else list(plans))}))
        for name in running:
            debug.add_context(name, RemoteExecutor(name, ours[name]), plans[name])
    from tafel.tools.foxglove_live import FED

    flags, feed = concurrent_feed(args.foxglove is not None, FED, setups)
    from tafel.tools.web import web_topics

    web_flags, web_feed = concurrent_feed(debug is not None and not args.no_web, web_topics(web_representations(plans)), setups)
    setup = (worker_setups, setups) if setups else None
    stall = float(config.get("runtime", {}).get("stall_timeout_s", 1.0))
    box = make_blackbox(args, plans, config, platform)
    add_blackbox_commands(debug, box)
    runtime = ConcurrentRuntime(plans, platform_class, options, strict=args.strict, stall_timeout_s=stall,
                                recorder=recorder, worker_setup=setup, grace_s=shutdown_grace(config),
                                stuck_timeout_s=stuck_timeout(config), blackbox=box[0] if box else None,
                                blackbox_record=box[1].by_context if box else None)
    if box is not None:
        trigger = blackbox_triggers(box[0])
        runtime.on_report.append(lambda rt: trigger(clock.now_ns(), rt.stats))
    started = time.monotonic()
    last = [started]
    line = StatusLine(platform_class.name, config)
    shown_dead: set[str] = set()
    if debug is not None:
        for name, executor in debug.executors.items():
            executor.alive = lambda name=name: runtime.dead.get(name)

    def on_report(rt: ConcurrentRuntime) -> None:
        now = time.monotonic()
        if now - last[0] >= args.status_interval or set(rt.dead) != shown_dead:
            last[0] = now
            shown_dead.update(rt.dead)
            status_print(line.format(now - started, rt.stats, now, None, [*rt.notices, *recording_notices(recorder)], rt.dead))

    runtime.on_report.append(on_report)
    signals = install_signal_handlers(runtime.stop, on_force=lambda: [p.kill() for p in runtime.processes.values()],
                                      grace_s=shutdown_grace(config))
    if debug is not None:
        listen(args, debug)
        threading.Thread(target=debug.server.dispatch_forever, args=(runtime.stop,), name="tafel-debug-dispatch", daemon=True).start()
    watcher = watch_sources(args, debug, plans)
    web = start_web(args, debug, plans, config, web_flags)
    live = start_foxglove(args, debug, config, flags)
    for viewer, source in ((web, web_feed), (live, feed)):
        if viewer is not None:
            threading.Thread(target=forward, args=(source, viewer.feed, runtime.stop), name="tafel-viewer-forward", daemon=True).start()
    try:
        stats = runtime.run(limits)
    finally:
        for viewer in (live, web, watcher):
            if viewer is not None:
                viewer.stop()
        if debug is not None:
            debug.server.stop()
    realtime = stats.get("motion", ContextStats("motion")).realtime
    notes = ([f"motion: {realtime}"] if realtime else []) + [f"notice: {notice}" for notice in runtime.notices]
    ran = max((s.wall_s for s in stats.values()), default=0.0)
    print_summary(platform_class.name, "concurrent", stats, time.monotonic() - started, ran, stop_reason(signals, ""), simulated=False,
                  notes=notes)
    report_recording(recorder)
    if box is not None:
        box[0].finish()
        print(box[0].status(), flush=True)
    return 1 if any(s.failure for s in stats.values()) else 0


def debug_recorded(recorder: Recorder | None, web_contexts: Sequence[str] = ()) -> dict[str, list[type]]:
    """Per context, the debug representations that must be filled every frame: those the recorder takes,
    and with the web view all of them (its page subscribes to them)."""
    recorded = {} if recorder is None else \
        {context: [s.rep for s in selections if s.source == "debug"] for context, selections in recorder.by_context.items()}
    for context in web_contexts:
        recorded[context] = list(dict.fromkeys([*recorded.get(context, []), *DEBUG_REPRESENTATIONS]))
    return recorded


def status_print(text: str) -> None:
    """A status line on stderr; a closed stream (``tafel run 2>&- ``, a gone terminal) never stops the run."""
    try:
        print(text, file=sys.stderr, flush=True)
    except (OSError, ValueError):
        pass


def make_recorder(args: argparse.Namespace, plans: dict[str, ContextPlan], config: dict[str, Any], platform: Platform) -> Recorder | None:
    """The recorder of this run, started with --record; ready for log:start when the debug server runs."""
    if args.record is None and args.no_debug:
        if args.record_reps:
            fail("--record-reps needs --record FILE.mcap (or the debug server's log:start)")
        return None
    names = [n.strip() for n in args.record_reps.split(",") if n.strip()] if args.record_reps else None
    # Without a beat to keep (lockstep at --speed max) recording waits for the writer rather than drop.
    recorder = program_recorder(plans, config, platform, names, blocking=args.speed is None and not args.concurrent)
    if args.record is not None:
        recorder.start(args.record)
    return recorder


def blackbox_triggers(box: BlackBox) -> Callable[[int, Mapping[str, ContextStats] | None], None]:
    """What the runtime sees that the stream does not say: module exceptions, missed frames, a stalled
    cognition (from the contexts' statistics; None: nothing new to look at)."""
    seen: dict[tuple[str, str], int] = {}

    def check(time_ns: int, stats: Mapping[str, ContextStats] | None) -> None:
        if stats is None:
            return
        for name, s in stats.items():
            for module, count in s.errors_by_module.items():
                if count > seen.get((name, module), 0):
                    box.note(f"module exception in {module}", time_ns)
                seen[(name, module)] = count
            for what, count in (("missed frames", s.missed_periods), ("frames without cognition", s.frames_without_cognition)):
                if count > seen.get((name, what), 0) + 9:  # a few late frames (a start, a busy moment) are no event
                    box.note(f"{name} {what}", time_ns)
                    seen[(name, what)] = count

    return check


def add_blackbox_commands(debug: ProgramDebug | None, box: tuple[BlackBox, Recorder] | None) -> None:
    if debug is None or box is None:
        return
    blackbox = box[0]

    def save(_command: Any) -> str:
        path = blackbox.save("blackbox:save")
        return f"saving the last {blackbox.seconds:g} s to {path}" if path else "not saved: a save happened less than 10 s ago"

    debug.router.register("blackbox:save", "write the black box's last seconds to a log file now", "blackbox:save", save)
    debug.router.register("blackbox:status", "what the black box holds and what it saved", "blackbox:status",
                          lambda _command: blackbox.status())


def make_blackbox(args: argparse.Namespace, plans: dict[str, ContextPlan], config: dict[str, Any],
                  platform: Platform) -> tuple[BlackBox, Recorder] | None:
    """The black-box recorder (``[blackbox]``, on by default) and the recorder that feeds it everything."""
    table = config.get("blackbox", {})
    known = {"enabled", "seconds", "max_mb", "image_period_s", "triggers"}
    unknown = sorted(set(table) - known)
    if unknown:
        fail(f"[blackbox] {unknown[0]} is not a setting; [blackbox] takes {', '.join(sorted(known))}")
    if not table.get("enabled", True):
        return None
    numbers = {key: table.get(key, default) for key, default in (("seconds", SECONDS), ("max_mb", MAX_MB), ("image_period_s", 0.5))}
    for key, value in numbers.items():
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not 0 < value <= 1e6:
            fail(f"blackbox.{key} takes a positive number, got {value!r}")
    feeder = program_recorder(plans, config, platform, ["all"], blocking=False)
    feeder.translate_factory = None
    box = BlackBox(args.record_dir, seconds=float(numbers["seconds"]), max_bytes=int(numbers["max_mb"] * 1e6),
                   heavy_period_s=float(numbers["image_period_s"]), metadata=feeder.metadata,
                   conditions=conditions_from_config(table.get("triggers")))
    box.on_save.append(lambda trigger, path: status_print(f"black box saved ({trigger}): {path}"))
    feeder.attach(box)
    return box, feeder


def program_recorder(plans: dict[str, ContextPlan], config: dict[str, Any], platform: Platform, names: list[str] | None = None,
                     blocking: bool = True) -> Recorder:
    """A recorder of ``names`` (default: the configuration's ``[recording]`` list and all sensor data), not started.

    The log's metadata names the platform and its configuration layers, so that a replay runs the
    program that was recorded (an orange ball's detector, say).
    """
    wanted = names if names is not None else list(config.get("recording", {}).get("representations", []))
    selections = select(plans, wanted, extra=DEBUG_REPRESENTATIONS, strict=names is not None)
    metadata = {"platform": type(platform).name, "config_layers": ",".join(platform.config_layers()),
                **{f"{c}_hz": str(p.rate_hz) for c, p in plans.items()}}
    recorder = Recorder(selections, metadata)
    if config.get("foxglove", {}).get("channels_in_recordings", True):
        recorder.translate_factory = foxglove_recording(recorder, jpeg_quality(config))
    recorder.blocking = blocking
    return recorder


def jpeg_quality(config: dict[str, Any]) -> int:
    """``[foxglove] jpeg_quality`` (1 to 100); anything else exits with status 2 and says so."""
    value = config.get("foxglove", {}).get("jpeg_quality", 80)
    if isinstance(value, bool) or not isinstance(value, int) or not 1 <= value <= 100:
        fail(f"foxglove.jpeg_quality takes a whole number from 1 to 100 (JPEG quality of the images), got {value!r}")
    return value


def foxglove_origins(config: dict[str, Any]) -> list[str]:
    """``[foxglove] origins``: web pages (``"https://app.foxglove.dev"``) whose WebSockets the live server takes besides
    clients that send no Origin (desktop apps); anything but a list of such origins exits with status 2."""
    value = config.get("foxglove", {}).get("origins", [])
    if not isinstance(value, list) or not all(isinstance(o, str) and re.fullmatch(r"https?://[^/\s]+/?", o) for o in value):
        fail(f'foxglove.origins takes a list of web origins such as ["https://app.foxglove.dev"], got {value!r}')
    return value


def foxglove_recording(recorder: Recorder, quality: int) -> Callable[[], Any]:
    """The hook that gives each recorded file Foxglove's channels; their code loads with the first recording."""
    channels: list[Any] = []

    def new_file() -> Any:
        if not channels:
            from tafel.tools.foxglove_channels import RecordingChannels

            channels.append(RecordingChannels(recorder, quality))
        return channels[0].new_file()

    return new_file


def recording_notices(recorder: Recorder | None) -> list[str]:
    """What the status line says about recording when it stopped by itself (a full disk, say)."""
    return [f"RECORDING STOPPED: {recorder.failed}"] if recorder is not None and recorder.failed else []


def report_recording(recorder: Recorder | None) -> None:
    if recorder is None or recorder.path is None:
        return
    status = recorder.status()
    print(f"recorded {recorder.path}: {status['messages']} messages; {recorder.dropped_total()} dropped"
          + (f"; problems: {status['error']}" if status["error"] else ""))


def report_pruned(plans: dict[str, ContextPlan]) -> None:
    for plan in plans.values():
        if not plan.runs:
            print(f"{plan.name}: not running: the platform provides nothing to it", file=sys.stderr)
            continue
        for module, reps in plan.replaced.items():
            print(f"{plan.name}: {module} replaced, the platform provides {', '.join(reps)}", file=sys.stderr)
        for module, missing in plan.pruned.items():
            print(f"{plan.name}: {module} disabled: nothing provides {', '.join(missing)} on this platform", file=sys.stderr)


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
    return 0


def tool_command(module: str, function: str) -> Callable[[argparse.Namespace, Sequence[str]], int]:
    """A command whose code is in ``tafel.tools.<module>`` (loaded when it runs) and that takes no
    arguments beyond its own."""

    def command(args: argparse.Namespace, extra: Sequence[str]) -> int:
        if extra:
            fail(f"unrecognized arguments: {' '.join(extra)}")
        return int(getattr(importlib.import_module(f"tafel.tools.{module}"), function)(args))

    return command


def command_view(args: argparse.Namespace, extra: Sequence[str]) -> int:
    """``tafel view FILE``: ``tafel run`` on the log platform, every recorded representation fed as
    recorded, paused at the first frame and at the end, with the web view's log player."""
    if not args.file.is_file():
        fail(f"{args.file}: no such file; tafel view takes a recorded log (FILE.mcap)")
    argv = ["run", "--platform", "log", "--log", str(args.file), "--replace", "all", "--start-paused", "--hold",
            "--web-port", str(args.web_port), "--debug-port", str(args.debug_port), "--debug-host", args.debug_host,
            "--speed", "max" if args.speed is None else repr(args.speed), "--status-interval", "3600", *extra]
    if args.debug_token is not None:
        argv += ["--debug-token", args.debug_token]
    argv += [a for folder in args.module_path for a in ("--module-path", str(folder))]
    run_args, run_extra = build_parser().parse_known_args(argv)
    return command_run(run_args, run_extra)


def command_match(args: argparse.Namespace, extra: Sequence[str]) -> int:
    from tafel.tools.match import command_match as run_match

    return run_match(args, extra)


COMMANDS = {"run": command_run, "view": command_view, "platforms": command_platforms, "modules": command_modules,
            "log": tool_command("log_tools", "run_log_command"), "console": tool_command("console", "run_console"),
            "match": command_match, "scenarios": tool_command("scenarios", "command_scenarios"),
            "replay-batch": tool_command("replay_batch", "command_replay_batch"),
            "team": tool_command("team", "run_team"), "deploy": tool_command("deploy", "run_command"), "robots": tool_command("deploy", "run_command")}


class PipeSafeStream:
    """Standard output that may be closed under the program (``tafel run | head -1``).

    The first write to a closed pipe points the file descriptor at /dev/null, so the run goes on, its
    summary goes nowhere, and the interpreter's final flush does not fail either.
    """

    def __init__(self, stream: Any) -> None:
        self._stream = stream

    def _quietly(self, action: str, *args: Any) -> Any:
        try:
            return getattr(self._stream, action)(*args)
        except (BrokenPipeError, ValueError):
            try:
                devnull = os.open(os.devnull, os.O_WRONLY)
                os.dup2(devnull, self._stream.fileno())
                os.close(devnull)
            except (OSError, ValueError):
                pass
            return None

    def write(self, text: str) -> int:
        result = self._quietly("write", text)
        return len(text) if result is None else result

    def flush(self) -> None:
        self._quietly("flush")

    def __getattr__(self, name: str) -> Any:
        return getattr(self._stream, name)


#: a value made of numbers and commas that starts with a minus sign: -1500,0,0
NEGATIVE_LIST = re.compile(r"^-\d[\d.]*(,-?[\d.]+)+$")


def join_negative_values(argv: Sequence[str]) -> list[str]:
    """``--start -3000,-1500,0`` as ``--start=-3000,-1500,0``: argparse takes a value that starts with a
    minus sign for an option, and most of the own half has negative x."""
    out: list[str] = []
    for token in argv:
        if out and out[-1].startswith("--") and "=" not in out[-1] and NEGATIVE_LIST.match(token):
            out[-1] = f"{out[-1]}={token}"
        else:
            out.append(token)
    return out


def main(argv: Sequence[str] | None = None) -> int:
    if not isinstance(sys.stdout, PipeSafeStream) and sys.stdout is not None:
        sys.stdout = PipeSafeStream(sys.stdout)
    parser = build_parser()
    args, extra = parser.parse_known_args(join_negative_values(sys.argv[1:] if argv is None else argv))
    if extra and args.command == "platforms":
        parser.error(f"unrecognized arguments: {' '.join(extra)}")
    try:
        return COMMANDS[args.command](args, extra)
    except BrokenPipeError:  # output piped into head and the like
        sys.stderr.close()
        return 0
    except UsageError as exc:
        parser.exit(2, f"tafel {args.command}: error: {exc}\n")
    except (TafelError, KeyError) as exc:
        message = str(exc.args[0]) if isinstance(exc, KeyError) and exc.args else str(exc)
        status = 1 if isinstance(exc, PlatformError) and not isinstance(exc, PlatformOptionError) else 2
        parser.exit(status, f"tafel {args.command}: error: {message}\n")


if __name__ == "__main__":
    sys.exit(main())
