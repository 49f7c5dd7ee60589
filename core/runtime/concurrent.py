"""``ConcurrentRuntime``: each context in a process of its own, supervised; for robots and cameras."""

from __future__ import annotations

import contextlib
import faulthandler
import importlib
import logging
import multiprocessing
import os
import queue
import signal
import sys
import threading
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

from tafel.core.framework.errors import TafelError
from tafel.core.framework.extensions import load_modules, loaded_folders
from tafel.core.framework.representation import defining_modules
from tafel.core.logs.recording import QueueSink, Recorder
from tafel.core.runtime import clock
from tafel.core.runtime.context import (
    MAIN_CONTEXT_ORDER,
    ContextRunner,
    ContextStats,
    Limits,
    cognition_watcher,
    recorder_hook,
    run_context_loop,
    state_digest,
)
from tafel.core.runtime.handover import SharedChannel
from tafel.core.runtime.platform import Platform, PlatformError
from tafel.core.runtime.processes import DUMP_SIGNAL, SHUTDOWN_GRACE_S, _watch_parent, keep_freed_memory, try_realtime
from tafel.core.runtime.program import ContextPlan
from tafel.core.runtime.watchdog import STUCK_TIMEOUT_S

log = logging.getLogger("tafel.runtime")


@dataclass
class WorkerSpec:
    """What a context process needs; pickled to the child (module classes travel by reference)."""

    plan: ContextPlan
    platform_class: type[Platform]
    platform_options: dict[str, Any]
    strict: bool
    limits: Limits
    is_main: bool
    inbox_name: str | None
    outbox_name: str | None
    stall_timeout_s: float
    #: the supervisor's process id, taken in the supervisor: a context process that starts slowly may find it already
    #: gone, and its own parent id then names whoever adopted it
    supervisor_pid: int
    realtime_priority: int = 50
    record: list[Any] = field(default_factory=list)
    record_queue: Any = None
    record_switch: Any = None
    #: (function, arguments) run in the context process once its runner exists (debug server wiring)
    setup: tuple[Callable[[ContextRunner, Any], None], Any] | None = None
    #: the program's time 0 on the monotonic clock, shared by every process (``core.clock``)
    clock_origin_ns: int = 0
    #: Python modules imported first, so the process knows every representation the program knows
    imports: tuple[str, ...] = ()
    #: folders of the program's own module files (``--module-path``), imported as the supervisor did
    module_paths: tuple[str, ...] = ()
    #: s a module may run without returning before the context ends (0: no watchdog)
    stuck_timeout_s: float = STUCK_TIMEOUT_S
    #: what the black box keeps of this context (every representation), and where it goes
    blackbox_record: list[Any] = field(default_factory=list)
    blackbox_queue: Any = None
    #: every context waits here until all are ready, so they start together (a barrier, or None)
    start_together: Any = None



def import_definitions(names: Sequence[str]) -> None:
    """Import the modules that define the program's representations; one that fails is named, not fatal
    (the context then fails later, and clearly, only if it really needs what that module defines)."""
    for name in names:
        try:
            importlib.import_module(name)
        except Exception as exc:  # noqa: BLE001 - a user's module may raise anything on import
            log.warning("cannot import %s, which defines representations: %s: %s", name, type(exc).__name__, exc)


#: s a context waits for the others to be ready before it runs alone (a process that never gets there)
START_TOGETHER_TIMEOUT_S = 20.0


def _wait_for_the_others(barrier: Any, stop: Any) -> None:
    """Start the loops together: a context process that imports slowly (a loaded machine, a robot's
    slow disk) would otherwise miss the first frames, and ``--frames N`` would end the main context
    before the other ran at all. A context that fails to start breaks the barrier; one that never
    arrives holds the others ``START_TOGETHER_TIMEOUT_S`` at most."""
    if barrier is None:
        return
    try:
        barrier.wait(timeout=START_TOGETHER_TIMEOUT_S)
    except threading.BrokenBarrierError:
        if not stop.is_set():
            log.warning("not every context started within %g s; the ready ones run without waiting", START_TOGETHER_TIMEOUT_S)


def _worker_main(spec: WorkerSpec, stop: Any, reports: Any) -> None:
    """Entry point of a context process."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # the supervisor decides when to stop
    signal.signal(signal.SIGTERM, lambda *_: stop.set())
    faulthandler.register(DUMP_SIGNAL, all_threads=True)
    keep_freed_memory()  # the frames' large arrays reuse the heap instead of faulting in fresh pages
    threading.Thread(target=_watch_parent, args=(stop, spec.supervisor_pid, spec.record_queue), name="tafel-parent-watch",
                     daemon=True).start()
    clock.set_origin(spec.clock_origin_ns)
    logging.basicConfig(level=logging.WARNING, format=f"[{spec.plan.name}] %(levelname)s %(message)s")
    try:
        load_modules(spec.module_paths)
    except TafelError as exc:  # the supervisor imported them: this is unlikely, and reported when it matters
        log.warning("%s", exc)
    import_definitions(spec.imports)
    realtime = try_realtime(spec.realtime_priority) if spec.plan.name == "motion" else ""
    inbox = SharedChannel.attach(spec.inbox_name) if spec.inbox_name else None
    outbox = SharedChannel.attach(spec.outbox_name) if spec.outbox_name else None
    platform = spec.platform_class(spec.platform_options)

    def send(stats: ContextStats) -> None:
        try:
            reports.send(stats)
        except (BrokenPipeError, OSError):
            stop.set()

    try:
        platform.start(frozenset({spec.plan.name}))
        manager = spec.plan.build_manager(spec.strict)
        runner = ContextRunner(spec.plan, manager, platform, inbox=inbox, outbox=outbox)
        sink = None
        if spec.record and spec.record_queue is not None:
            recorder = Recorder(spec.record)
            sink = QueueSink(spec.record_queue)
            recorder.attach(sink)
            recorder.gate = spec.record_switch.is_set
            runner.after_step.append(recorder_hook(recorder))
        if spec.blackbox_record and spec.blackbox_queue is not None:
            box = Recorder(spec.blackbox_record)
            box.attach(QueueSink(spec.blackbox_queue))
            runner.after_step.append(recorder_hook(box))
        if spec.setup is not None:
            function, arguments = spec.setup
            function(runner, arguments)
        watch = cognition_watcher(inbox, spec.stall_timeout_s) if spec.plan.name == "motion" and inbox else None
        if spec.plan.name == "motion" and watch is None:
            watch = lambda: (False, 0, 0.0)  # noqa: E731 - no cognition context at all
        _wait_for_the_others(spec.start_together, stop)
        final = run_context_loop(runner, spec.limits, stop, is_main=spec.is_main, report=send,
                                 cognition_watch=watch, realtime=realtime, stuck_timeout_s=spec.stuck_timeout_s)
        final.digest = state_digest(manager)
        final.record_dropped = sink.dropped if sink else 0
        send(final)
    except Exception as exc:  # noqa: BLE001 - report instead of dying silently
        if spec.start_together is not None:
            spec.start_together.abort()  # the others start without this context, at once
        log.exception("%s context failed to start", spec.plan.name)
        send(ContextStats(name=spec.plan.name, finished=True, failure=f"{type(exc).__name__}: {exc}"))
    finally:
        platform.stop()
        for channel in (inbox, outbox):
            if channel is not None:
                channel.close()
        if spec.is_main:
            stop.set()



class ConcurrentRuntime:
    """Each context in its own process; the calling process supervises, reports and shuts down."""

    def __init__(self, plans: Mapping[str, ContextPlan], platform_class: type[Platform],
                 platform_options: Mapping[str, Any], *, strict: bool = False, stall_timeout_s: float = 1.0,
                 recorder: Recorder | None = None,
                 worker_setup: tuple[Callable[[ContextRunner, Any], None], Any] | None = None,
                 grace_s: float = SHUTDOWN_GRACE_S, stuck_timeout_s: float = STUCK_TIMEOUT_S,
                 blackbox: Any = None, blackbox_record: Mapping[str, list[Any]] | None = None) -> None:
        self.recorder = recorder
        #: a sink (``core.blackbox.BlackBox``) that every context's representations reach, always
        self.blackbox = blackbox
        self.blackbox_record = dict(blackbox_record or {})
        self.stuck_timeout_s = stuck_timeout_s
        #: s the context processes get to stop once asked; then their stacks are dumped and they are ended
        self.grace_s = grace_s
        self.worker_setup = worker_setup
        self.plans = {name: plan for name, plan in plans.items() if plan.runs}
        if not self.plans:
            raise PlatformError("nothing to run: no context has modules or platform data")
        if not platform_class.concurrent and len(self.plans) > 1:
            raise PlatformError(
                f"platform {platform_class.name!r} feeds both contexts from one simulated world and runs them in "
                "lockstep; run it without --concurrent (the concurrent runtime is for robots and cameras)"
            )
        self.platform_class = platform_class
        self.platform_options = dict(platform_options)
        self.strict = strict
        self.stall_timeout_s = stall_timeout_s
        self.main = next(name for name in MAIN_CONTEXT_ORDER if name in self.plans)
        self.stats: dict[str, ContextStats] = {name: ContextStats(name=name) for name in self.plans}
        self.exit_codes: dict[str, int | None] = {}
        #: contexts whose process died before finishing, with why (the status line and the debug server say so)
        self.dead: dict[str, str] = {}
        self.notices: list[str] = []
        self.on_report: list[Callable[[ConcurrentRuntime], None]] = []
        self._mp = multiprocessing.get_context("spawn")
        self.stop = self._mp.Event()
        self.record_switch = self._mp.Event()
        if recorder is not None:
            recorder.listeners.append(lambda on: self.record_switch.set() if on else self.record_switch.clear())
            if recorder.recording:
                self.record_switch.set()
        self.processes: dict[str, Any] = {}
        self._stopping_since: float | None = None
        self.start_together = self._mp.Barrier(len(self.plans)) if len(self.plans) > 1 else None

    def run(self, limits: Limits) -> dict[str, ContextStats]:
        channels = {name: SharedChannel() for name in self.plans}
        connections = {}
        record_queue = self._mp.Queue(maxsize=8192) if self.recorder is not None else None
        drain = threading.Thread(target=self._drain, args=(record_queue,), daemon=True) if record_queue else None
        if drain:
            drain.start()
        box_queue = self._mp.Queue(maxsize=8192) if self.blackbox is not None else None
        box_drain = threading.Thread(target=self._drain_into, args=(box_queue, self.blackbox), name="tafel-blackbox-drain",
                                     daemon=True) if box_queue is not None else None
        if box_drain is not None:
            box_drain.start()
        try:
            for name, plan in self.plans.items():
                other = "motion" if name == "cognition" else "cognition"
                watch_cognition = name == "motion" and "cognition" in channels
                spec = WorkerSpec(
                    plan=plan, platform_class=self.platform_class, platform_options=self.platform_options,
                    strict=self.strict, limits=limits, is_main=name == self.main,
                    inbox_name=channels[other].name if (plan.handover_in or watch_cognition) and other in channels else None,
                    outbox_name=channels[name].name, stall_timeout_s=self.stall_timeout_s, supervisor_pid=os.getpid(),
                    record=self.recorder.by_context.get(name, []) if self.recorder else [], record_queue=record_queue,
                    record_switch=self.record_switch, setup=self.worker_setup, clock_origin_ns=clock.origin_ns(),
                    imports=tuple(defining_modules()), module_paths=tuple(loaded_folders()), stuck_timeout_s=self.stuck_timeout_s,
                    blackbox_record=self.blackbox_record.get(name, []), blackbox_queue=box_queue,
                    start_together=self.start_together,
                )
                receiver, sender = self._mp.Pipe(duplex=False)
                process = self._mp.Process(target=_worker_main, args=(spec, self.stop, sender), name=f"tafel-{name}", daemon=True)
                process.start()
                sender.close()
                connections[name] = receiver
                self.processes[name] = process
            self._supervise(connections)
        finally:
            self.stop.set()
            since = self._stopping_since
            self._end_processes(self.grace_s if since is None else max(0.0, self.grace_s - (time.monotonic() - since)))
            for channel in channels.values():
                channel.close()
            if drain is not None and record_queue is not None:
                record_queue.put(None)
                drain.join(timeout=30)
            if box_queue is not None and box_drain is not None:
                box_queue.cancel_join_thread()
                with contextlib.suppress(queue.Full):  # a drain that ended early leaves the queue full
                    box_queue.put(None, timeout=1.0)
                # the black box holds the last records before the run's end is reported (and dumped), and the
                # thread never reads from a queue the interpreter's exit is tearing down
                box_drain.join(timeout=5.0)
            if self.recorder is not None:
                self.recorder.forward_dropped += sum(s.record_dropped for s in self.stats.values())
                self.recorder.stop()
        return self.stats

    @staticmethod
    def _drain_into(source: Any, sink: Any) -> None:
        """Supervisor thread: what the context processes sent the black box, into it."""
        while True:
            try:
                item = source.get()
            except Exception:  # noqa: BLE001 - a queue closed or torn down under it (EOFError, OSError, ValueError, TypeError): done
                return
            if item is None:
                return
            sink.write(*item)

    def _drain(self, record_queue: Any) -> None:
        """Supervisor thread: write what the context processes recorded into the one log file."""
        while True:
            item = record_queue.get()
            if item is None:
                return
            sink = self.recorder.sink if self.recorder else None
            if sink is not None:
                sink.write(*item)

    def _supervise(self, connections: dict[str, Any]) -> None:
        from multiprocessing.connection import wait

        reported_dead: set[str] = set()
        open_connections = dict(connections)
        while open_connections:
            ready = wait(list(open_connections.values()), timeout=0.2)
            for name, connection in list(open_connections.items()):
                if connection in ready:
                    try:
                        self.stats[name] = connection.recv()
                    except (EOFError, OSError):
                        del open_connections[name]
                        continue
                    if self.stats[name].finished and self.stats[name].failure and name not in self.dead:
                        self._ended(name, self.stats[name].failure)
                    for hook in self.on_report:
                        hook(self)
            for name, process in self.processes.items():
                if not process.is_alive() and name not in reported_dead:
                    reported_dead.add(name)
                    self.exit_codes[name] = process.exitcode
                    self._read_last_reports(name, open_connections)
                    if not self.stats[name].finished:
                        self._ended(name, f"process died (exit code {process.exitcode})")
                        open_connections.pop(name, None)
                        for hook in self.on_report:
                            hook(self)
            if self.stop.is_set() and all(not p.is_alive() for p in self.processes.values()):
                break
            if not self.processes[self.main].is_alive() and self.main in reported_dead:
                self.stop.set()
            if self.stop.is_set():
                self._stopping_since = self._stopping_since or time.monotonic()
                if time.monotonic() - self._stopping_since > self.grace_s:
                    break  # a context that does not stop in time: run() ends it

    def _read_last_reports(self, name: str, open_connections: dict[str, Any]) -> None:
        """A process that ended may have sent its final report after the last wait: read what is left,
        so that a clean end between two polls is not taken for a death."""
        connection = open_connections.get(name)
        try:
            while connection is not None and connection.poll():
                self.stats[name] = connection.recv()
        except (EOFError, OSError):
            open_connections.pop(name, None)

    def _ended(self, name: str, why: str) -> None:
        """A context died or failed (a stuck module): a failure of the program, whichever context it was.
        Without the main context nothing drives the robot, so the program ends; without cognition motion
        goes on with its safe motions."""
        self.dead[name] = why
        if self.start_together is not None:
            self.start_together.abort()  # whoever still waits for it starts now
        self.stats[name].failure = self.stats[name].failure or why
        consequence = "the program ends" if name == self.main else "the other context keeps running"
        self.notices.append(f"{name} {why}; {consequence}")
        log.error(self.notices[-1])
        if name == self.main:
            self.stop.set()

    def alive(self, name: str) -> bool:
        """Whether the context's process runs (or has not started yet)."""
        return name not in self.dead

    def _end_processes(self, grace_s: float) -> None:
        """Every process this runtime started ends: asked to stop, given the grace period, then its
        stacks are dumped (SIGUSR1) and it is terminated, and killed if even that does not help."""
        deadline = time.monotonic() + grace_s
        for process in self.processes.values():
            process.join(timeout=max(0.0, deadline - time.monotonic()))
        for name, process in self.processes.items():
            if not process.is_alive():
                continue
            message = f"{name} process did not stop within {self.grace_s:g} s; its stacks follow, then it is ended"
            self.notices.append(message)
            self.stats[name].failure = self.stats[name].failure or f"did not stop within {self.grace_s:g} s (stuck?)"
            print(f"tafel: {message}", file=sys.stderr, flush=True)
            try:
                os.kill(process.pid, DUMP_SIGNAL)
                time.sleep(0.3)
            except ProcessLookupError:
                continue
            process.terminate()
            process.join(timeout=1.0)
            if process.is_alive():
                process.kill()
                process.join(timeout=2.0)
