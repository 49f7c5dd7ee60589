"""Who used the machine's cores over a stretch of a test: the machine's idle cores and one process tree's.

Tests that judge a program's loop rates under a load need this to tell the load's doing from the machine's:
when the cores are used up (the load's own clients and log readers run on the same machine, where on a robot
they would be elsewhere), a program paced by its own computing slows whatever it does. Linux only (``/proc``).
"""

from __future__ import annotations

import os
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import TypeVar

from tafel.tools.simulation.match import cpu_seconds


@dataclass(frozen=True)
class CpuSample:
    """Counters at one moment: monotonic time (s), the machine's idle and total ticks, each process's CPU s so far."""

    at_s: float
    machine_idle_ticks: int
    machine_total_ticks: int
    process_cpu_s: dict[int, float]


@dataclass(frozen=True)
class CpuUse:
    """Average use between two samples, in cores (1.0 = one core busy all the time)."""

    seconds: float
    machine_idle_cores: float
    tree_cores: float
    #: the busiest process of the tree: a process's loops share its one interpreter, so it cannot use more than 1.0
    busiest_process_cores: float

    def __str__(self) -> str:
        return (f"{self.tree_cores:.2f} cores for the program, {self.busiest_process_cores:.2f} in its busiest process, "
                f"{self.machine_idle_cores:.2f} idle, over {self.seconds:.1f} s")


def _tree(pid: int) -> list[int]:
    """``pid`` and every process below it (threads' children included)."""
    found, queue = [], [pid]
    while queue:
        current = queue.pop()
        found.append(current)
        for task in Path(f"/proc/{current}/task").glob("*/children"):
            try:
                queue.extend(int(child) for child in task.read_text().split())
            except OSError:  # the task ended meanwhile
                pass
    return found


def sample(pid: int) -> CpuSample:
    """The counters now, for the process tree under ``pid``."""
    with open("/proc/stat") as stat:
        ticks = [int(value) for value in stat.readline().split()[1:]]
    idle = ticks[3] + ticks[4]  # idle, iowait
    used = {p: cpu_seconds(p) for p in _tree(pid)}
    return CpuSample(time.monotonic(), idle, sum(ticks[:8]), {p: s for p, s in used.items() if s is not None})


def between(first: CpuSample, last: CpuSample) -> CpuUse:
    """Average use between two samples, of the processes in both. The tree's count misses what processes that
    started or ended meanwhile used."""
    seconds = max(last.at_s - first.at_s, 1e-6)
    total = max(last.machine_total_ticks - first.machine_total_ticks, 1)
    cores = os.cpu_count() or 1
    idle_cores = cores * (last.machine_idle_ticks - first.machine_idle_ticks) / total
    used = [(cpu_s - first.process_cpu_s[pid]) / seconds for pid, cpu_s in last.process_cpu_s.items() if pid in first.process_cpu_s]
    return CpuUse(seconds, idle_cores, sum(used), max(used, default=0.0))


T = TypeVar("T")


def measured(pid: int, work: Callable[[], T]) -> tuple[T, CpuUse]:
    """``work()``'s result and the use while it ran, for the process tree under ``pid``."""
    first = sample(pid)
    result = work()
    return result, between(first, sample(pid))
