"""Operating-system plumbing of a running program: signals and the clean stop, real-time scheduling,
thread names, and processes that end with their parent.
"""

from __future__ import annotations

import faulthandler
import logging
import os
import signal
import sys
import threading
import time
from collections.abc import Callable
from typing import Any

log = logging.getLogger("tafel.runtime")


#: s a clean stop may take before the program dumps every thread's stack and exits anyway
SHUTDOWN_GRACE_S = 15.0


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


#: glibc's mallopt parameters and the values ``keep_freed_memory`` sets: arrays up to 32 MB (the most glibc allows) from
#: the heap instead of fresh mappings, and up to 256 MB of freed heap kept for the next frame
M_TRIM_THRESHOLD, M_MMAP_THRESHOLD = -1, -3
KEPT_TRIM, KEPT_MMAP = 256 << 20, 32 << 20


def keep_freed_memory() -> bool:
    """Let the C allocator keep the memory a frame's large arrays free for the next frame: by default glibc maps every
    allocation above 128 kB afresh (an image of 640x480 is 300 kB) and gives it back when it is freed, and each of its
    pages then faults when first written, frame after frame (issue 34: 350 to 550 faults, 0.5 to 1 ms of the
    cognition's 13 ms of CPU a frame; about 20 faults with this). The process keeps its peak heap. Linux with glibc
    only; elsewhere nothing happens. Whether it was set."""
    if sys.platform != "linux":
        return False
    import ctypes

    try:
        mallopt = ctypes.CDLL(None).mallopt
    except (OSError, AttributeError):  # not glibc
        return False
    return bool(mallopt(M_MMAP_THRESHOLD, KEPT_MMAP)) and bool(mallopt(M_TRIM_THRESHOLD, KEPT_TRIM))


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



#: signal the supervisor sends a context process that does not stop in time: dump every stack
DUMP_SIGNAL = signal.SIGUSR1


def _watch_parent(stop: Any, parent: int, record_queue: Any) -> None:
    """End this process when the supervisor ``parent`` is gone (killed with SIGKILL, say): first the clean stop,
    then, if a module is stuck, for good. Linux also sends SIGTERM at once (PR_SET_PDEATHSIG), but only for a death
    after this call: the poll below also sees a supervisor that died while this process was still starting."""
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


