"""Simulation speed: real-time factor of the whole program at --speed max, with and without cameras.

MuJoCo and PyBullet side by side in one run. For each engine, runs the default configuration (every module of both contexts) in lockstep as fast as
possible for ``--seconds`` of simulated time, with both cameras rendered at 320x240 at 30 Hz and with
the cameras off; and times each physics step and each camera render inside those runs.
Prints one JSON line.
"""

from __future__ import annotations

import argparse
import json
import statistics
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from tests.support.simulation import Simulation  # noqa: E402

ENGINES = ("mujoco", "pybullet")


def instrument(sim: Simulation) -> dict[str, list[float]]:
    """Wrap the platform's stepping and rendering with timers (seconds per call)."""
    timings: dict[str, list[float]] = {"advance": [], "steps": [], "render": []}
    platform = sim.platform
    original_advance = platform.advance

    def timed_advance(time_ns: int) -> None:
        start = time.perf_counter()
        original_advance(time_ns)
        timings["advance"].append(time.perf_counter() - start)
        timings["steps"].append(platform.last_steps)

    platform.advance = timed_advance
    original_render = platform.render

    def timed_render(camera: str):
        start = time.perf_counter()
        image = original_render(camera)
        timings["render"].append(time.perf_counter() - start)
        return image

    platform.render = timed_render
    return timings


def measure(engine: str, seconds: float, cameras: bool) -> dict:
    sim = Simulation(engine, cameras="on" if cameras else "off", resolution="320x240")
    try:
        timings = instrument(sim)
        sim.run(0.5)  # warm up (first renders, first module calls)
        for values in timings.values():
            values.clear()
        start = time.perf_counter()
        sim.run(seconds)
        wall = time.perf_counter() - start
    finally:
        sim.close()
    steps = sum(timings["steps"])
    result = {"realtime_factor": round(seconds / wall, 2), "wall_s": round(wall, 2)}
    if steps:
        result["physics_step_us"] = round(sum(timings["advance"]) / steps * 1e6, 1)
    if timings["render"]:
        result["render_ms"] = round(statistics.fmean(timings["render"]) * 1e3, 2)
        result["renders_per_sim_s"] = round(len(timings["render"]) / seconds, 1)
    return result


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seconds", type=float, default=20.0, help="simulated seconds per run (default 20)")
    args = parser.parse_args()
    report = {}
    for engine in ENGINES:
        report[engine] = {
            "cameras_on": measure(engine, args.seconds, cameras=True),
            "cameras_off": measure(engine, args.seconds, cameras=False),
        }
    report["targets"] = {"mujoco": {"realtime_factor_cameras_on_min": 1.0, "realtime_factor_cameras_off_min": 10.0}}
    print(json.dumps(report))


if __name__ == "__main__":
    main()
