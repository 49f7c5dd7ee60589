"""Recording cost, replay speed, and automatic against hand-built protobuf serialization.

1. Records a synthetic run of 10,000 motion frames (3,000 cognition frames, no images) on the dummy
   platform with the default selection (all sensor data plus the main percepts and models), timing the
   recorder's work on the loop (serializing and queueing) per frame.
2. Replays the log through both contexts at --speed max: frames per second and real-time factor.
3. Serializes representations automatically and with hand-written code that builds the same protobuf
   message field by field, and compares the times per message.
4. Long logs: records the default MuJoCo program with both cameras at 320x240 for 1 and for 10
   simulated minutes (``--long-minutes``), then runs ``tafel log info`` and a full replay of each as
   separate processes and reports their peak resident memory next to the file sizes. Memory must not
   grow with the length of the log. ``--keep DIR`` keeps (and reuses) the recordings.
Prints one JSON line.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
import timeit
from pathlib import Path

import numpy as np

from tafel.core.framework.config import load_config
from tafel.core.logs.recording import Recorder, select
from tafel.core.logs.serialization import codec, serialize
from tafel.core.runtime import Limits, LockstepRuntime
from tafel.core.runtime.program import plan_program
from tafel.platforms.dummy import DummyPlatform
from tafel.platforms.log import LogPlatform
from tafel.representations.infrastructure import FrameInfo
from tafel.representations.modeling import BallModel
from tafel.representations.motion import InertialSensorData, JointSensorData
from tafel.tools.launch.defaults import DEFAULT_CONFIG
from tafel.tools.launch.program import discover_modules

MOTION_FRAMES = 10_000


class TimedRecorder(Recorder):
    """Measures what recording costs the loop: serializing and queueing each frame."""

    def __init__(self, *args, **kwargs) -> None:
        super().__init__(*args, **kwargs)
        self.seconds = 0.0
        self.calls = 0

    def record(self, context, blackboard, frame_number, time_ns) -> None:
        start = time.perf_counter()
        super().record(context, blackboard, frame_number, time_ns)
        self.seconds += time.perf_counter() - start
        self.calls += 1


def record(path: Path) -> dict:
    config = load_config(DEFAULT_CONFIG, "dummy")
    plans = plan_program(config, DummyPlatform)
    recorder = TimedRecorder(select(plans, config["recording"]["representations"], strict=False),
                             {f"{c}_hz": str(p.rate_hz) for c, p in plans.items()})
    recorder.start(path)
    recorder.writer._queue.maxsize = 10**7  # the loop never waits, and nothing is dropped
    runtime = LockstepRuntime(plans, DummyPlatform(), recorder=recorder)
    start = time.perf_counter()
    stats = runtime.run(Limits(frames=MOTION_FRAMES, speed=None))
    wall = time.perf_counter() - start
    status = recorder.status()
    return {
        "recorded_motion_frames": stats["motion"].frames,
        "recorded_cognition_frames": stats["cognition"].frames,
        "recorded_messages": status["messages"],
        "dropped": recorder.dropped_total(),
        "recording_us_per_frame": round(recorder.seconds / recorder.calls * 1e6, 2),
        "record_run_wall_s": round(wall, 3),
    }


def replay(path: Path) -> dict:
    platform = LogPlatform({"log": str(path)})
    plans = plan_program(load_config(DEFAULT_CONFIG, platform.config_layers()), platform)
    runtime = LockstepRuntime(plans, platform)
    start = time.perf_counter()
    stats = runtime.run(Limits(speed=None))
    wall = time.perf_counter() - start
    frames = stats["motion"].frames + stats["cognition"].frames
    duration = runtime.time_ns * 1e-9
    return {
        "replayed_motion_frames": stats["motion"].frames,
        "replayed_cognition_frames": stats["cognition"].frames,
        "replay_frames_per_s": round(frames / wall, 1),
        "replay_motion_frames_per_s": round(stats["motion"].frames / wall, 1),
        "replay_realtime_factor": round(duration / wall, 2),
    }


# Hand-written serializers: what a NaoTH developer writes for each representation.
def hand_ball_model(rep: BallModel, message_class=codec(BallModel).message_class) -> bytes:
    m = message_class()
    m.valid = rep.valid
    m.seen = rep.seen
    m.x = rep.x
    m.y = rep.y
    m.vx = rep.vx
    m.vy = rep.vy
    m.position_std = rep.position_std
    m.time_since_seen = rep.time_since_seen
    return m.SerializeToString()


def hand_frame_info(rep: FrameInfo, message_class=codec(FrameInfo).message_class) -> bytes:
    m = message_class()
    m.frame_number = rep.frame_number
    m.time_ns = rep.time_ns
    return m.SerializeToString()


def _hand_array(target, array: np.ndarray) -> None:
    target.dtype = array.dtype.str
    target.shape.extend(array.shape)
    target.data = array.tobytes()


def hand_joint_sensor_data(rep: JointSensorData, message_class=codec(JointSensorData).message_class) -> bytes:
    m = message_class()
    _hand_array(m.position, rep.position)
    _hand_array(m.stiffness, rep.stiffness)
    _hand_array(m.current, rep.current)
    _hand_array(m.temperature, rep.temperature)
    return m.SerializeToString()


def hand_inertial(rep: InertialSensorData, message_class=codec(InertialSensorData).message_class) -> bytes:
    m = message_class()
    _hand_array(m.accelerometer, rep.accelerometer)
    _hand_array(m.gyroscope, rep.gyroscope)
    _hand_array(m.angles, rep.angles)
    return m.SerializeToString()


def serialization() -> dict:
    rng = np.random.default_rng(1)
    cases = {
        "BallModel": (BallModel(valid=True, seen=True, x=1500.5, y=-320.25, vx=12.0, vy=-3.5, position_std=40.0, time_since_seen=0.1), hand_ball_model),
        "FrameInfo": (FrameInfo(frame_number=1234, time_ns=12_340_000_000), hand_frame_info),
        "JointSensorData": (JointSensorData(position=rng.normal(size=25), stiffness=rng.random(25), current=rng.random(25), temperature=rng.random(25) * 60), hand_joint_sensor_data),
        "InertialSensorData": (InertialSensorData(accelerometer=rng.normal(size=3), gyroscope=rng.normal(size=3), angles=rng.normal(size=2)), hand_inertial),
    }
    result = {}
    for name, (rep, hand) in cases.items():
        assert serialize(rep) == hand(rep), name  # the same bytes: a fair comparison
        auto_times, hand_times, ratios = [], [], []
        for _ in range(31):  # short rounds, alternating: machine noise hits both alike, and drifts cancel
            auto = min(timeit.repeat(lambda r=rep: serialize(r), number=500, repeat=3)) / 500
            manual = min(timeit.repeat(lambda r=rep, h=hand: h(r), number=500, repeat=3)) / 500
            auto_times.append(auto)
            hand_times.append(manual)
            ratios.append(auto / manual)
        result[name] = {"auto_us": round(statistics.median(auto_times) * 1e6, 3),
                        "hand_us": round(statistics.median(hand_times) * 1e6, 3), "ratio": round(statistics.median(ratios), 3)}
    return result


TAFEL = [sys.executable, "-m", "tafel.tools.cli"]


def peak_memory_mb(command: list[str]) -> tuple[float, float]:
    """(peak resident memory in MB, wall seconds) of one process run to its end."""
    start = time.perf_counter()
    process = subprocess.Popen(command, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    _pid, status, usage = os.wait4(process.pid, 0)
    if status != 0:
        raise RuntimeError(f"{' '.join(command)} failed: {process.stderr.read().decode()[-2000:]}")
    return usage.ru_maxrss / 1024, time.perf_counter() - start


def long_logs(folder: Path, long_minutes: float) -> dict:
    env = {**os.environ, "MUJOCO_GL": os.environ.get("MUJOCO_GL", "egl")}
    result = {}
    for label, minutes in (("1min", 1.0), (f"{long_minutes:g}min", long_minutes)):
        path = folder / f"mujoco_{minutes:g}min.mcap"
        if not path.exists():
            subprocess.run([*TAFEL, "run", "--seconds", str(minutes * 60), "--speed", "max", "--no-debug", "--cameras", "on",
                            "--record", str(path.with_suffix(".part")), "--status-interval", "3600"], check=True, env=env,
                           stdout=subprocess.DEVNULL)
            path.with_suffix(".part").rename(path)
        info_mb, info_s = peak_memory_mb([*TAFEL, "log", "info", str(path)])
        replay_mb, replay_s = peak_memory_mb([*TAFEL, "run", "--platform", "log", "--log", str(path), "--speed", "max", "--no-debug"])
        result[label] = {"file_mb": round(path.stat().st_size / 1e6, 1), "log_info_peak_mb": round(info_mb, 1),
                         "log_info_s": round(info_s, 1), "replay_peak_mb": round(replay_mb, 1), "replay_s": round(replay_s, 1)}
    return result


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--long-minutes", type=float, default=10.0)
    parser.add_argument("--keep", type=Path, help="folder to keep and reuse the long recordings in")
    parser.add_argument("--skip-long", action="store_true", help="leave out the long-log case (it records for minutes)")
    args = parser.parse_args()
    discover_modules()
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "synthetic.mcap"
        recorded = record(path)
        replayed = replay(path)
        long = {} if args.skip_long else long_logs(args.keep or Path(folder), args.long_minutes)
    per_message = serialization()
    ratios = [v["ratio"] for v in per_message.values()]
    print(json.dumps({
        **recorded,
        **replayed,
        "serialization": per_message,
        "serialization_ratio_max": max(ratios),
        "long_logs": long,
        "targets": {"replay_realtime_factor_min": 50, "serialization_ratio_max": 1.5, "long_log_peak_mb_max": 300},
    }))


if __name__ == "__main__":
    main()
