"""Scenario throughput: simulated seconds per wall second with 1 local worker, 2 local workers and Ray
with 2 CPUs, all in one run, and each one's scaling efficiency against one worker.

The same runs every time (``benchmarks/scenarios/throughput.toml``, ``--runs`` seeded runs of 8 s of
the striker walking with both cameras rendered), so the three measure the same work. Start-up (worker
processes, imports, Ray's own start) is timed apart and left out of the rates, as the issue asks; it
is reported on its own. Prints one JSON line.
"""

from __future__ import annotations

import argparse
import json
import sys
from functools import partial
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from tafel.tools.simulation.batch import BatchInfo, run_jobs  # noqa: E402
from tafel.tools.simulation.scenario_file import load_scenario  # noqa: E402
from tafel.tools.simulation.scenarios import Job, run_job, run_seed, warm_up  # noqa: E402

SCENARIO = Path(__file__).resolve().parent / "scenarios" / "throughput.toml"


def measure(jobs: list[Job], workers: int, ray: str | None) -> dict:
    info = BatchInfo()
    rows = run_jobs(run_job, jobs, workers=workers, ray=ray, warm_up=partial(warm_up, ("mujoco",)), info=info)
    failed = [r for r in rows if str(r.get("reason", "")).startswith("error")]
    if failed:
        raise SystemExit(f"runs failed: {failed[0]['reason']}")
    simulated = sum(r["sim_s"] for r in rows)
    return {"simulated_s": round(simulated, 1), "wall_s": round(info.wall_s, 2), "startup_s": round(info.startup_s, 2),
            "sim_s_per_wall_s": round(simulated / info.wall_s, 3), "rows": [(r["seed"], r["sim_s"], r["falls"]) for r in rows]}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=8, help="runs per measurement (default 8)")
    args = parser.parse_args()
    scenario = load_scenario(SCENARIO)
    jobs = [Job(scenario, run, run_seed(0, scenario.name, run), None, keep_logs=False) for run in range(args.runs)]
    report: dict = {"benchmark": "scenarios", "runs": args.runs, "run_s": scenario.duration_s}
    report["one_worker"] = measure(jobs, 1, None)
    report["two_workers"] = measure(jobs, 2, None)
    try:
        import ray  # noqa: F401

        report["ray_two_cpus"] = measure(jobs, 2, "local")
    except ImportError:
        report["ray_two_cpus"] = "not measured: pip install -e '.[ray]'"
    base = report["one_worker"]["sim_s_per_wall_s"]
    for key in ("two_workers", "ray_two_cpus"):
        if isinstance(report[key], dict):
            report[key]["speedup"] = round(report[key]["sim_s_per_wall_s"] / base, 3)
            report[key]["efficiency"] = round(report[key]["speedup"] / 2, 3)
            report[key]["same_rows_as_one_worker"] = report[key]["rows"] == report["one_worker"]["rows"]
    for key in ("one_worker", "two_workers", "ray_two_cpus"):
        if isinstance(report[key], dict):
            del report[key]["rows"]
    report["targets"] = {"two_workers_speedup": 1.7, "ray_two_cpus_speedup": 1.5}
    print(json.dumps(report))


if __name__ == "__main__":
    main()
