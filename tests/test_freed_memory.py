"""The program keeps the memory its frames' large arrays free (issue 34): glibc's default maps each large allocation
afresh and returns it when freed, so that every frame faulted in the pages of its images, masks and distance
transforms again (350 to 550 minor faults, 0.5 to 1 ms of the cognition's CPU a frame on 640x480 images)."""

from __future__ import annotations

import subprocess
import sys
import textwrap

import pytest

from tafel.core.runtime import LockstepRuntime
from tafel.core.runtime.program import plan_program
from tests.test_program import CONFIG, FullTestPlatform

#: a frame's worth of large temporaries (masks, distance transforms, integral images), made and freed 40 times in a
#: fresh interpreter; prints the minor page faults of the last 30 rounds. ``KEEP``: what runs first.
FRAMES = textwrap.dedent("""
    import resource
    import numpy as np
    KEEP
    def frame():
        arrays = [np.ones(size, np.uint8) for size in (300_000, 1_200_000, 1_000_000, 300_000, 2_400_000, 600_000)]
        return sum(int(a[-1]) for a in arrays)
    for _ in range(10):
        frame()
    before = resource.getrusage(resource.RUSAGE_SELF).ru_minflt
    for _ in range(30):
        frame()
    print(resource.getrusage(resource.RUSAGE_SELF).ru_minflt - before)
""")


def faults(keep: str) -> int:
    result = subprocess.run([sys.executable, "-c", FRAMES.replace("KEEP", keep)], capture_output=True, text=True, check=True, timeout=60)
    return int(result.stdout.strip())


@pytest.mark.skipif(sys.platform != "linux", reason="glibc's allocator")
def test_frames_of_large_arrays_fault_no_pages_once_freed_memory_is_kept() -> None:
    """Without it, the frames fault their arrays' pages in again and again; with it, hardly at all."""
    plain = faults("")
    kept = faults("from tafel.core.runtime.processes import keep_freed_memory; assert keep_freed_memory()")
    assert plain > 30 * 500  # the 5.8 MB a frame holds are 1400 pages: most of them fault again each frame
    assert kept < 30 * 10


def test_the_runtime_keeps_freed_memory(monkeypatch: pytest.MonkeyPatch) -> None:
    """Building a runtime asks for it (the stepped programs, tests and benchmarks run it in their process; each
    context process of a concurrent runtime asks in its own)."""
    import tafel.core.runtime.lockstep as lockstep

    calls: list[bool] = []
    monkeypatch.setattr(lockstep, "keep_freed_memory", lambda: calls.append(True) or True)
    LockstepRuntime(plan_program(CONFIG, FullTestPlatform), FullTestPlatform())
    assert calls == [True]
