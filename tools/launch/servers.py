"""The servers a run offers: the debug server, the web view, the live Foxglove server, and --watch."""

from __future__ import annotations

import argparse
import datetime
import errno
import ipaddress
import os
import sys
from collections.abc import Mapping, Sequence
from importlib.metadata import version
from typing import Any

from tafel.core.framework.errors import TafelError
from tafel.core.logs.recording import Recorder
from tafel.core.runtime.program import ContextPlan
from tafel.tools.launch.debugging import ProgramDebug, handovers_of
from tafel.tools.launch.defaults import DEFAULT_DEBUG_PORT, DEFAULT_FOXGLOVE_PORT
from tafel.tools.launch.errors import fail
from tafel.tools.launch.program import store_dir
from tafel.tools.launch.recording import foxglove_origins, jpeg_quality
from tafel.tools.launch.status import status_print


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
    from tafel.tools.launch.source_watch import SourceWatcher, module_files

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
    from tafel.tools.viewers.foxglove_live import FoxgloveLive

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
    from tafel.tools.viewers.web import WebView

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
    from tafel.tools.viewers.live_feed import feed_order, shared_feed, worker_feed_setup

    names = [rep.__name__ for rep in feed_order(reps)]
    flags, feed = shared_feed(len(names))
    setups.append((worker_feed_setup, {"names": names, "flags": flags, "queue": feed}))
    return flags, feed


