"""The ``tafel`` command line: parse the arguments, hand them to the subcommand's code, turn errors into
exit statuses. Each subcommand's code is imported when it runs (``COMMANDS``), so ``tafel --help`` and
the light commands load no simulator."""

from __future__ import annotations

import argparse
import importlib
import os
import re
import sys
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

from tafel.core.framework.errors import TafelError
from tafel.core.runtime.platform import PlatformError, PlatformOptionError
from tafel.tools.cli.arguments import build_parser
from tafel.tools.launch.errors import UsageError, fail

Command = Callable[[argparse.Namespace, Sequence[str]], int]


@dataclass(frozen=True)
class LazyCommand:
    """A subcommand whose code is ``function`` in ``tafel.tools.<module>``, imported when it runs. With
    ``takes_unknown`` the function also takes the arguments the parser did not know (a platform's
    options, which only the platform can check); otherwise such arguments are an error."""

    module: str
    function: str
    takes_unknown: bool = False

    def target(self) -> Callable[..., int]:
        return getattr(importlib.import_module(f"tafel.tools.{self.module}"), self.function)

    def __call__(self, args: argparse.Namespace, extra: Sequence[str]) -> int:
        if self.takes_unknown:
            return int(self.target()(args, extra))
        if extra:
            fail(f"unrecognized arguments: {' '.join(extra)}")
        return int(self.target()(args))


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
    return COMMANDS["run"](run_args, run_extra)


#: every subcommand and where its code is; nothing of it is imported before it runs
COMMANDS: dict[str, Command] = {
    "run": LazyCommand("launch.run", "command_run", takes_unknown=True),
    "view": command_view,
    "platforms": LazyCommand("cli.listing", "command_platforms", takes_unknown=True),
    "modules": LazyCommand("cli.listing", "command_modules", takes_unknown=True),
    "log": LazyCommand("logs.log_tools", "run_log_command"),
    "console": LazyCommand("viewers.console", "run_console"),
    "match": LazyCommand("simulation.match", "command_match", takes_unknown=True),
    "scenarios": LazyCommand("simulation.scenarios", "command_scenarios"),
    "replay-batch": LazyCommand("simulation.replay_batch", "command_replay_batch"),
    "team": LazyCommand("viewers.team", "run_team"),
    "deploy": LazyCommand("robot.deploy", "run_command"),
    "robots": LazyCommand("robot.deploy", "run_command"),
}


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
    """``tafel ARGV``: the exit status of the subcommand; 2 for wrong arguments or configuration."""
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

