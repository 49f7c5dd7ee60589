"""The runtimes: how the contexts of a program are driven frame by frame.

- ``LockstepRuntime`` (simulated clocks): one thread; motion runs on every motion tick and cognition
  whenever simulated time has passed its next tick, so a 30/100 Hz program gets exactly 3 cognition
  frames per 10 motion frames over whole seconds, deterministically. Paced to the wall clock by
  ``speed`` (1 = real time, None = as fast as possible).
- ``ConcurrentRuntime`` (own clocks, or forced): each context in its own process, so Python-heavy
  cognition cannot take the interpreter lock from motion; motion asks for SCHED_FIFO. Hand-overs go
  through shared memory, and motion sees in ``CognitionStatus`` when cognition stalls or dies.

Both call the same ``ContextRunner.step`` per frame: sense, take hand-overs, execute, act, publish.
"""

from __future__ import annotations

import faulthandler
import hashlib
import importlib
import logging
import multiprocessing
import os
import pickle
import signal
import sys
import threading
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from fractions import Fraction
from typing import Any

from tafel.core import clock
from tafel.core.errors import TafelError
from tafel.core.extensions import load_modules, loaded_folders
from tafel.core.handover import Bundle, LocalChannel, SharedChannel, apply_bundle, make_bundle
from tafel.core.manager import ModuleManager
from tafel.core.platform import EndOfData, Platform, PlatformError
from tafel.core.program import ContextPlan
from tafel.core.recording import QueueSink, Recorder
from tafel.core.representation import defining_modules, is_state
from tafel.core.serialization import SerializationError, serialize
from tafel.core.statistics import PeriodStatistics
from tafel.core.status import CognitionStatus
from tafel.core.watchdog import STUCK_TIMEOUT_S, ContextStuck, Watchdog

log = logging.getLogger("tafel.runtime")

#: the context that drives the frame count (``--frames``) when both run
MAIN_CONTEXT_ORDER = ("motion", "cognition")


@dataclass
class Limits:
    """When to stop: after ``frames`` frames of the main context, ``seconds`` of platform time, or never."""

    frames: int | None = None
    seconds: float | None = None
    #: pace factor against the wall clock; None runs as fast as possible
    speed: float | None = 1.0


@dataclass
class ContextStats:
    """What a context reports about itself (sent between processes, so plain data)."""

    name: str
    frames: int = 0
    wall_s: float = 0.0
    module_errors: int = 0
    errors_by_module: dict[str, int] = field(default_factory=dict)
    #: period errors (ms) in bounded memory: reporting costs the same at any uptime
    period_errors: PeriodStatistics = field(default_factory=PeriodStatistics)
    missed_periods: int = 0
    realtime: str = ""
    frames_without_cognition: int = 0
    digest: str = ""
    record_dropped: int = 0
    finished: bool = False
    failure: str = ""

    @property
    def rate_hz(self) -> float:
        return self.frames / self.wall_s if self.wall_s > 0 else 0.0

    def period_error_percentiles(self) -> dict[str, float]:
        return self.period_errors.percentiles()


def recorder_hook(recorder: Recorder) -> Callable[[ContextRunner], None]:
    def record(runner: ContextRunner) -> None:
        recorder.record(runner.name, runner.manager.blackboard, runner.manager.frame, runner.time_ns)

    return record


def state_digest(manager: ModuleManager) -> str:
    """A short fingerprint of every representation on a blackboard (equal states, equal digests);
    representations declared ``state=False`` (timing) are left out.

    Each is hashed in its serialized form, the form logs hold, so a value read back from a log
    (a Python float where a module wrote a numpy float) counts as the same state.
    """
    digest = hashlib.blake2b(digest_size=8)
    for name in manager.blackboard.names():
        instance = manager.blackboard.get(name)
        if not is_state(type(instance)):
            continue  # timing differs between equal runs; it is no state
        digest.update(name.encode())
        try:
            digest.update(serialize(instance))
        except SerializationError:
            digest.update(pickle.dumps(instance.__dict__, protocol=5))
    return digest.hexdigest()


def program_fingerprint(stats: Mapping[str, ContextStats]) -> str:
    """One fingerprint of a whole program's state: every representation on every blackboard.

    Equal in a live run and in its replay when the replay reproduces it (``tafel log compare`` says
    where it does not); empty when a context could not report its state.
    """
    if not stats or any(not s.digest for s in stats.values()):
        return ""
    digest = hashlib.blake2b(digest_size=8)
    for name in sorted(stats):
        digest.update(f"{name}={stats[name].digest};".encode())
    return digest.hexdigest()


class ContextRunner:
    """One context's frame: sense, take the other context's hand-over, execute, act, publish."""

    def __init__(self, plan: ContextPlan, manager: ModuleManager, platform: Platform,
                 inbox: Any = None, outbox: Any = None) -> None:
        self.plan = plan
        self.name = plan.name
        self.manager = manager
        self.platform = platform
        self.inbox = inbox
        self.outbox = outbox
        self.last_bundle: Bundle | None = None
        self.time_ns = 0
        #: called after every frame (recording, debug data)
        self.after_step: list[Callable[[ContextRunner], None]] = []
        #: waits until the next frame in the concurrent runtime; replaced to do work meanwhile (debug commands)
        self.idle: Callable[[float], None] = time.sleep

    @property
    def frames(self) -> int:
        return self.manager.frame

    def step(self, time_ns: int) -> None:
        blackboard = self.manager.blackboard
        frame_number = self.manager.frame + 1
        self.platform.sense(self.name, blackboard, frame_number, time_ns)
        own_time = self.platform.frame_time_ns(self.name)
        self.time_ns = own_time if own_time is not None else time_ns
        if self.inbox is not None:
            bundle = self.inbox.latest()
            if bundle is not None and bundle is not self.last_bundle:
                apply_bundle(bundle, blackboard, self.plan.handover_in)
                self.last_bundle = bundle
        self.manager.execute()
        self.platform.act(self.name, blackboard)
        if self.outbox is not None and self.plan.handover_out:
            self.outbox.publish(make_bundle(blackboard, self.plan.handover_out, self.manager.frame, self.time_ns))
        for hook in self.after_step:
            hook(self)

    def stats(self, wall_s: float) -> ContextStats:
        errors = {name: count for name, (count, _) in self.manager.errors().items()}
        return ContextStats(
            name=self.name, frames=self.frames, wall_s=wall_s,
            module_errors=sum(errors.values()), errors_by_module=errors,
        )


class StopFlag:
    """Set by a signal handler or another thread; the loops check it between frames."""

    def __init__(self) -> None:
        self._event = threading.Event()

    def set(self) -> None:
        self._event.set()

    def is_set(self) -> bool:
        return self._event.is_set()


#: s a clean stop may take before the program dumps every thread's stack and exits anyway
SHUTDOWN_GRACE_S = 15.0
#: s the lockstep loop waits at most before it looks at its stop flag again
MAX_IDLE_S = 0.1


def install_signal_handlers(stop: Any, on_force: Callable[[], None] | None = None,
                            grace_s: float = SHUTDOWN_GRACE_S) -> list[str]:
    """First Ctrl-C or SIGTERM asks for a clean stop; a second one forces (KeyboardInterrupt).

    A stop that has not finished after ``grace_s`` dumps all threads' stacks to stderr and exits (a
    module stuck in an endless loop, say): a robot program must go away when it is told to, and the
    dump says what held it. Returns the names of the signals received, in order (filled as they come),
    so that the summary can say what stopped the run.
    """

    received: list[str] = []  # signals, counted on their own: a stop the program began itself is not one

    def handle(signum: int, _frame: Any) -> None:
        received.append(signal.Signals(signum).name)
        if len(received) > 1:
            if on_force is not None:
                on_force()
            raise KeyboardInterrupt
        stop.set()
        again = "Ctrl-C again to force; " if signum == signal.SIGINT else ""
        # one line, on a line of its own (the terminal shows ^C after the status line)
        print(f"\nstopping ({again}if that takes over {grace_s:g} s, every thread's stack is dumped and the program exits)",
              file=sys.stderr, flush=True)
        faulthandler.dump_traceback_later(grace_s, exit=True)

    signal.signal(signal.SIGINT, handle)
    signal.signal(signal.SIGTERM, handle)
    return received


# ---------------------------------------------------------------------------------------- lockstep
class LockstepRuntime:
    """Deterministic single-threaded runtime for platforms with a simulated clock."""

    def __init__(self, plans: Mapping[str, ContextPlan], platform: Platform, *, strict: bool = False,
                 recorder: Recorder | None = None, stuck_timeout_s: float = STUCK_TIMEOUT_S) -> None:
        self.platform = platform
        #: s a module may run without returning before ``run`` ends the program (0: no watchdog)
        self.stuck_timeout_s = stuck_timeout_s
        #: context -> why it failed (a stuck module)
        self.failures: dict[str, str] = {}
        self.recorder = recorder
        self.plans = {name: plan for name, plan in plans.items() if plan.runs}
        if not self.plans:
            raise PlatformError("nothing to run: no context has modules or platform data")
        channels = {name: LocalChannel() for name in self.plans}
        self.runners: dict[str, ContextRunner] = {}
        for name, plan in self.plans.items():
            other = "motion" if name == "cognition" else "cognition"
            self.runners[name] = ContextRunner(
                plan, plan.build_manager(strict), platform,
                inbox=channels.get(other) if plan.handover_in else None,
                outbox=channels[name],
            )
        self.main = next(name for name in MAIN_CONTEXT_ORDER if name in self.runners)
        if recorder is not None:
            for runner in self.runners.values():
                runner.after_step.append(recorder_hook(recorder))
        self.ticks = 0
        self._opened = False
        self._main_rate = Fraction(str(self.plans[self.main].rate_hz))
        self._cognition_rate = Fraction(str(self.plans["cognition"].rate_hz)) if "cognition" in self.plans else Fraction(0)
        self._motion_status = self._cognition_status()
        self.time_ns = 0
        self.wall_s = 0.0
        self.stop = StopFlag()
        self.end_reason = ""
        #: called after every tick with the runtime (status lines, debug commands between frames)
        self.after_tick: list[Callable[[LockstepRuntime], None]] = []
        #: waits between ticks when pacing to the wall clock; replaced to do work meanwhile (debug commands)
        self.idle: Callable[[float], None] = time.sleep

    @property
    def managers(self) -> dict[str, ModuleManager]:
        return {name: runner.manager for name, runner in self.runners.items()}

    def open(self) -> None:
        """Start the platform (once); ``run`` does this itself, tests and tools stepping by hand call it."""
        if not self._opened:
            self.platform.start(frozenset(self.runners))
            self._opened = True

    def close(self) -> None:
        """Stop the platform and finish the recording (once)."""
        if self._opened:
            self._opened = False
            self.platform.stop()
            if self.recorder is not None:
                self.recorder.stop()

    def next_time_ns(self) -> int:
        """Platform time of the next tick of the rate schedule."""
        return int(Fraction(self.ticks * 10**9) / self._main_rate)

    def tick(self) -> int:
        """One tick of the rate schedule: the main context's frame, and cognition's if it is due.

        Motion runs first, so cognition sees this tick's motion results (camera matrices).
        Returns the tick's platform time (ns).
        """
        self.open()
        time_ns = self.next_time_ns()
        self.time_ns = time_ns
        self.platform.advance(time_ns)
        cognition = self.runners.get("cognition") if self.main == "motion" else None
        self._update_cognition_status(time_ns)
        self.runners[self.main].step(time_ns)
        # cognition tick k is due at k / cognition_rate seconds: compare exactly
        if cognition is not None and self.ticks * self._cognition_rate >= cognition.frames * self._main_rate:
            cognition.step(time_ns)
        self.ticks += 1
        for hook in self.after_tick:
            hook(self)
        return time_ns

    def run(self, limits: Limits) -> dict[str, ContextStats]:
        self.open()
        start = time.monotonic()
        watchdog = Watchdog(self.managers, self.stuck_timeout_s, on_stuck=self.failures.__setitem__).start() \
            if self.stuck_timeout_s else None
        try:
            if self.platform.drives_schedule:
                self._run_platform_schedule(limits)
            else:
                self._run_rate_schedule(limits)
        except EndOfData as exc:
            self.end_reason = str(exc) or "end of data"
        except ContextStuck:
            self.end_reason = next(iter(self.failures.values()), "a module got stuck")
        finally:
            if watchdog is not None:
                watchdog.stop()
            self.wall_s = time.monotonic() - start
            self.close()
        if self.stop.is_set() and not self.end_reason:
            self.end_reason = "stopped"
        return self.stats()

    #: s the last tick started after its time on the wall clock (0 when on time or unpaced); hooks that do
    #: optional work (debug commands) do less while the loop is behind
    behind_s = 0.0

    def _run_rate_schedule(self, limits: Limits) -> None:
        """Ticks paced to the wall clock (or as fast as possible) until a limit or a stop."""
        start = time.monotonic()
        first = self.ticks
        try:
            while not self.stop.is_set():
                if limits.frames is not None and self.ticks - first >= limits.frames:
                    self.end_reason = f"{limits.frames} {self.main} frames"
                    break
                time_ns = self.next_time_ns()
                if limits.seconds is not None and time_ns >= limits.seconds * 1e9:
                    self.end_reason = f"{limits.seconds:g} s"
                    break
                if limits.speed:
                    delay = start + time_ns * 1e-9 / limits.speed - time.monotonic()
                    self.behind_s = max(0.0, -delay)
                    if delay > MAX_IDLE_S:  # a long wait in slices: a stop is seen within one
                        self.idle(MAX_IDLE_S)
                        continue
                    if delay > 0:
                        self.idle(delay)
                self.tick()
        finally:
            self.time_ns = self.next_time_ns()  # platform time covered by the ticks run

    def _run_platform_schedule(self, limits: Limits) -> None:
        """The platform says which contexts run next and at what time (log replay)."""
        origin: tuple[float, int] | None = None  # (wall, platform time) pacing starts from
        first_ns: int | None = None
        while not self.stop.is_set():
            main = self.runners[self.main]
            if limits.frames is not None and main.frames >= limits.frames:
                self.end_reason = f"{limits.frames} {self.main} frames"
                break
            step = self.platform.next_step()
            if step is None:  # paused
                origin = None
                self.idle(0.01)
                for hook in self.after_tick:
                    hook(self)
                continue
            time_ns, contexts = step
            first_ns = time_ns if first_ns is None else first_ns
            if limits.seconds is not None and time_ns - first_ns >= limits.seconds * 1e9:
                self.end_reason = f"{limits.seconds:g} s"
                break
            if limits.speed:
                if origin is None or time_ns < origin[1]:
                    origin = (time.monotonic(), time_ns)
                delay = origin[0] + (time_ns - origin[1]) * 1e-9 / limits.speed - time.monotonic()
                while delay > 0 and not self.stop.is_set():  # a long wait in slices: a stop is seen within one
                    self.idle(min(delay, MAX_IDLE_S))
                    delay = origin[0] + (time_ns - origin[1]) * 1e-9 / limits.speed - time.monotonic()
            self.time_ns = time_ns
            if "motion" in contexts:
                self._update_cognition_status(time_ns)
            for name in MAIN_CONTEXT_ORDER:
                if name in contexts and name in self.runners:
                    self.runners[name].step(time_ns)
            for hook in self.after_tick:
                hook(self)
        if first_ns is not None:
            self.time_ns -= first_ns

    def _update_cognition_status(self, time_ns: int) -> None:
        """In lockstep cognition is alive by construction; motion sees its last frame and age."""
        cognition = self.runners.get("cognition") if self.main == "motion" else None
        if self._motion_status is not None and cognition is not None:
            self._motion_status.alive = True
            self._motion_status.frame_number = cognition.frames
            self._motion_status.age = (time_ns - cognition.time_ns) * 1e-9 if cognition.frames else 0.0

    def _cognition_status(self) -> CognitionStatus | None:
        runner = self.runners.get("motion")
        if runner is None or CognitionStatus not in runner.manager.blackboard:
            return None
        return runner.manager.blackboard[CognitionStatus]

    def stats(self) -> dict[str, ContextStats]:
        result = {}
        for name, runner in self.runners.items():
            stats = runner.stats(self.wall_s)
            stats.digest = state_digest(runner.manager)
            stats.finished = True
            stats.failure = self.failures.get(name, "")
            result[name] = stats
        return result


# -------------------------------------------------------------------------------------- concurrent
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


def try_realtime(priority: int) -> str:
    """Ask for SCHED_FIFO for the calling thread; returns a sentence saying what was granted."""
    if not hasattr(os, "sched_setscheduler"):
        return "SCHED_FIFO not available on this system"
    try:
        os.sched_setscheduler(0, os.SCHED_FIFO, os.sched_param(priority))
    except PermissionError:
        return "SCHED_FIFO not permitted (run as root or grant CAP_SYS_NICE / rtprio); normal scheduling"
    except OSError as exc:
        return f"SCHED_FIFO refused ({exc.strerror}); normal scheduling"
    return f"SCHED_FIFO priority {priority} granted"


def name_os_thread(name: str) -> None:
    """Give the calling thread a name the operating system shows (``top -H``, ``/proc/PID/task/*/comm``),
    so that a thread's CPU time can be told from the loops'. Linux only; elsewhere nothing happens."""
    if sys.platform != "linux":
        return
    import ctypes

    try:
        ctypes.CDLL(None).prctl(15, name.encode()[:15], 0, 0, 0)  # PR_SET_NAME
    except (OSError, AttributeError):
        pass


def run_context_loop(
    runner: ContextRunner,
    limits: Limits,
    stop: Any,
    *,
    is_main: bool,
    report: Callable[[ContextStats], None],
    cognition_watch: Callable[[], tuple[bool, int, float]] | None = None,
    realtime: str = "",
    stuck_timeout_s: float = 0.0,
) -> ContextStats:
    """Run one context at its own pace until ``stop``, the limits, the end of the data, or a module that
    does not return within ``stuck_timeout_s`` (the watchdog; 0: none).

    With a simulated or wall clock the loop sleeps to absolute deadlines (``deadline += period``), and
    a late frame never shifts the beat; with a platform clock ``sense`` blocks and sets the pace.
    """
    watchdog = Watchdog({runner.name: runner.manager}, stuck_timeout_s).start() if stuck_timeout_s else None
    plan = runner.plan
    own_clock = runner.platform.clock == "own"
    period_ns = int(1e9 / plan.rate_hz)
    status = runner.manager.blackboard[CognitionStatus] if CognitionStatus in runner.manager.blackboard else None
    stats = ContextStats(name=plan.name, realtime=realtime)
    start_ns = time.monotonic_ns()
    deadline = start_ns
    last_report = start_ns
    try:
        while not stop.is_set():
            if is_main and limits.frames is not None and runner.frames >= limits.frames:
                break
            now = time.monotonic_ns()
            if is_main and limits.seconds is not None and now - start_ns >= limits.seconds * 1e9:
                break
            if not own_clock:
                if now < deadline:
                    runner.idle((deadline - now) * 1e-9)
                    now = time.monotonic_ns()
                stats.period_errors.add((now - deadline) / 1e6)
                deadline += period_ns
                while deadline < now - period_ns:  # a whole period lost: skip it, keep the beat
                    deadline += period_ns
                    stats.missed_periods += 1
            if status is not None and cognition_watch is not None:
                alive, frame_number, age = cognition_watch()
                status.alive, status.frame_number, status.age = alive, frame_number, age
                if not alive:
                    stats.frames_without_cognition += 1
            runner.step(clock.from_monotonic_ns(now))  # one time base for both contexts
            if now - last_report >= 1e9:
                last_report = now
                report(_snapshot_stats(runner, stats, start_ns))
    except EndOfData:
        pass
    except ContextStuck:  # the watchdog has said which module and why
        stats.failure = watchdog.stuck if watchdog is not None else "stuck"
    except PlatformError as exc:  # a known failure (lost device, bad data): say it plainly
        stats.failure = str(exc)
        log.error("%s stopped: %s", plan.name, exc)
    except Exception as exc:  # noqa: BLE001 - anything else ends this context with a report
        stats.failure = f"{type(exc).__name__}: {exc}"
        log.exception("%s loop failed", plan.name)
    finally:
        if watchdog is not None:
            watchdog.stop()
    final = _snapshot_stats(runner, stats, start_ns)
    final.finished = True
    report(final)
    return final


def _snapshot_stats(runner: ContextRunner, stats: ContextStats, start_ns: int) -> ContextStats:
    own = runner.stats((time.monotonic_ns() - start_ns) * 1e-9)
    own.period_errors = stats.period_errors.copy()
    own.missed_periods = stats.missed_periods
    own.realtime = stats.realtime
    own.frames_without_cognition = stats.frames_without_cognition
    own.failure = stats.failure
    return own


#: signal the supervisor sends a context process that does not stop in time: dump every stack
DUMP_SIGNAL = signal.SIGUSR1


def _watch_parent(stop: Any, parent: int, record_queue: Any) -> None:
    """End this process when the supervisor is gone (killed with SIGKILL, say): first the clean stop,
    then, if a module is stuck, for good. Linux also sends SIGTERM at once (PR_SET_PDEATHSIG)."""
    _die_with_parent()
    while os.getppid() == parent:  # also while stopping normally: the supervisor still reads the queue
        time.sleep(0.2)
    if record_queue is not None:
        record_queue.cancel_join_thread()  # nobody reads it any more: do not wait at exit to flush it
    stop.set()
    time.sleep(PARENT_GONE_GRACE_S)
    faulthandler.dump_traceback(all_threads=True)
    os._exit(3)


#: s a context process whose supervisor died gets for its clean stop before it ends itself
PARENT_GONE_GRACE_S = 1.5


def _die_with_parent() -> None:
    try:
        import ctypes

        libc = ctypes.CDLL(None, use_errno=True)
        libc.prctl(1, signal.SIGTERM)  # PR_SET_PDEATHSIG
    except (OSError, AttributeError):
        pass  # not Linux: the polling in _watch_parent does the job


def end_with_parent(parent: int) -> None:
    """For a worker process (a batch's pool): end when ``parent`` is gone, whatever killed it.

    Linux sends SIGTERM at the parent's death (PR_SET_PDEATHSIG); a thread also polls for the parent,
    which covers other systems and a parent that died before this call."""
    _die_with_parent()

    def watch() -> None:
        while os.getppid() == parent:
            time.sleep(0.5)
        os._exit(3)

    threading.Thread(target=watch, name="tafel-parent-watch", daemon=True).start()


def import_definitions(names: Sequence[str]) -> None:
    """Import the modules that define the program's representations; one that fails is named, not fatal
    (the context then fails later, and clearly, only if it really needs what that module defines)."""
    for name in names:
        try:
            importlib.import_module(name)
        except Exception as exc:  # noqa: BLE001 - a user's module may raise anything on import
            log.warning("cannot import %s, which defines representations: %s: %s", name, type(exc).__name__, exc)


def _worker_main(spec: WorkerSpec, stop: Any, reports: Any) -> None:
    """Entry point of a context process."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # the supervisor decides when to stop
    signal.signal(signal.SIGTERM, lambda *_: stop.set())
    faulthandler.register(DUMP_SIGNAL, all_threads=True)
    threading.Thread(target=_watch_parent, args=(stop, os.getppid(), spec.record_queue), name="tafel-parent-watch",
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
        final = run_context_loop(runner, spec.limits, stop, is_main=spec.is_main, report=send,
                                 cognition_watch=watch, realtime=realtime, stuck_timeout_s=spec.stuck_timeout_s)
        final.digest = state_digest(manager)
        final.record_dropped = sink.dropped if sink else 0
        send(final)
    except Exception as exc:  # noqa: BLE001 - report instead of dying silently
        log.exception("%s context failed to start", spec.plan.name)
        send(ContextStats(name=spec.plan.name, finished=True, failure=f"{type(exc).__name__}: {exc}"))
    finally:
        platform.stop()
        for channel in (inbox, outbox):
            if channel is not None:
                channel.close()
        if spec.is_main:
            stop.set()


def cognition_watcher(channel: Any, timeout_s: float) -> Callable[[], tuple[bool, int, float]]:
    """Motion's view of cognition: alive while bundles keep arriving within ``timeout_s``."""
    started = time.monotonic_ns()
    state = {"frame": 0, "seen_ns": started}

    def watch() -> tuple[bool, int, float]:
        bundle = channel.latest()
        now = time.monotonic_ns()
        if bundle is not None and bundle.frame_number != state["frame"]:
            state["frame"], state["seen_ns"] = bundle.frame_number, now
        age = (now - state["seen_ns"]) * 1e-9
        return age < timeout_s, state["frame"], age

    return watch


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

    def run(self, limits: Limits) -> dict[str, ContextStats]:
        channels = {name: SharedChannel() for name in self.plans}
        connections = {}
        record_queue = self._mp.Queue(maxsize=8192) if self.recorder is not None else None
        drain = threading.Thread(target=self._drain, args=(record_queue,), daemon=True) if record_queue else None
        if drain:
            drain.start()
        box_queue = self._mp.Queue(maxsize=8192) if self.blackbox is not None else None
        if box_queue is not None:
            threading.Thread(target=self._drain_into, args=(box_queue, self.blackbox), name="tafel-blackbox-drain",
                             daemon=True).start()
        try:
            for name, plan in self.plans.items():
                other = "motion" if name == "cognition" else "cognition"
                watch_cognition = name == "motion" and "cognition" in channels
                spec = WorkerSpec(
                    plan=plan, platform_class=self.platform_class, platform_options=self.platform_options,
                    strict=self.strict, limits=limits, is_main=name == self.main,
                    inbox_name=channels[other].name if (plan.handover_in or watch_cognition) and other in channels else None,
                    outbox_name=channels[name].name, stall_timeout_s=self.stall_timeout_s,
                    record=self.recorder.by_context.get(name, []) if self.recorder else [], record_queue=record_queue,
                    record_switch=self.record_switch, setup=self.worker_setup, clock_origin_ns=clock.origin_ns(),
                    imports=tuple(defining_modules()), module_paths=tuple(loaded_folders()), stuck_timeout_s=self.stuck_timeout_s,
                    blackbox_record=self.blackbox_record.get(name, []), blackbox_queue=box_queue,
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
            if box_queue is not None:
                box_queue.cancel_join_thread()
                box_queue.put(None)
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
            except (EOFError, OSError, ValueError):
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

    def _ended(self, name: str, why: str) -> None:
        """A context died or failed (a stuck module): a failure of the program, whichever context it was.
        Without the main context nothing drives the robot, so the program ends; without cognition motion
        goes on with its safe motions."""
        self.dead[name] = why
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
