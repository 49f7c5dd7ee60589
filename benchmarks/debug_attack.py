"""Loop rates of the default simulation (MuJoCo, both cameras, speed 1) without and during the attack.

The attack is the security issues': 20 clients pipelining commands, one streaming 50 MB without
newlines, 40 connections over the limit of 32, an HTTP POST, one with a request line over 64 KiB, a page
of another site and a DNS-rebinding host at the Foxglove server, and two log bombs read beside it. Rates are the program's own, from its
status line (one a second); the baseline is measured in the same run, just before the attack. Beside them, the
CPU the program used (all its processes, and its busiest one: a process's loops share one interpreter) and the
cores the machine left idle: where the program's busiest process used most of its core before the attack, or the
attack's clients and log readers on the same machine left none idle, slower rates are the machine's, not the attack's.

    python benchmarks/debug_attack.py [--seconds 10]

Prints one JSON line.
"""

from __future__ import annotations

import argparse
import json
import os
import re
import statistics
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(REPO))

from tests.support import cpu_use  # noqa: E402
from tests.support.attack import Attack, status_rates  # noqa: E402
from tests.support.mcap_files import cpu_bomb, memory_bomb  # noqa: E402
from tests.support.ssh_server import free_port  # noqa: E402


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--seconds", type=float, default=10.0, help="length of each phase (without, during)")
    args = parser.parse_args()
    folder = Path(tempfile.mkdtemp(prefix="tafel-attack-"))
    victim = folder / "victim.txt"
    victim.write_text("precious\n")
    bombs = Path(tempfile.mkdtemp(prefix="tafel-bombs-"))
    foxglove_port = free_port()
    process = subprocess.Popen(
        [sys.executable, "-m", "tafel.tools.cli", "run", "--platform", "mujoco", "--debug-port", "0", "--status-interval", "1",
         "--foxglove", f"127.0.0.1:{foxglove_port}"],
        cwd=folder, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env={**os.environ, "PYTHONPATH": str(REPO)})
    port = int(re.search(r":(\d+)", process.stdout.readline()).group(1))
    lines: list[str] = []
    threading.Thread(target=lambda: lines.extend(process.stderr), daemon=True).start()
    threading.Thread(target=lambda: [None for _ in process.stdout], daemon=True).start()

    def phase_rates() -> dict[str, list[float]]:
        """The status lines' rates over the next ``args.seconds`` (the first line's interval began before)."""
        start = len(lines)
        time.sleep(args.seconds)
        return status_rates(lines[start + 1:])
    try:
        time.sleep(3.0)  # stand up, first images
        without, use_without = cpu_use.measured(process.pid, phase_rates)
        attack = Attack("127.0.0.1", port, http_victim=str(victim), foxglove_port=foxglove_port,
                        bombs=[memory_bomb(bombs / "memory.mcap"), cpu_bomb(bombs / "cpu.mcap")])
        started = time.perf_counter()
        attack.start()
        during, use_during = cpu_use.measured(process.pid, phase_rates)
        report = attack.stop()
        attack_s = time.perf_counter() - started
    finally:
        process.terminate()
        process.wait(timeout=30)

    def summary(rates: dict[str, list[float]]) -> dict[str, float]:
        return {f"{name}_{what}_hz": round(func(values), 2) for name, values in rates.items() if values
                for what, func in (("mean", statistics.fmean), ("min", min))}

    def cores(use: cpu_use.CpuUse) -> dict[str, float]:
        return {"program_cores": round(use.tree_cores, 2), "busiest_process_cores": round(use.busiest_process_cores, 2),
                "machine_idle_cores": round(use.machine_idle_cores, 2)}

    print(json.dumps({
        "benchmark": "debug_attack", "platform": "mujoco", "speed": 1, "phase_s": args.seconds,
        "without_attack": summary(without) | cores(use_without), "during_attack": summary(during) | cores(use_during),
        "targets": {"motion_min_hz": 95.0, "cognition_min_hz": 28.0},
        "attack": {"pipelined_answers": report.answers, "answers_per_s": round(report.answers / attack_s),
                   "streamed_mb": round(report.streamed_bytes / 2**20, 1), "refused_over_limit": report.refused,
                   "over_limit_left_open": report.over_limit_open, "http_post_answered": report.http_answered,
                   "long_http_post_answered": report.long_http_answered, "foxglove_foreign_pages": report.foxglove,
                   "log_bombs_exit_and_peak_mb": [[code, round(mb, 1)] for code, mb in report.bombs],
                   "client_errors": report.errors[:3]},
        "victim_unchanged": victim.read_text() == "precious\n",
        "files_in_working_folder": sorted(p.name for p in folder.iterdir()),
    }))


if __name__ == "__main__":
    main()
