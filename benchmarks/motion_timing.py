"""Motion timing under a Python-heavy cognition: the concurrent runtime against threads in one process.

Motion runs its modules at 100 Hz on the dummy platform while cognition runs its modules plus
``PythonHeavyLoad`` (20 ms of pure-Python work per frame) at 30 Hz. The same context loop runs twice in
one benchmark run: in the concurrent runtime (one process per context, motion asking for SCHED_FIFO)
and as two threads of this process (the naive baseline, same SCHED_FIFO request for its motion thread).
Motion period error is the lateness of each frame's start against its absolute deadline. As a floor,
the same run also times a bare 100 Hz sleep loop with nothing else running: no runtime can beat what
the machine gives an idle loop. A third variant keeps the black box on (every representation of both
contexts, as on the robot) to show what it costs motion. Prints one JSON line.
"""

from __future__ import annotations

import argparse
import json
import os
import tempfile
import threading
from pathlib import Path

from tafel.core.framework.config import load_config
from tafel.core.logs.blackbox import BlackBox
from tafel.core.logs.recording import select
from tafel.core.runtime import ConcurrentRuntime, ContextRunner, Limits, StopFlag, cognition_watcher, run_context_loop, try_realtime
from tafel.core.runtime.handover import LocalChannel
from tafel.core.runtime.program import plan_program
from tafel.platforms.dummy import DummyPlatform
from tafel.tools.launch.defaults import DEFAULT_CONFIG
from tafel.tools.launch.program import discover_modules


def plans(load_ms: float):
    discover_modules()
    import loads  # noqa: F401 - registers PythonHeavyLoad

    config = load_config(DEFAULT_CONFIG, "dummy", overrides=[
        'cognition.modules=["KalmanBallModeler", "SimpleBallModeler", "LookAtBallBehavior", "Striker", "loads:PythonHeavyLoad"]',
        f"parameters.PythonHeavyLoad.milliseconds={load_ms}",
    ])
    return plan_program(config, DummyPlatform)


def summarize(stats) -> dict:
    timing = stats.period_error_percentiles()
    return {
        "p50_ms": round(timing["p50_ms"], 3),
        "p99_ms": round(timing["p99_ms"], 3),
        "max_ms": round(timing["max_ms"], 3),
        "missed_periods": stats.missed_periods,
        "motion_frames": stats.frames,
        "motion_rate_hz": round(stats.rate_hz, 2),
    }


def run_concurrent(frames: int, load_ms: float, blackbox: bool = False) -> tuple[dict, dict, str]:
    """The concurrent runtime; with ``blackbox``, every representation of both contexts also goes into a
    black box (as on the robot), to measure what keeping it costs motion."""
    program = plans(load_ms)
    box = BlackBox(Path(tempfile.mkdtemp()), seconds=20.0) if blackbox else None
    record = {}
    for selection in select(program, ["all"]) if blackbox else []:
        record.setdefault(selection.context, []).append(selection)
    runtime = ConcurrentRuntime(program, DummyPlatform, {}, blackbox=box, blackbox_record=record)
    stats = runtime.run(Limits(frames=frames, speed=1.0))
    extra = {"cognition_rate_hz": round(stats["cognition"].rate_hz, 2)}
    if box is not None:
        extra.update(blackbox_mb=round(box.bytes / 1e6, 2), blackbox_messages=len(box.ring))
    return summarize(stats["motion"]), extra, stats["motion"].realtime


def run_threads(frames: int, load_ms: float) -> tuple[dict, dict]:
    program = plans(load_ms)
    platform_motion, platform_cognition = DummyPlatform(), DummyPlatform()
    platform_motion.start(frozenset({"motion"}))
    platform_cognition.start(frozenset({"cognition"}))
    to_motion, to_cognition = LocalChannel(), LocalChannel()
    motion = ContextRunner(program["motion"], program["motion"].build_manager(), platform_motion, inbox=to_motion, outbox=to_cognition)
    cognition = ContextRunner(program["cognition"], program["cognition"].build_manager(), platform_cognition, inbox=to_cognition, outbox=to_motion)
    stop = StopFlag()
    results = {}

    def motion_thread() -> None:
        realtime = try_realtime(50)
        results["motion"] = run_context_loop(motion, Limits(frames=frames), stop, is_main=True, report=lambda s: None,
                                             cognition_watch=cognition_watcher(to_motion, 1.0), realtime=realtime)
        stop.set()

    def cognition_thread() -> None:
        results["cognition"] = run_context_loop(cognition, Limits(), stop, is_main=False, report=lambda s: None)

    threads = [threading.Thread(target=motion_thread), threading.Thread(target=cognition_thread)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    return summarize(results["motion"]), {"cognition_rate_hz": round(results["cognition"].rate_hz, 2)}


def run_bare_floor(frames: int) -> dict:
    """The machine's floor: a bare 100 Hz sleep loop with nothing else running (same SCHED_FIFO request)."""
    import time

    from tafel.core.runtime import ContextStats

    try_realtime(50)
    stats = ContextStats(name="floor")
    period = 10_000_000
    deadline = time.monotonic_ns()
    start = deadline
    for _ in range(frames):
        now = time.monotonic_ns()
        if now < deadline:
            time.sleep((deadline - now) * 1e-9)
            now = time.monotonic_ns()
        stats.period_errors.add((now - deadline) / 1e6)
        stats.frames += 1
        deadline += period
        while deadline < now - period:
            deadline += period
            stats.missed_periods += 1
    stats.wall_s = (time.monotonic_ns() - start) * 1e-9
    try:
        os.sched_setscheduler(0, os.SCHED_OTHER, os.sched_param(0))
    except OSError:
        pass
    return summarize(stats)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seconds", type=float, default=10.0, help="motion run time per variant (default 10)")
    parser.add_argument("--load-ms", type=float, default=20.0, help="pure-Python work per cognition frame")
    args = parser.parse_args()
    frames = int(args.seconds * 100)
    concurrent, concurrent_cognition, realtime = run_concurrent(frames, args.load_ms)
    with_box, with_box_cognition, _ = run_concurrent(frames, args.load_ms, blackbox=True)
    threads, threads_cognition = run_threads(frames, args.load_ms)
    floor = run_bare_floor(frames)
    print(json.dumps({
        "seconds": args.seconds,
        "cognition_load_ms_per_frame": args.load_ms,
        "runtime": {**concurrent, **concurrent_cognition},
        "runtime_with_blackbox": {**with_box, **with_box_cognition},
        "threads_baseline": {**threads, **threads_cognition},
        "bare_sleep_loop_floor": floor,
        "realtime": realtime,
        "target_p99_ms": 1.0,
    }))


if __name__ == "__main__":
    main()
