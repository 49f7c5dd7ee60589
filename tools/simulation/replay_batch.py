"""``tafel replay-batch``: replay many logs with a changed configuration or module, and say what changed.

Every log is replayed as ``tafel run --platform log`` would (sensor data fed as recorded, the modules
run again, ``--replace`` feeds recorded representations instead of their providers) with the
``--set``, ``--add-module`` and ``--remove-module`` changes (modules of one's own from ``--module-path``
folders), recording what the original holds. With
``--compare`` each replay is compared with its original as ``tafel log compare`` does: channels that
differ, the first differing frame and field. ``--metric Rep.field`` adds that field's mean over the
frames of the original and of the replay. One CSV row per log, a summary on the console; the runs go
to worker processes or Ray tasks like scenario runs.
"""

from __future__ import annotations

import argparse
import csv
import glob
import math
import sys
import tempfile
import time
from collections.abc import Sequence
from dataclasses import dataclass
from functools import partial
from pathlib import Path
from typing import Any

from tafel.core.framework.errors import UnknownModuleError
from tafel.core.framework.naming import did_you_mean
from tafel.core.logs import LogError, LogReader
from tafel.tools.launch.program import check_module_edits, discover_modules
from tafel.tools.logs.decoding import decoded_messages
from tafel.tools.logs.log_compare import compare_logs
from tafel.tools.simulation.batch import BatchError, BatchInfo, run_jobs
from tafel.tools.simulation.scenarios import plural, warm_up


@dataclass(frozen=True)
class ReplayJob:
    """One log to replay, the changes, and what to report."""

    log: str
    overrides: tuple[str, ...]
    replace: str
    add_modules: tuple[str, ...]
    remove_modules: tuple[str, ...]
    compare: bool
    metrics: tuple[str, ...]
    #: where the replayed log is kept (None: it is thrown away after the comparison)
    keep_in: str | None
    #: folders of one's own module files (absolute), imported in every worker
    module_paths: tuple[str, ...] = ()


def expand(patterns: Sequence[str]) -> list[Path]:
    """Files named by paths and globs (``logs/*.mcap``, ``games/**/*.mcap``), each once, in order; a
    pattern that names nothing is a ``ValueError`` that says which."""
    found: list[Path] = []
    for pattern in patterns:
        matches = sorted(glob.glob(pattern, recursive=True)) if glob.has_magic(pattern) else ([pattern] if Path(pattern).is_file() else [])
        matches = [m for m in matches if Path(m).is_file()]
        if not matches:
            raise ValueError(f"{pattern}: no such log" + (" (the pattern matches no file)" if glob.has_magic(pattern) else ""))
        found += [Path(m) for m in matches if Path(m) not in found]
    return found


def metric_means(path: Path, metrics: Sequence[str]) -> dict[str, float | None]:
    """``Rep.field`` -> the mean of that field over the log's frames (booleans count as 0 and 1)."""
    means: dict[str, float | None] = {}
    with LogReader(path) as reader:
        held = {c.representation for c in reader.channels.values()}
        for metric in metrics:
            rep, _, name = metric.partition(".")
            values = []
            for _topic, _sequence, _time, fields in (decoded_messages(reader, rep, None) if rep in held else ()):
                value: Any = fields
                for part in name.split("."):
                    value = value.get(part) if isinstance(value, dict) else None
                if isinstance(value, (bool, int, float)) and math.isfinite(float(value)):
                    values.append(float(value))
            means[metric] = sum(values) / len(values) if values else None
    return means


def check_metrics(metrics: Sequence[str], logs: Sequence[Path]) -> None:
    """Every ``REP.FIELD`` names a representation some log holds and a field it has; ``ValueError`` otherwise
    (the modules, one's own too, are discovered before)."""
    from tafel.core.framework.representation import fields_of, get_representation

    if not metrics:
        return
    held: set[str] = set()
    for log in logs:
        try:
            with LogReader(log) as reader:
                held |= {c.representation for c in reader.channels.values()}
        except LogError:
            continue  # its row will say what is wrong with it
    for metric in metrics:
        rep, _, name = metric.partition(".")
        if rep not in held:
            raise ValueError(f"--metric {metric}: no log holds {rep!r}; {did_you_mean(rep, held)}")
        fields = [info.name for info in fields_of(get_representation(rep))]
        if name.split(".")[0] not in fields:
            raise ValueError(f"--metric {metric}: {rep} has no field {name.split('.')[0]!r}; {did_you_mean(name.split('.')[0], fields)}")


def replay_log(job: ReplayJob) -> dict[str, Any]:
    """A worker's task: replay one log, record, compare, measure. Never raises: errors are rows."""
    from tafel.tools.simulation.stepped_program import SteppedProgram

    row: dict[str, Any] = {"log": job.log}
    began = time.perf_counter()
    folder = Path(job.keep_in) if job.keep_in else Path(tempfile.mkdtemp(prefix="tafel-replay-"))
    folder.mkdir(parents=True, exist_ok=True)
    replayed = folder / (Path(job.log).stem + ".replay.mcap")
    try:
        with LogReader(job.log) as original:
            # the program's own channels, not the Foxglove channels made from them
            recorded = sorted({c.representation for c in original.channels.values() if c.context in ("cognition", "motion")})
        program = SteppedProgram("log", {"log": job.log, "replace": job.replace}, job.overrides, record=replayed, record_reps=recorded,
                                 add_modules=job.add_modules, remove_modules=job.remove_modules, module_paths=job.module_paths)
        row["ended"] = program.run_to_end()
        row["frames"] = {name: runner.frames for name, runner in program.runtime.runners.items()}
        if job.compare:
            with LogReader(job.log) as first, LogReader(replayed) as second:
                differences = compare_logs(first, second)
            differing = [d for d in differences.values() if d.differs]
            row.update(channels=len(differences), channels_differing=len(differing),
                       differing=" ".join(d.topic for d in differing))
            if differing:
                first_difference = min(differing, key=lambda d: (d.first_frame is None, d.first_frame or 0))
                path, a, b = first_difference.fields[0] if first_difference.fields else ("", "", "")
                row["first_difference"] = f"{first_difference.topic} frame {first_difference.first_frame}: {path} {a!r} -> {b!r}"
        for metric, mean in metric_means(Path(job.log), job.metrics).items():
            row[f"{metric} recorded"] = mean
        for metric, mean in metric_means(replayed, job.metrics).items():
            row[f"{metric} replayed"] = mean
        row["status"] = "ok"
    except Exception as exc:  # noqa: BLE001 - one bad log is a row that says why, the batch goes on
        row.update(status="error", error=f"{type(exc).__name__}: {exc}")
    finally:
        if job.keep_in is None:
            replayed.unlink(missing_ok=True)
            folder.rmdir()
        else:
            row["replay"] = str(replayed)
    row["wall_s"] = round(time.perf_counter() - began, 3)
    return row


# ------------------------------------------------------------------------------------ the command
COLUMNS = ["log", "status", "ended", "frames", "channels", "channels_differing", "first_difference", "differing", "wall_s", "replay", "error"]


def command_replay_batch(args: argparse.Namespace) -> int:
    if args.workers is not None and args.workers < 1:
        print("tafel replay-batch: --workers takes a whole number of 1 or more", file=sys.stderr)
        return 2
    bad = [m for m in args.metric if "." not in m.strip(".")]
    if bad:
        print(f"tafel replay-batch: --metric takes REPRESENTATION.FIELD (a representation the logs hold and one of its fields); got {bad[0]!r}", file=sys.stderr)
        return 2
    module_paths = tuple(str(folder.resolve()) for folder in args.module_path)
    try:
        logs = expand(args.logs)
        discover_modules(module_paths)  # a folder that cannot be imported is refused here, before any worker starts
        check_module_edits(args.add_module, args.remove_module, "log")
        check_metrics(args.metric, logs)
    except UnknownModuleError as exc:
        print(f"tafel replay-batch: {exc.args[0]}", file=sys.stderr)
        return 2
    except (ValueError, LogError) as exc:
        print(f"tafel replay-batch: {exc}", file=sys.stderr)
        return 2
    keep = str(args.artifacts.resolve()) if args.artifacts is not None else None
    jobs = [ReplayJob(str(log.resolve()), tuple(args.overrides), args.replace, tuple(args.add_module), tuple(args.remove_module),
                      args.compare, tuple(args.metric), keep, module_paths) for log in logs]
    print(f"replaying {plural(len(jobs), 'log')}", flush=True)

    def progress(index: int, row: dict[str, Any]) -> None:
        if row.get("status") != "ok":
            print(f"  ERROR   {logs[index]}: {row.get('error') or row.get('reason')}", flush=True)
        elif args.compare:
            verdict = f"{row['channels_differing']} of {row['channels']} channels differ" if row["channels_differing"] else "no difference"
            print(f"  {'DIFFERS' if row['channels_differing'] else 'same   '} {logs[index]}: {verdict}", flush=True)
        else:
            print(f"  done    {logs[index]}", flush=True)

    info = BatchInfo()
    try:
        rows = run_jobs(replay_log, jobs, workers=args.workers, ray=args.ray, on_result=progress, warm_up=partial(warm_up, ("log",), module_paths), info=info)
    except BatchError as exc:
        print(f"tafel replay-batch: {exc}", file=sys.stderr)
        return 2
    write_csv(args.out, rows, args.metric)
    return print_replay_summary(rows, args, info)


def write_csv(path: Path, rows: Sequence[dict[str, Any]], metrics: Sequence[str]) -> None:
    columns = COLUMNS + [f"{m} {side}" for m in metrics for side in ("recorded", "replayed")]
    path.parent.mkdir(parents=True, exist_ok=True)
    with path.open("w", newline="", encoding="utf-8") as out:
        writer = csv.DictWriter(out, fieldnames=columns, extrasaction="ignore")
        writer.writeheader()
        for row in rows:
            writer.writerow({k: (" ".join(f"{c}={n}" for c, n in v.items()) if isinstance(v, dict) else v) for k, v in row.items()})


def print_replay_summary(rows: Sequence[dict[str, Any]], args: argparse.Namespace, info: BatchInfo) -> int:
    ok = [r for r in rows if r.get("status") == "ok"]
    errors = len(rows) - len(ok)
    print(f"\n{plural(len(rows), 'log')} replayed on {info.where} with {plural(info.workers, 'worker')} in {info.wall_s:.1f} s; rows in {args.out}")
    if errors:
        print(f"{errors} could not be replayed (see the error column)")
    differing = [r for r in ok if r.get("channels_differing")]
    if args.compare:
        print(f"{len(differing)} of {len(ok)} logs differ from their recorded outputs")
        for row in differing:
            print(f"  {row['log']}: {row['first_difference']}")
    for metric in args.metric:
        recorded = [r[f"{metric} recorded"] for r in ok if r.get(f"{metric} recorded") is not None]
        replayed = [r[f"{metric} replayed"] for r in ok if r.get(f"{metric} replayed") is not None]
        if recorded and replayed:
            print(f"{metric}: mean {sum(recorded) / len(recorded):.4g} recorded, {sum(replayed) / len(replayed):.4g} replayed")
        else:
            print(f"{metric}: no such field in the logs (tafel log info lists what they hold)")
    if errors:
        return 2
    return 1 if differing else 0
