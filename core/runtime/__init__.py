"""The runtime wing: how the contexts of a program are driven frame by frame.

- ``LockstepRuntime`` (simulated clocks; ``lockstep.py``): one thread; motion runs on every motion tick
  and cognition whenever simulated time has passed its next tick, so a 30/100 Hz program gets exactly 3
  cognition frames per 10 motion frames over whole seconds, deterministically. Paced to the wall clock
  by ``speed`` (1 = real time, None = as fast as possible).
- ``ConcurrentRuntime`` (own clocks, or forced; ``concurrent.py``): each context in its own process, so
  Python-heavy cognition cannot take the interpreter lock from motion; motion asks for SCHED_FIFO.
  Hand-overs go through shared memory (``handover.py``), and motion sees in ``CognitionStatus``
  (``status.py``) when cognition stalls or dies.

Both call the same ``ContextRunner.step`` per frame (``context.py``): sense, take hand-overs, execute,
act, publish. ``platform.py`` is the interface every platform implements, ``program.py`` plans a
program's contexts from the configuration, ``clock.py`` is the program's one time base,
``watchdog.py`` ends a context whose module does not return, and ``processes.py`` holds the operating
system's part (signals, scheduling, processes that end with their parent).
"""

from __future__ import annotations

import importlib
from typing import Any

#: name -> the submodule that defines it: loaded when first asked for, so that importing one submodule
#: (``tafel.core.runtime.program``, say) does not pull in the runtimes and what they import
_EXPORTS = {
    **dict.fromkeys(("ConcurrentRuntime", "WorkerSpec", "import_definitions"), "concurrent"),
    **dict.fromkeys(("MAIN_CONTEXT_ORDER", "ContextRunner", "ContextStats", "Limits", "StopFlag", "cognition_watcher",
                     "program_fingerprint", "recorder_hook", "run_context_loop", "state_digest"), "context"),
    **dict.fromkeys(("MAX_IDLE_S", "LockstepRuntime"), "lockstep"),
    **dict.fromkeys(("DUMP_SIGNAL", "SHUTDOWN_GRACE_S", "end_with_parent", "install_signal_handlers", "name_os_thread",
                     "try_realtime"), "processes"),
}

__all__ = sorted(_EXPORTS)


def __getattr__(name: str) -> Any:
    if name in _EXPORTS:
        value = getattr(importlib.import_module(f"tafel.core.runtime.{_EXPORTS[name]}"), name)
        globals()[name] = value
        return value
    raise AttributeError(f"module 'tafel.core.runtime' has no attribute {name!r}")
