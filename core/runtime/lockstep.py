"""``LockstepRuntime``: both contexts in one thread, deterministic, for platforms with a simulated clock."""

from __future__ import annotations

import logging
import time
from collections.abc import Callable, Mapping
from fractions import Fraction

from tafel.core.framework.manager import ModuleManager
from tafel.core.logs.recording import Recorder
from tafel.core.runtime.context import MAIN_CONTEXT_ORDER, ContextRunner, ContextStats, Limits, StopFlag, recorder_hook, state_digest
from tafel.core.runtime.handover import LocalChannel
from tafel.core.runtime.platform import EndOfData, Platform, PlatformError
from tafel.core.runtime.processes import keep_freed_memory
from tafel.core.runtime.program import ContextPlan
from tafel.core.runtime.status import CognitionStatus
from tafel.core.runtime.watchdog import STUCK_TIMEOUT_S, ContextStuck, Watchdog

log = logging.getLogger("tafel.runtime")


#: s the lockstep loop waits at most before it looks at its stop flag again
MAX_IDLE_S = 0.1


class LockstepRuntime:
    """Deterministic single-threaded runtime for platforms with a simulated clock."""

    def __init__(self, plans: Mapping[str, ContextPlan], platform: Platform, *, strict: bool = False,
                 recorder: Recorder | None = None, stuck_timeout_s: float = STUCK_TIMEOUT_S) -> None:
        self.platform = platform
        keep_freed_memory()  # the frames' large arrays reuse the heap instead of faulting in fresh pages
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


