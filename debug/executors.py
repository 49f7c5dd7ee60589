"""Executors: how the debug server reaches a context, between that context's frames.

``LocalExecutor`` answers in the loop's own thread (lockstep: commands run in the runtime's after-tick
hook); ``RemoteExecutor`` asks a context process through a pipe, and ``worker_debug_setup`` answers
there, a batch at a time within a tenth of a frame period. ``context_debug`` wires a context's manager
to the debug concepts (drawings, plots, module times) and its command handler.
"""

from __future__ import annotations

import multiprocessing
import threading
import time
from collections import deque
from collections.abc import Callable, Mapping, Sequence
from typing import Any

from tafel.core.framework.errors import TafelError
from tafel.core.framework.manager import ModuleManager
from tafel.core.runtime import ContextRunner
from tafel.debug.commands import CommandError, ContextDebug
from tafel.debug.concepts import DebugDrawings, DebugPlots, ModuleTimes, frame_debug_data
from tafel.debug.outputs import debug_state
from tafel.debug.protocol import Command
from tafel.debug.router import Executor

DEBUG_REPRESENTATIONS = (DebugDrawings, DebugPlots, ModuleTimes)
INTERNAL_ERROR = "__error__"  # key of a context's answer to an internal question it could not answer
#: s before a context's next frame when command work stops, so the frame starts on time
RESERVE = 0.002


class RateMeter:
    """Frames per second over the last two seconds of wall time."""

    def __init__(self) -> None:
        self.stamps: deque[float] = deque(maxlen=2000)

    def tick(self) -> None:
        self.stamps.append(time.monotonic())

    def rate(self) -> float:
        now = time.monotonic()
        recent = [t for t in self.stamps if now - t <= 2.0]
        if len(recent) < 2:
            return 0.0
        return (len(recent) - 1) / (recent[-1] - recent[0]) if recent[-1] > recent[0] else 0.0


def instrument(context: str, manager: ModuleManager, meter: RateMeter) -> None:
    """Frame hooks: count the loop's rate, put the frame's drawings, plots and module times on the blackboard
    where something reads them (the context's ``DebugState`` keeps its own frame hooks)."""
    state = debug_state(manager)
    fed = set(manager.external)  # replaying a log feeds recorded debug data: it is shown as recorded

    def after() -> None:
        meter.tick()
        filled = [rep for rep in DEBUG_REPRESENTATIONS if rep in manager.blackboard and rep not in fed]
        if DebugDrawings in filled or DebugPlots in filled:
            drawings, plots = frame_debug_data(state)
            if DebugDrawings in filled:
                manager.blackboard.set(drawings)
            if DebugPlots in filled:
                manager.blackboard.set(plots)
        if ModuleTimes in filled:
            manager.blackboard.set(ModuleTimes(*manager.last_times_ms()))

    manager.after_frame.append(after)


def context_debug(context: str, manager: ModuleManager, recorded: Sequence[type] = ()) -> ContextDebug:
    meter = RateMeter()
    for rep in recorded:
        manager.blackboard.ensure(rep)
    instrument(context, manager, meter)
    return ContextDebug(context, manager, rate=meter.rate)


class LocalExecutor(Executor):
    def __init__(self, debug: ContextDebug) -> None:
        self.debug = debug

    def execute_batch(self, commands: Sequence[Command]) -> list[tuple[str, str | bytes]]:
        return self.debug.execute_batch(commands)

    def internal(self, what: str, argument_: str = "") -> Any:
        return internal_answer(self.debug, what, argument_)


def internal_answer(debug: ContextDebug, what: str, argument_: str) -> Any:
    """Plain data the router needs from a context (graph, choices, parameter values)."""
    if what == "graph":
        return debug.graph()
    if what == "choices":
        return debug.choices()
    if what == "parameters":
        return debug.parameter_values(argument_)
    raise ValueError(what)


class RemoteExecutor(Executor):
    """A context in another process, asked through a pipe; answers arrive between its frames."""

    def __init__(self, context: str, connection: Any, timeout: float = 3.0) -> None:
        self.context = context
        self.connection = connection
        self.timeout = timeout
        self.batch = 0
        self.lock = threading.Lock()
        #: why the context's process is gone, or None while it runs (set by whoever supervises it)
        self.alive: Callable[[], str | None] = lambda: None

    def _ask(self, payload: Any) -> Any:
        with self.lock:
            self.batch += 1
            try:
                self.connection.send((self.batch, payload))
                return self._receive()
            except (OSError, EOFError):
                return None

    def execute_batch(self, commands: Sequence[Command]) -> list[tuple[str, str | bytes]]:
        return self.finish(self.start(commands))

    def start(self, commands: Sequence[Command]) -> Any:
        """Send the batch; the process answers as many as fit in its frame budget."""
        gone = self.alive()
        if gone:  # answer at once: nobody should wait seconds for a context that is not there
            return (list(commands), gone)
        self.lock.acquire()
        self.batch += 1
        try:
            self.connection.send((self.batch, ("commands", list(commands))))
        except (OSError, EOFError):
            return (list(commands), False)
        return (list(commands), True)

    def finish(self, started: Any) -> list[tuple[str, str | bytes]]:
        """Collect the answers, sending what did not fit again until all are answered."""
        commands, sent = started
        if isinstance(sent, str):
            return [("error", f"{self.context} cannot answer: its {sent}")] * len(commands)
        answers: list[tuple[str, str | bytes]] = []
        try:
            while sent:
                part = self._receive()
                if not part:
                    break
                answers.extend(part)
                if len(answers) >= len(commands):
                    return answers
                self.batch += 1
                self.connection.send((self.batch, ("commands", commands[len(answers):])))
        except (OSError, EOFError):
            pass
        finally:
            self.lock.release()
        return answers + [("error", f"{self.context} does not answer (stalled or gone)")] * (len(commands) - len(answers))

    def _receive(self) -> list[Any] | None:
        deadline = time.monotonic() + self.timeout
        while time.monotonic() < deadline:
            if self.connection.poll(max(0.0, deadline - time.monotonic())):
                batch, answers = self.connection.recv()
                if batch == self.batch:
                    return answers
        return None

    def internal(self, what: str, argument_: str = "") -> Any:
        gone = self.alive()
        if gone:
            raise CommandError(f"{self.context} cannot answer: its {gone}")
        answers = self._ask(("internal", (what, argument_)))
        if answers is None:
            raise CommandError(f"{self.context} does not answer (stalled or gone)")
        if isinstance(answers, dict) and INTERNAL_ERROR in answers:
            raise CommandError(answers[INTERNAL_ERROR])
        return answers


def worker_setups(runner: ContextRunner, steps: Sequence[tuple[Callable[..., None], Any]]) -> None:
    """Runs in a context process: every set-up the supervisor asked for (debug, Foxglove), in order."""
    for function, arguments in steps:
        function(runner, arguments)


def worker_debug_setup(runner: ContextRunner, args: Mapping[str, Any]) -> None:
    """Runs in a context process: answer the supervisor's commands between frames."""
    connection = args["connections"].get(runner.name)
    budget = 0.1 / runner.plan.rate_hz  # at most a tenth of a frame period per frame for commands
    debug = context_debug(runner.name, runner.manager, args.get("recorded", {}).get(runner.name, ()))
    if connection is None:
        return

    def answer(budget_s: float) -> None:
        batch, (kind, payload) = connection.recv()
        if kind == "commands":
            connection.send((batch, debug.execute_batch(payload, budget_s=budget_s)))
            return
        try:
            connection.send((batch, internal_answer(debug, *payload)))
        except (TafelError, ValueError) as exc:  # the question cannot be answered: say so, never stop the loop
            connection.send((batch, {INTERNAL_ERROR: str(exc)}))

    def serve(_runner: ContextRunner) -> None:
        while connection.poll():
            answer(budget)

    def idle(seconds: float) -> None:
        """While the loop waits for its next frame: answer batches as they arrive, stopping in time."""
        end = time.perf_counter() + seconds
        work_until = end - min(RESERVE, seconds / 2)
        while (left := work_until - time.perf_counter()) > 0:
            if connection.poll(min(left, 0.005)):
                answer(max(0.0, work_until - time.perf_counter()))
        rest = end - time.perf_counter()
        if rest > 0:
            time.sleep(rest)

    runner.after_step.append(serve)
    runner.idle = idle



def concurrent_pipes(contexts: Sequence[str]) -> tuple[dict[str, Any], dict[str, Any]]:
    """(supervisor ends, worker ends) of one command pipe per context process."""
    mp = multiprocessing.get_context("spawn")
    ours, theirs = {}, {}
    for context in contexts:
        ours[context], theirs[context] = mp.Pipe(duplex=True)
    return ours, theirs


