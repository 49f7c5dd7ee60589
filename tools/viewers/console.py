"""``tafel console``: an interactive debug console with history and tab completion, or one command."""

from __future__ import annotations

import argparse
import re
import sys
from pathlib import Path

from tafel.core.framework.contexts import CONTEXT_NAMES
from tafel.debug.client import DebugClient

HISTORY = Path.home() / ".tafel_history"


def run_console(args: argparse.Namespace) -> int:
    try:
        client = DebugClient(args.host, args.port)
    except OSError as exc:
        print(f"tafel console: error: cannot connect to {args.host}:{args.port}: {exc.strerror or exc}; "
              "is 'tafel run' running, and on which --debug-port?", file=sys.stderr)
        return 2
    with client:
        if args.token:
            answer = client.ask(f"auth {args.token}")
            if answer.startswith("error:"):
                print(answer, file=sys.stderr)
                return 1
        if args.one_command is not None:
            answer = client.ask(args.one_command)
            print(answer)
            return 1 if answer.startswith("error:") else 0
        return interactive(client, f"{args.host}:{args.port}: {client.ask('hello')}")


class Completer:
    """Completes command names, then the names that fit where the cursor is: after
    ``representation:print`` only representations, after ``-module`` only modules, and so on."""

    #: command -> the kind of name its first argument takes
    COMMAND_KINDS = {
        "representation:print": "representations", "representation:get": "representations", "representation:set": "representations",
        "modules:set": "modules", "modules:provider": "representations", "parameter:get": "modules",
        "parameter:set": "modules", "parameter:store": "modules", "debug_request:set": "requests",
        "modify:set": "modify", "modify:release": "modify", "help": "commands",
    }
    #: argument -> the kind of name it takes
    ARGUMENT_KINDS = {"-module": "modules", "-representation": "representations", "-context": "contexts"}
    LISTS = (("modules", "modules:list", r"^\s+(\w+)\s+(?:on|off)\b"), ("representations", "representation:list", r"^\s+(\w+)\s"),
             ("requests", "debug_request:list", r"^\s+(?:on|off)\s+(\S+)"), ("modify", "modify:list", r"^\s+(\S+) ="))

    def __init__(self, client: DebugClient) -> None:
        self.client = client
        self.commands = [line.split()[0] for line in client.ask("help").splitlines() if line.strip()]
        self.names: dict[str, list[str]] = {}
        self.refresh()

    def refresh(self) -> None:
        self.names = {"commands": self.commands, "contexts": list(CONTEXT_NAMES)}
        for kind, command, pattern in self.LISTS:
            answer = self.client.ask(command)
            found = set() if answer.startswith("error:") else {
                m.group(1) for line in answer.splitlines() for m in [re.match(pattern, line)] if m}
            self.names[kind] = sorted(found)

    def candidates(self, text: str, line: str) -> list[str]:
        words = line.split()
        if not words or (len(words) == 1 and not line.endswith(" ")):
            return [c for c in self.commands if c.startswith(text)]
        before = words[-1] if line.endswith(" ") else (words[-2] if len(words) > 1 else "")
        kind = self.ARGUMENT_KINDS.get(before) or self.COMMAND_KINDS.get(words[0].lstrip("+"))
        if kind is None:
            return []
        return [name for name in self.names.get(kind, []) if name.startswith(text)]

    def complete(self, text: str, state: int) -> str | None:
        import readline

        matches = self.candidates(text, readline.get_line_buffer())
        return matches[state] if state < len(matches) else None


def interactive(client: DebugClient, where: str) -> int:
    try:
        import readline
    except ImportError:  # pragma: no cover - not on Linux
        readline = None
    completer = Completer(client)
    if readline is not None:
        readline.set_completer(completer.complete)
        readline.set_completer_delims(" ")
        readline.parse_and_bind("tab: complete")
        if HISTORY.exists():
            readline.read_history_file(HISTORY)
    print(f"connected to {where}; 'help' lists the commands, Ctrl-D leaves")
    try:
        while True:
            try:
                line = input("tafel> ").strip()
            except EOFError:  # Ctrl-D: leave
                print()
                return 0
            except KeyboardInterrupt:  # Ctrl-C: drop the line, as a shell does
                print()
                continue
            if not line:
                continue
            if line in ("quit", "exit"):
                return 0
            try:
                answer = client.ask(line)
            except ConnectionError as exc:
                print(f"connection lost: {exc}", file=sys.stderr)
                return 1
            print(answer)
            if line.split()[0] in ("modules:set", "modules:provider", "debug_request:set"):
                completer.refresh()
    finally:
        if readline is not None:
            readline.set_history_length(1000)
            try:
                readline.write_history_file(HISTORY)
            except OSError:
                pass
    return 0


