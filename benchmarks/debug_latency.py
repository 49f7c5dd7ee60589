"""Debug server latency and its effect on the loops.

Starts ``tafel run`` (dummy platform, paced to the wall clock) and measures over real sockets:
1. round trips of ``ping`` and ``representation:print BallModel`` from one client, p50 and p99;
2. the loops' achieved rates (frames per wall second, as the program measures them) when idle, and
   while 20 clients each keep pipelining batches of commands, with the round trips of a 21st client.
Done for the default program (MuJoCo, lockstep), and on the dummy platform for the lockstep and the
concurrent runtime. Prints one JSON line.
"""

from __future__ import annotations

import json
import os
import re
import statistics
import subprocess
import sys
import threading
import time
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(REPO))

from tafel.debug.client import DebugClient  # noqa: E402

HAMMER_SECONDS = 5.0
CLIENTS = 20


def start(*args: str) -> tuple[subprocess.Popen, int]:
    process = subprocess.Popen([sys.executable, "-m", "tafel.tools.cli", "run", "--debug-port", "0", "--status-interval", "3600", *args],
                               cwd=REPO, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True,
                               env={**os.environ, "PYTHONPATH": str(REPO)})
    line = process.stdout.readline()
    match = re.search(r"listening on [\d.]+:(\d+)", line)
    if not match:
        process.kill()
        raise RuntimeError(f"tafel run did not start its debug server: {line!r}")
    threading.Thread(target=lambda: [None for _ in process.stdout], daemon=True).start()
    return process, int(match.group(1))


def percentiles(samples_ms: list[float]) -> dict[str, float]:
    ordered = sorted(samples_ms)
    return {"p50_ms": round(statistics.median(ordered), 3), "p99_ms": round(ordered[int(0.99 * (len(ordered) - 1))], 3)}


def round_trips(client: DebugClient, command: str, count: int) -> list[float]:
    samples = []
    for _ in range(count):
        start_ = time.perf_counter()
        client.ask(command)
        samples.append((time.perf_counter() - start_) * 1e3)
    return samples


def loop_rates(client: DebugClient) -> dict[str, float]:
    """Frames per wall second over the last two seconds, as the program measures them itself.

    Measured inside the program when the command runs, so queueing delays of the answer do not
    distort it (frame numbers read from outside would be).
    """
    answer = client.ask("stopwatch:list")
    return {context: float(hz) for context, hz in re.findall(r"\[(\w+)\]\nloop: ([\d.]+) Hz", answer)}


def sampled_rates(client: DebugClient, seconds: float) -> dict[str, float]:
    """Mean of the program's own rate readings, taken every half second for ``seconds``."""
    samples: dict[str, list[float]] = {}
    end = time.perf_counter() + seconds
    while time.perf_counter() < end:
        time.sleep(0.5)
        for context, hz in loop_rates(client).items():
            samples.setdefault(context, []).append(hz)
    return {context: round(statistics.fmean(values), 2) for context, values in samples.items()}


def measure(*args: str) -> dict:
    process, port = start(*args)
    try:
        time.sleep(1.5)  # let both loops settle
        with DebugClient(port=port) as client:
            ping = round_trips(client, "ping", 500)
            printed = round_trips(client, "representation:print BallModel", 500)
            time.sleep(2.0)  # the rate window covers idle time only
            idle_rates = sampled_rates(client, 3.0)
            stop = threading.Event()
            answered = [0] * CLIENTS
            batch = ["ping", "representation:print BallModel", "stopwatch:list", "modules:list"] * 25

            def hammer(index: int) -> None:
                with DebugClient(port=port, timeout=60) as own:
                    while not stop.is_set():
                        answered[index] += len(own.ask_many(batch))

            threads = [threading.Thread(target=hammer, args=(i,), daemon=True) for i in range(CLIENTS)]
            for thread in threads:
                thread.start()
            time.sleep(2.0)  # the rate window covers loaded time only
            loaded_start = time.perf_counter()
            loaded_ping = round_trips(client, "ping", 100)
            loaded_print = round_trips(client, "representation:print BallModel", 20)
            loaded_rates = sampled_rates(client, HAMMER_SECONDS)
            elapsed = time.perf_counter() - loaded_start
            stop.set()
            for thread in threads:
                thread.join(timeout=60)
        return {
            "ping": percentiles(ping),
            "representation_print": percentiles(printed),
            "rates_idle_hz": idle_rates,
            "rates_under_20_clients_hz": loaded_rates,
            "ping_under_20_clients": percentiles(loaded_ping),
            "representation_print_under_20_clients": percentiles(loaded_print),
            "commands_answered_per_s_under_load": round(sum(answered) / elapsed, 1),
        }
    finally:
        process.terminate()
        process.wait(timeout=30)


def main() -> None:
    print(json.dumps({
        "lockstep_mujoco": measure("--platform", "mujoco"),  # the default program
        "lockstep_dummy": measure("--platform", "dummy"),
        "concurrent_dummy": measure("--platform", "dummy", "--concurrent"),
        "frame_periods_ms": {"motion": 10.0, "cognition": 33.3},
    }))


if __name__ == "__main__":
    main()
