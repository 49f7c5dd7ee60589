"""A batch's pool workers (tafel scenarios run, tafel replay-batch) end with their parent, whatever
ends it: before, a SIGTERM or SIGKILL of the parent left two workers at 55 % CPU each."""

from __future__ import annotations

import os
import signal
import subprocess
import time

import pytest

from tests.test_cli_runtime import REPO, TAFEL, alive, child_pids, cmdline


def pool_workers(pid: int) -> list[int]:
    return [child for child in child_pids(pid) if "spawn_main" in cmdline(child) and "resource_tracker" not in cmdline(child)]


@pytest.mark.slow
@pytest.mark.parametrize("signum", [signal.SIGTERM, signal.SIGKILL])
def test_scenario_workers_end_with_their_parent(signum: int) -> None:
    process = subprocess.Popen([*TAFEL, "scenarios", "run", "config/scenarios/walk_to_ball.toml", "--repeat", "4", "--workers", "2",
                                "--no-logs"], cwd=REPO, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                               env={**os.environ, "PYTHONPATH": str(REPO), "MUJOCO_GL": "egl"})
    try:
        deadline = time.monotonic() + 60
        workers: list[int] = []
        while len(workers) < 2 and time.monotonic() < deadline:
            time.sleep(0.2)
            workers = pool_workers(process.pid)
        assert len(workers) == 2, "the batch never started its two workers"
        time.sleep(1.0)  # the workers are running their jobs now
        os.kill(process.pid, signum)
        process.wait(timeout=30)
        deadline = time.monotonic() + 10
        while [pid for pid in workers if alive(pid)] and time.monotonic() < deadline:
            time.sleep(0.1)
        assert not [(pid, cmdline(pid)) for pid in workers if alive(pid)]
    finally:
        if process.poll() is None:
            process.kill()
