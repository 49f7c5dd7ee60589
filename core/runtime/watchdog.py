"""A watchdog beside a context's loop: it notices a module that does not return and ends that loop.

A module in an endless loop makes no exception and no log line: the loop simply stops making frames.
The watchdog is a thread that looks a few times a second at what the loop's module manager runs
(``ModuleManager.running``). When one module has run for longer than the timeout, it says so, naming
the module, the frame and the time, and raises ``ContextStuck`` in the loop's thread, so the loop ends
the way a failing context ends: in lockstep the program stops with a failure; in the concurrent
runtime the context's process reports the failure and ends, and its supervisor applies the policy for
a context that died.

Time the loop spends outside modules (a platform that waits for its data, a paused log) is no stall.
"""

from __future__ import annotations

import ctypes
import logging
import threading
import time
from collections.abc import Callable, Mapping
from typing import Any

log = logging.getLogger("tafel.watchdog")

#: s one module may run without returning before its context counts as stuck (``runtime.stuck_timeout_s``)
STUCK_TIMEOUT_S = 5.0


class ContextStuck(BaseException):
    """Raised in a loop's thread whose module did not return in time.

    A ``BaseException``, so that the module manager's handling of module errors (which counts and goes
    on) does not swallow it: the context must end."""


class Watchdog:
    """Watches ``managers`` (context name -> ``ModuleManager``) driven by the thread ``thread_id``."""

    def __init__(self, managers: Mapping[str, Any], timeout_s: float = STUCK_TIMEOUT_S, *,
                 thread_id: int | None = None, on_stuck: Callable[[str, str], None] | None = None) -> None:
        if not timeout_s > 0:
            raise ValueError(f"the stuck timeout takes a positive number of seconds, got {timeout_s!r}")
        self.managers = dict(managers)
        self.timeout_s = timeout_s
        self.thread_id = thread_id if thread_id is not None else threading.get_ident()
        #: called once with (context, message) when a context is found stuck, before the loop is interrupted
        self.on_stuck = on_stuck
        #: the message of the stall found, or "" while none was
        self.stuck = ""
        self._done = threading.Event()
        self._thread = threading.Thread(target=self._watch, name="tafel-watchdog", daemon=True)

    def start(self) -> Watchdog:
        self._thread.start()
        return self

    def stop(self) -> None:
        self._done.set()

    def _watch(self) -> None:
        seen: dict[str, tuple[int, str, float]] = {}
        interval = min(0.25, self.timeout_s / 4)
        while not self._done.wait(interval):
            now = time.monotonic()
            for name, manager in self.managers.items():
                state = (manager.frame, manager.running)
                frame, running, since = seen.get(name, (-1, "", now))
                if (frame, running) != state:
                    seen[name] = (*state, now)
                    continue
                if running and now - since >= self.timeout_s:
                    self._report(name, f"stuck: module {running} ran {now - since:.1f} s without returning (frame {frame})")
                    return

    def _report(self, context: str, message: str) -> None:
        self.stuck = message
        log.error("%s %s; the context is ended", context, message)
        if self.on_stuck is not None:
            self.on_stuck(context, message)
        interrupt(self.thread_id, ContextStuck)


def interrupt(thread_id: int, exception: type[BaseException]) -> None:
    """Raise ``exception`` in another thread of this process at its next Python instruction (a module
    blocked inside C code gets it when the call returns)."""
    ctypes.pythonapi.PyThreadState_SetAsyncExc(ctypes.c_ulong(thread_id), ctypes.py_object(exception))
