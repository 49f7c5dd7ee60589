"""Start-up time of the command line: ``tafel --help``, ``tafel console -c help`` and ``tafel log info``.

Each command runs as a fresh process (as a user types it), beside ``python -c pass`` as the baseline,
alternately in one run; the medians of several repetitions are reported in seconds of wall time. The
console asks a port nobody listens on, so it fails at once: what is left is the start-up. The page
cache is warm after the first repetition: a cold start (after a reboot) takes longer, by how much more
has to be read, which is what importing only what a command uses keeps small.
Prints one JSON line.
"""

from __future__ import annotations

import json
import os
import socket
import statistics
import subprocess
import sys
import time
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
SMALL_LOG = REPO / "tests" / "data" / "ball_situation.mcap"
REPEATS = 7


def unused_port() -> int:
    """A port that was free a moment ago and that nobody listens on now."""
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return int(probe.getsockname()[1])


def wall_time(argv: list[str]) -> float:
    started = time.perf_counter()
    subprocess.run(argv, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, cwd=REPO,
                   env={**os.environ, "PYTHONPATH": str(REPO)}, timeout=120)
    return time.perf_counter() - started


def main() -> None:
    tafel = [sys.executable, "-m", "tafel.tools.cli"]
    commands = {
        "python_pass_s": [sys.executable, "-c", "pass"],
        "help_s": [*tafel, "--help"],
        "console_s": [*tafel, "console", "--port", str(unused_port()), "-c", "help"],
        "log_info_s": [*tafel, "log", "info", str(SMALL_LOG)],
    }
    times: dict[str, list[float]] = {name: [] for name in commands}
    for _ in range(REPEATS):
        for name, argv in commands.items():
            times[name].append(wall_time(argv))
    result = {name: round(statistics.median(values), 4) for name, values in times.items()}
    result["repeats"] = REPEATS
    print(json.dumps(result))


if __name__ == "__main__":
    main()
