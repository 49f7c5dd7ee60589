"""``tafel scenarios run``: every scenario N times with seeded perturbations, K runs at a time.

One run is the real program on a headless simulator at full speed, in one worker process, with the
scenario's start (perturbed by the run's seed) and configuration overrides. After every tick the
success condition is checked against ground truth and the blackboards; the run ends as soon as its
outcome is known. A run's result depends on its seed alone, so 1 worker, 2 workers and Ray agree.

A run that fails runs once more with recording on, from the same seed, and keeps that log in the
artifacts folder: replay it with ``tafel run --platform log --log FILE`` or open it in ``tafel view``
or Foxglove. The rows go to a CSV or JSON Lines file; the summary gives each scenario's success rate
with its 95 % interval, and the exit status is 1 when a rate is below the scenario's requirement.
"""

from __future__ import annotations

import argparse
import csv
import hashlib
import json
import math
import sys
import tempfile
import time
from collections.abc import Sequence
from dataclasses import dataclass
from functools import partial
from pathlib import Path
from typing import Any

import numpy as np

from tafel.tools.simulation.batch import BatchError, BatchInfo, run_jobs
from tafel.tools.simulation.scenario_file import Scenario, load_scenario
from tafel.tools.simulation.scenario_predicates import PREDICATES

#: the columns of every row, in the order CSV files show them
COLUMNS = ["scenario", "run", "seed", "success", "time_to_success_s", "sim_s", "wall_s", "reason", "robot_x_mm", "robot_y_mm",
           "ball_x_mm", "ball_y_mm", "falls", "start", "ball", "sensor_noise", "log"]


@dataclass(frozen=True)
class ProgramChanges:
    """What the command line changes in every run's program: folders of one's own module files (absolute,
    ``--module-path``) and the module lists (``--add-module``, ``--remove-module``, ``CONTEXT:MODULE``)."""

    module_paths: tuple[str, ...] = ()
    add_modules: tuple[str, ...] = ()
    remove_modules: tuple[str, ...] = ()


@dataclass(frozen=True)
class Job:
    """One run: the scenario, which repetition, its seed, and where a failure's log goes (None: back to the caller)."""

    scenario: Scenario
    run: int
    seed: int
    artifacts: str | None
    keep_logs: bool = True
    changes: ProgramChanges = ProgramChanges()


@dataclass(frozen=True)
class Start:
    """A run's perturbed start: robot pose (mm, mm, rad), ball (mm), ball velocity (mm/s), noise factor."""

    robot: tuple[float, float, float]
    ball: tuple[float, float]
    ball_velocity: tuple[float, float]
    sensor_noise: float


def run_seed(base_seed: int, scenario: str, run: int) -> int:
    """The seed of run ``run`` of ``scenario``: stable across machines and Python versions."""
    digest = hashlib.sha256(f"{base_seed}/{scenario}/{run}".encode()).digest()
    return int.from_bytes(digest[:4], "little") & 0x7FFFFFFF


def perturbed_start(scenario: Scenario, seed: int) -> Start:
    rng = np.random.default_rng(seed)
    p = scenario.perturbation
    x, y, rotation = scenario.robot_start
    spread = lambda amount: float(rng.uniform(-amount, amount)) if amount else 0.0  # noqa: E731
    robot = (x + spread(p.robot_x_mm), y + spread(p.robot_y_mm), math.radians(rotation + spread(p.robot_rotation_deg)))
    ball = (scenario.ball[0] + spread(p.ball_x_mm), scenario.ball[1] + spread(p.ball_y_mm))
    velocity = (scenario.ball_velocity_mm_s[0] + spread(p.ball_velocity_mm_s), scenario.ball_velocity_mm_s[1] + spread(p.ball_velocity_mm_s))
    low, high = p.sensor_noise
    return Start(robot, ball, velocity, float(rng.uniform(low, high)) if high > low else low)


# ------------------------------------------------------------------------------------- one run
class _Truth:
    """The ``World`` the predicates see: the simulator's ground truth and the program's blackboards."""

    def __init__(self, program: Any) -> None:
        self.program, self.platform = program, program.platform

    def ball(self) -> tuple[float, float]:
        return self.platform.ball_position()

    def robot(self) -> tuple[float, float, float]:
        return self.platform.robot_pose()

    def posture(self) -> str:
        return self.platform.posture()

    def torso_height(self) -> float:
        return self.platform.torso_height()

    def representation(self, name: str, context: str) -> Any:
        return self.program.blackboard(context).get(name)


class _Judge:
    """Follows the success condition tick by tick; ``outcome`` is None while it is open."""

    def __init__(self, scenario: Scenario) -> None:
        self.scenario = scenario
        self.since: list[float | None] = [None] * len(scenario.success)
        self.met: list[float | None] = [None] * len(scenario.success)
        self.outcome: tuple[bool, str] | None = None

    def check(self, world: _Truth, now: float) -> None:
        for i, condition in enumerate(self.scenario.success):
            if self.met[i] is not None or now < condition.after_s:
                continue
            holds = PREDICATES[condition.predicate].test(world, condition.parameters)
            if condition.when == "always":
                if not holds and now <= condition.within_s:
                    self.outcome = (False, f"{condition.describe()} broke at {now:.2f} s")
                    return
                continue
            if holds:
                self.since[i] = now if self.since[i] is None else self.since[i]
                if now - self.since[i] >= condition.for_s - 1e-9:
                    self.met[i] = now
            else:
                self.since[i] = None
            if self.met[i] is None and now >= condition.within_s:
                self.outcome = (False, f"{condition.describe()} did not hold within {condition.within_s:g} s")
                return
        waiting = [i for i, c in enumerate(self.scenario.success) if c.when == "eventually" and self.met[i] is None]
        if not waiting and any(c.when == "eventually" for c in self.scenario.success):
            self.outcome = (True, "")
        elif now >= self.scenario.duration_s - 1e-9:
            self.outcome = (not waiting, "" if not waiting else f"the run ended ({self.scenario.duration_s:g} s) before "
                            + ", ".join(self.scenario.success[i].describe() for i in waiting))


def _options(scenario: Scenario, start: Start, seed: int) -> dict[str, Any]:
    return {"start": ",".join(f"{v:.6f}" for v in start.robot), "ball": f"{start.ball[0]:.3f},{start.ball[1]:.3f}",
            "ball_velocity": f"{start.ball_velocity[0]:.3f},{start.ball_velocity[1]:.3f}", "seed": seed,
            "cameras": "on" if scenario.cameras else "off", "sensor_noise": start.sensor_noise, "realism": scenario.realism}


def play(scenario: Scenario, seed: int, record: Path | None = None, changes: ProgramChanges = ProgramChanges()) -> dict[str, Any]:
    """One run of ``scenario`` from ``seed``: success, when, why not, and where things ended."""
    from tafel.tools.simulation.stepped_program import SteppedProgram

    start = perturbed_start(scenario, seed)
    began = time.perf_counter()
    program = SteppedProgram(scenario.platform, _options(scenario, start, seed), scenario.overrides, record=record,
                             add_modules=changes.add_modules, remove_modules=changes.remove_modules, module_paths=changes.module_paths)
    program.platform.tell_pose = scenario.told_pose  # told at the first cognition frame, as sim:move_robot -reset on tells it
    world, judge = _Truth(program), _Judge(scenario)
    pushes = sorted(scenario.events, key=lambda e: e.at_s)
    push = program.platform.commands()["sim:push"][1]
    falls, upright = 0, True
    try:
        while judge.outcome is None:
            while pushes and pushes[0].at_s <= program.time + 1e-9:
                event = pushes.pop(0)
                push({"x": event.force_n[0], "y": event.force_n[1]})
            program.runtime.tick()
            now = program.time
            standing = world.posture() == "upright"
            falls += upright and not standing
            upright = standing
            judge.check(world, now)
    finally:
        program.close()
    success, reason = judge.outcome
    (rx, ry, _), (bx, by) = world.robot(), world.ball()
    return {"scenario": scenario.name, "seed": seed, "success": success, "time_to_success_s": round(now, 3) if success else None,
            "sim_s": round(now, 3), "wall_s": round(time.perf_counter() - began, 3), "reason": reason,
            "robot_x_mm": round(rx, 1), "robot_y_mm": round(ry, 1), "ball_x_mm": round(bx, 1), "ball_y_mm": round(by, 1),
            "falls": falls, "start": [round(start.robot[0], 1), round(start.robot[1], 1), round(math.degrees(start.robot[2]), 2)],
            "ball": [round(v, 1) for v in start.ball], "sensor_noise": round(start.sensor_noise, 3)}


def run_job(job: Job) -> dict[str, Any]:
    """A worker's whole task: the run, and for a failure the same run again, recorded. Never raises."""
    try:
        row = {"run": job.run, **play(job.scenario, job.seed, changes=job.changes)}
    except Exception as exc:  # noqa: BLE001 - a broken run is a row that says why, not a dead batch
        return {"scenario": job.scenario.name, "run": job.run, "seed": job.seed, "success": False,
                "reason": f"error: {type(exc).__name__}: {exc}"}
    if not row["success"] and job.keep_logs:
        row.update(_failure_log(job, row))
    return row


def _failure_log(job: Job, row: dict[str, Any]) -> dict[str, Any]:
    name = f"{Path(job.scenario.path).stem}-run{job.run}-seed{job.seed}.mcap"
    folder = Path(job.artifacts) if job.artifacts is not None else Path(tempfile.mkdtemp(prefix="tafel-scenario-"))
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / name
    try:
        again = play(job.scenario, job.seed, record=path, changes=job.changes)
    except Exception as exc:  # noqa: BLE001
        return {"log": f"not recorded: {type(exc).__name__}: {exc}"}
    found: dict[str, Any] = {"log": str(path)}
    if (again["success"], again["sim_s"]) != (row["success"], row["sim_s"]):
        found["reason"] = row["reason"] + f"; the recorded run went otherwise ({again['reason'] or 'success'})"
    if job.artifacts is None:  # on a cluster without a shared folder: the log travels back with the row
        found["log_bytes"] = path.read_bytes()
        path.unlink()
        path.parent.rmdir()
        found["log"] = name
    return found


def warm_up(platforms: Sequence[str] = ("mujoco",), module_paths: Sequence[str] = ()) -> None:
    """Imports, module discovery (one's own ``module_paths`` too) and the simulators' libraries, once per
    worker, before the clock starts."""
    from tafel.core.runtime.platform import load_platform
    from tafel.tools.launch.program import discover_modules

    discover_modules(module_paths)
    for name in platforms:
        load_platform(name)


# -------------------------------------------------------------------------------------- summary
def plural(count: int, word: str) -> str:
    return f"{count} {word}" + ("" if count == 1 else "s")


def wilson_interval(successes: int, runs: int, z: float = 1.959964) -> tuple[float, float]:
    """95 % interval of a success rate (Wilson score): honest for small N and rates near 0 or 1."""
    if runs == 0:
        return 0.0, 1.0
    if successes in (0, runs):  # the exact bounds, free of rounding
        return (0.0, (z * z / runs) / (1 + z * z / runs)) if successes == 0 else (1 / (1 + z * z / runs), 1.0)
    rate = successes / runs
    centre = (rate + z * z / (2 * runs)) / (1 + z * z / runs)
    half = z * math.sqrt(rate * (1 - rate) / runs + z * z / (4 * runs * runs)) / (1 + z * z / runs)
    return max(0.0, centre - half), min(1.0, centre + half)


def summarize(scenarios: Sequence[Scenario], rows: Sequence[dict[str, Any]]) -> tuple[list[dict[str, Any]], bool]:
    """Per scenario: runs, successes, rate, interval, requirement, verdict; and whether all passed."""
    table, passed = [], True
    for scenario in scenarios:
        mine = [r for r in rows if r.get("scenario") == scenario.name]
        successes = sum(bool(r.get("success")) for r in mine)
        rate = successes / len(mine) if mine else 0.0
        low, high = wilson_interval(successes, len(mine))
        times = [r["time_to_success_s"] for r in mine if r.get("success")]
        ok = rate >= scenario.required_success_rate - 1e-12
        passed &= ok
        table.append({"scenario": scenario.name, "runs": len(mine), "successes": successes, "rate": rate, "low": low, "high": high,
                      "required": scenario.required_success_rate, "passed": ok,
                      "median_time_s": float(np.median(times)) if times else None})
    return table, passed


def print_summary(table: list[dict[str, Any]], stream: Any = None) -> None:
    stream = stream or sys.stdout
    width = max([len("scenario"), *(len(t["scenario"]) for t in table)])
    print(f"{'scenario':<{width}}  runs  success  95 % interval   required  median time  verdict", file=stream)
    for t in table:
        median = f"{t['median_time_s']:.1f} s" if t["median_time_s"] is not None else "-"
        print(f"{t['scenario']:<{width}}  {t['runs']:>4}  {t['rate']:>6.0%}   {t['low']:>5.0%} to {t['high']:<5.0%}  "
              f"{t['required']:>7.0%}  {median:>11}  {'ok' if t['passed'] else 'BELOW'}", file=stream)


def write_rows(path: Path, rows: Sequence[dict[str, Any]]) -> None:
    """CSV for a ``.csv`` name, JSON Lines otherwise (``.jsonl``)."""
    path.parent.mkdir(parents=True, exist_ok=True)
    if path.suffix.lower() == ".csv":
        with path.open("w", newline="", encoding="utf-8") as out:
            writer = csv.DictWriter(out, fieldnames=COLUMNS, extrasaction="ignore")
            writer.writeheader()
            for row in rows:
                writer.writerow({k: (json.dumps(v) if isinstance(v, list) else v) for k, v in row.items()})
        return
    with path.open("w", encoding="utf-8") as out:
        for row in rows:
            out.write(json.dumps({k: row.get(k) for k in COLUMNS}) + "\n")


# ------------------------------------------------------------------------------------ the command
def print_predicates() -> int:
    from tafel.tools.simulation.scenario_predicates import REQUIRED, TIMING

    for name, kind in PREDICATES.items():
        print(f"{name} ({kind.when}): {kind.summary}")
        for key, parameter in {**kind.parameters, **TIMING}.items():
            default = "required" if parameter.default is REQUIRED else f"default {parameter.default}"
            print(f"    {key}: {parameter.kind}, {parameter.meaning} ({default})")
    return 0


def command_scenarios(args: argparse.Namespace) -> int:
    if args.scenarios_command == "predicates":
        return print_predicates()
    if args.repeat < 1 or (args.workers is not None and args.workers < 1):
        print("tafel scenarios run: --repeat and --workers take whole numbers of 1 or more", file=sys.stderr)
        return 2
    from tafel.core.framework.errors import UnknownModuleError
    from tafel.tools.launch.program import check_module_edits, discover_modules

    changes = ProgramChanges(tuple(str(folder.resolve()) for folder in args.module_path), tuple(args.add_module), tuple(args.remove_module))
    try:
        discover_modules(changes.module_paths)  # before the files: their predicates may name one's own representations
        check_module_edits(changes.add_modules, changes.remove_modules)
        scenarios = [load_scenario(path) for path in args.files]
    except UnknownModuleError as exc:
        print(f"tafel scenarios run: {exc.args[0]}", file=sys.stderr)
        return 2
    except ValueError as exc:  # ScenarioError, ModulePathError, ConfigError
        print(f"tafel scenarios run: {exc}", file=sys.stderr)
        return 2
    names = [s.name for s in scenarios]
    if len(set(names)) != len(names):
        print(f"tafel scenarios run: two files have the same scenario name ({', '.join(sorted({n for n in names if names.count(n) > 1}))}); "
              "give each a name of its own", file=sys.stderr)
        return 2
    # Logs stay on this machine: locally in the artifacts folder; from a cluster they travel back unless it shares one.
    artifacts = args.artifacts or Path("scenario-logs")
    remote = args.ray not in (None, "local") and args.artifacts is None
    jobs = [Job(s, run, run_seed(args.seed, s.name, run), None if remote else str(artifacts.resolve()), not args.no_logs, changes)
            for s in scenarios for run in range(args.repeat)]
    print(f"{plural(len(jobs), 'run')} of {plural(len(scenarios), 'scenario')}", flush=True)
    info = BatchInfo()

    def progress(index: int, row: dict[str, Any]) -> None:
        if row.get("log_bytes") is not None:
            artifacts.mkdir(parents=True, exist_ok=True)
            (artifacts / row["log"]).write_bytes(row.pop("log_bytes"))
            row["log"] = str(artifacts / row["log"])
        verdict = "ok  " if row.get("success") else "FAIL"
        detail = f"{row['time_to_success_s']:.1f} s" if row.get("success") else row.get("reason", "")
        print(f"  {verdict} {jobs[index].scenario.name} run {jobs[index].run} (seed {jobs[index].seed}): {detail}", flush=True)

    try:
        rows = run_jobs(run_job, jobs, workers=args.workers, ray=args.ray, on_result=progress, info=info,
                        warm_up=partial(warm_up, tuple(sorted({s.platform for s in scenarios})), changes.module_paths))
    except BatchError as exc:
        print(f"tafel scenarios run: {exc}", file=sys.stderr)
        return 2
    for job, row in zip(jobs, rows):
        row.setdefault("scenario", job.scenario.name)
        row.setdefault("run", job.run)
        row.setdefault("seed", job.seed)
    write_rows(args.out, rows)
    table, passed = summarize(scenarios, rows)
    simulated = sum(r.get("sim_s") or 0.0 for r in rows)
    print(f"\n{len(rows)} runs on {info.where} with {plural(info.workers, 'worker')}: {simulated:.0f} simulated s in {info.wall_s:.1f} s "
          f"(start-up {info.startup_s:.1f} s); rows in {args.out}")
    print_summary(table)
    return 0 if passed else 1
