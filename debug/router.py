"""Routing a command: global commands run in place, context commands go to every context that has the
name (``Executor``: in this thread or in another process), and the answers are merged."""

from __future__ import annotations

import json
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

from tafel.core.framework.contexts import Context
from tafel.core.framework.naming import did_you_mean
from tafel.debug.commands import SPECS, CommandError
from tafel.debug.protocol import Command


class Executor:
    """Something that answers context commands in batches: a ``ContextDebug`` or a remote process.

    ``start`` hands a batch over and ``finish`` collects its answers, so that contexts in other
    processes work on their batches at the same time.
    """

    def start(self, commands: Sequence[Command]) -> Any:
        return self.execute_batch(commands)

    def finish(self, started: Any) -> list[tuple[str, str | bytes]]:
        return started

    def execute_batch(self, commands: Sequence[Command]) -> list[tuple[str, str | bytes]]:
        raise NotImplementedError


@dataclass
class GlobalCommand:
    summary: str
    usage: str
    handler: Callable[[Command], str | bytes]


class DebugRouter:
    """Runs commands: globals itself, context commands on every context, answers combined."""

    def __init__(self) -> None:
        self.contexts: dict[str, Executor] = {}
        self.globals: dict[str, GlobalCommand] = {}
        #: context -> names of its modules and representations, to ask only the context that has a name
        self.index: dict[str, set[str]] = {}
        self.register("help", "the commands, or one command's arguments", "help [NAME]", self._help)
        self.register("ping", "answers pong", "ping", lambda command: "pong")
        self.register("auth", "authenticate with the server's token (--debug-token)", "auth TOKEN", lambda command: "authenticated")
        #: what ``hello`` answers: which program this is (platform, pid, start time)
        self.identity = "tafel"
        self.register("hello", "which program this is: platform, process id, start time", "hello", lambda command: self.identity)

    def add_context(self, name: str, executor: Executor, names: set[str] | None = None) -> None:
        self.contexts[name] = executor
        if names is not None:
            self.index[name] = set(names)

    #: commands that need no context and change nothing: answered by the network thread on arrival
    IMMEDIATE = frozenset({"ping", "help", "hello"})

    def wanted_context(self, command: Command) -> str | None:
        """The context ``-context`` names (None without it); ``CommandError`` for a name that is no context
        (``-context takes cognition or motion, got 'Motion'``) or one this program does not run."""
        if "context" not in command.args:
            return None
        wanted = Context.of(command.args["context"], "-context", CommandError)
        if self.contexts and wanted not in self.contexts:
            raise CommandError(f"-context {wanted}: this program runs no {wanted} context; it runs {' and '.join(self.contexts)}")
        return wanted

    def targets(self, command: Command) -> list[str]:
        """The contexts to ask: the one ``-context`` names, else the one that has the named module or
        representation, else all (``wanted_context`` has checked the name)."""
        wanted = command.args.get("context")
        if isinstance(wanted, str) and wanted in self.contexts:
            return [wanted]
        if SPECS[command.name].routing != "merge" and self.index:
            names = {v for k, v in command.args.items() if k in ("module", "name", "representation") and isinstance(v, str)}
            names |= {k for k, v in command.args.items() if v == ""}
            having = [c for c in self.contexts if names & self.index.get(c, set())]
            if having:
                return having
        return list(self.contexts)

    def register(self, name: str, summary: str, usage: str, handler: Callable[[Command], str | bytes]) -> None:
        self.globals[name] = GlobalCommand(summary, usage, handler)

    def names(self) -> list[str]:
        return sorted({*self.globals, *SPECS})

    def _help(self, command: Command) -> str:
        name = next((k for k, v in command.args.items() if v == ""), "") or str(command.args.get("name", ""))
        if name:
            if name in self.globals:
                return f"{name}: {self.globals[name].summary}\nusage: {self.globals[name].usage}"
            if name in SPECS:
                return f"{name}: {SPECS[name].summary}\nusage: {SPECS[name].usage}"
            raise CommandError(f"unknown command {name!r}: {did_you_mean(name, self.names())}")
        lines = [f"{n:<24} {self.globals[n].summary if n in self.globals else SPECS[n].summary}" for n in self.names()]
        return "\n".join(lines)

    def handle_batch(self, commands: Sequence[Command]) -> list[tuple[bool, str | bytes]]:
        """(is_error, answer) per command, in order. Runs of context commands go out as one batch."""
        results: list[tuple[bool, str | bytes] | None] = [None] * len(commands)
        run: list[int] = []

        def flush() -> None:
            if not run:
                return
            wanted = {index: self.targets(commands[index]) for index in run}
            batches = {name: [i for i in run if name in wanted[i]] for name in self.contexts}
            started = {name: executor.start([commands[i] for i in batches[name]])
                       for name, executor in self.contexts.items() if batches[name]}
            per_context = {name: dict(zip(batches[name], self.contexts[name].finish(handle))) for name, handle in started.items()}
            for index in run:
                answers = {name: per_context[name][index] for name in wanted[index] if name in per_context}
                results[index] = merge_answers(commands[index], answers) if answers else (True, "no context is running")
            run.clear()

        for index, command in enumerate(commands):
            if command.name in SPECS:
                try:
                    self.wanted_context(command)
                except CommandError as exc:
                    results[index] = (True, str(exc))
                    continue
                run.append(index)
                continue
            flush()
            handler = self.globals.get(command.name)
            if handler is None:
                results[index] = (True, f"unknown command {command.name!r}: {did_you_mean(command.name, self.names())}")
                continue
            try:
                results[index] = (False, handler.handler(command))
            except CommandError as exc:
                results[index] = (True, str(exc))
            except Exception as exc:  # noqa: BLE001 - a handler bug answers, never crashes the loop
                results[index] = (True, f"{command.name} failed: {type(exc).__name__}: {exc}")
        flush()
        return [r if r is not None else (True, "no answer") for r in results]


def merge_answers(command: Command, answers: Mapping[str, tuple[str, str | bytes]]) -> tuple[bool, str | bytes]:
    """Combine the contexts' answers to one: (is_error, text or bytes)."""
    spec = SPECS[command.name]
    errors = [(ctx, text) for ctx, (status, text) in answers.items() if status == "error"]
    oks = [(ctx, text) for ctx, (status, text) in answers.items() if status == "ok"]
    if spec.routing == "lines":
        if oks:
            return False, "\n".join(str(text) for _, text in oks if text)
        if errors:
            return True, str(errors[0][1])
    if spec.routing in ("first", "lines"):
        if oks and all(text == oks[0][1] for _, text in oks):
            return False, oks[0][1]
        if oks:  # the name exists in several contexts (a representation on both blackboards): show each
            if any(isinstance(text, bytes) for _, text in oks):
                return True, f"{command.name}: the name exists in {' and '.join(c for c, _ in oks)}; add -context NAME"
            if command.args.get("format") == "json":
                return False, json.dumps({ctx: json.loads(text) for ctx, text in oks})
            return False, "\n".join(f"[{ctx}]\n{text}" for ctx, text in oks)
        if errors:
            return True, str(errors[0][1])
        known: set[str] = set()
        kind, name = "name", ""
        for status, text in answers.values():
            if status == "missing":
                kind, name, names = json.loads(text)
                known.update(names)
        return True, f"unknown {kind} {name!r}: {did_you_mean(name, known)}"
    if errors and not oks:
        return True, "; ".join(f"{ctx}: {text}" for ctx, text in errors)
    if command.args.get("format") == "json":  # one JSON object, by context
        return False, json.dumps({**{ctx: json.loads(text) for ctx, text in oks}, **{ctx: {"error": text} for ctx, text in errors}})
    parts = [f"[{ctx}]\n{text}" for ctx, text in oks] + [f"[{ctx}] error: {text}" for ctx, text in errors]
    return False, "\n".join(parts)
