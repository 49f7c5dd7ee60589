"""One context's frame and its loop: ``ContextRunner`` (sense, hand-overs, execute, act, publish),
``run_context_loop`` (the beat of a context in its own process or thread), and the statistics and
fingerprints of a run.
"""

from __future__ import annotations

import hashlib
import logging
import pickle
import threading
import time
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any

from tafel.core.framework.frame_info import FrameInfo
from tafel.core.framework.manager import ModuleManager
from tafel.core.framework.representation import is_state
from tafel.core.logs.recording import Recorder
from tafel.core.logs.serialization import SerializationError, serialize
from tafel.core.runtime import clock
from tafel.core.runtime.handover import Bundle, apply_bundle, make_bundle
from tafel.core.runtime.platform import EndOfData, Platform, PlatformError
from tafel.core.runtime.program import ContextPlan
from tafel.core.runtime.statistics import PeriodStatistics
from tafel.core.runtime.status import CognitionStatus
from tafel.core.runtime.watchdog import ContextStuck, Watchdog

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
        """One frame at ``time_ns`` (the runtime's clock): sense, write ``FrameInfo``, take the hand-over,
        execute, act, publish."""
        blackboard = self.manager.blackboard
        frame_number = self.manager.frame + 1
        self.platform.sense(self.name, blackboard, frame_number, time_ns)
        own_time = self.platform.frame_time_ns(self.name)
        self.time_ns = own_time if own_time is not None else time_ns
        own_number = self.platform.frame_number_of(self.name)
        info = blackboard.ensure(FrameInfo)  # the frame clock is the runtime's; the platform gives the time
        info.frame_number = own_number if own_number is not None else frame_number
        info.time_ns = self.time_ns
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


