"""Ending ``tafel`` subprocesses in tests the way a user does, and holding them to it."""

from __future__ import annotations

import subprocess
import threading
import time

#: s a program may take to stop after SIGTERM (it takes a fraction of a second; its own grace is 15 s)
STOP_WITHIN_S = 10.0


def stop_program(process: subprocess.Popen, readers: list[threading.Thread], output: list[str], errors: list[str]) -> tuple[str, str]:
    """SIGTERM, wait, and the program's whole output; fails, showing the stack dump, if stopping took too long."""
    started = time.monotonic()
    process.terminate()
    process.wait(timeout=30)
    for reader in readers:
        reader.join(timeout=10)
    took = time.monotonic() - started
    # a program must go away when told; after its grace period it dumps every thread's stack: show it
    assert took < STOP_WITHIN_S, f"the program took {took:.1f} s to stop:\n" + "".join(errors)[-6000:]
    return "".join(output), "".join(errors)
