"""Simulation speed: real-time factor of the whole program at --speed max, with and without cameras.

MuJoCo and PyBullet side by side in one run. For each engine, runs the default configuration (every module of both contexts) in lockstep as fast as
possible for ``--seconds`` of simulated time, with both cameras rendered at 320x240 at 30 Hz and with
the cameras off; and times each physics step and each camera render inside those runs. PyBullet with
cameras runs three times: as it runs by default, its world drawn by MuJoCo's renderer (``cameras_on``), and
with its own CPU renderer (``--renderer pybullet``, the default before MuJoCo drew its images), with its
render worker (the top camera drawn in a process of its own; ``cameras_on_pybullet_renderer``) and without
(``cameras_on_pybullet_renderer_one_process``): before and after side by side.

Beside each real-time factor, the limit this machine allows, from the CPU the run used in the same run:
``cpu_s_per_sim_s`` (every process of the simulation, per simulated second) and
``limit_realtime_factor``, the lower of the cores over that and one over the main process's share
(the lockstep loop itself runs on one core). On a machine shared with other work the measured factor
falls below the limit; the limit says what the simulation itself allows. ``--engines`` picks engines.
Targets (issue 34): PyBullet walking with both cameras at least 1.0. Prints one JSON line.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from tafel.tools.simulation.match import cpu_seconds  # noqa: E402
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


def helper_cpu(sim: Simulation) -> float:
    """CPU seconds used so far by the simulation's helper processes (PyBullet's render worker)."""
    worker = getattr(sim.platform, "worker", None)
    return (cpu_seconds(worker.process.pid) or 0.0) if worker is not None else 0.0


def measure(engine: str, seconds: float, cameras: bool, **options: str) -> dict:
    sim = Simulation(engine, scene="default", cameras="on" if cameras else "off", resolution="320x240", **options)
    try:
        timings = instrument(sim)
        sim.run(0.5)  # warm up (first renders, first module calls)
        for values in timings.values():
            values.clear()
        cpu_main, cpu_helpers = time.process_time(), helper_cpu(sim)
        start = time.perf_counter()
        sim.run(seconds)
        wall = time.perf_counter() - start
        cpu_main, cpu_helpers = time.process_time() - cpu_main, helper_cpu(sim) - cpu_helpers
    finally:
        sim.close()
    steps = sum(timings["steps"])
    cpu = (cpu_main + cpu_helpers) / seconds
    limit = min((os.cpu_count() or 1) / cpu, seconds / cpu_main)
    result = {"realtime_factor": round(seconds / wall, 2), "limit_realtime_factor": round(limit, 2), "cpu_s_per_sim_s": round(cpu, 3),
              "cpu_s_per_sim_s_main": round(cpu_main / seconds, 3), "wall_s": round(wall, 2)}
    if steps:
        result["physics_step_us"] = round(sum(timings["advance"]) / steps * 1e6, 1)
    if timings["render"]:
        result["render_ms"] = round(statistics.fmean(timings["render"]) * 1e3, 2)
        result["renders_per_sim_s"] = round(len(timings["render"]) / seconds, 1)
    return result


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seconds", type=float, default=20.0, help="simulated seconds per run (default 20)")
    parser.add_argument("--engines", default=",".join(ENGINES), help="engines to measure, comma-separated (default: both)")
    args = parser.parse_args()
    report: dict[str, object] = {}
    for engine in args.engines.split(","):
        if engine not in ENGINES:
            parser.error(f"--engines takes {' and '.join(ENGINES)}, got {engine!r}")
        if engine == "pybullet":  # its own renderer with and without the render worker, whatever the machine's load would choose
            report[engine] = {"cameras_on": measure(engine, args.seconds, cameras=True, renderer="mujoco"),
                              "cameras_on_pybullet_renderer": measure(engine, args.seconds, cameras=True, renderer="pybullet", render_worker="on"),
                              "cameras_on_pybullet_renderer_one_process": measure(engine, args.seconds, cameras=True, renderer="pybullet",
                                                                                  render_worker="off")}
        else:
            report[engine] = {"cameras_on": measure(engine, args.seconds, cameras=True)}
        report[engine]["cameras_off"] = measure(engine, args.seconds, cameras=False)
    report["targets"] = {"mujoco": {"realtime_factor_cameras_on_min": 1.0, "realtime_factor_cameras_off_min": 10.0},
                         "pybullet": {"realtime_factor_cameras_on_min": 1.0}}
    report["cpu_count"], report["load_average_1min"] = os.cpu_count(), round(os.getloadavg()[0], 2)
    print(json.dumps(report))


if __name__ == "__main__":
    main()
