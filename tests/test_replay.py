"""Replay reproduces the recorded run, and ``tafel log compare`` says where two runs differ."""

from __future__ import annotations

import json
import math
import re
from pathlib import Path

import numpy as np
import pytest

from tafel.core.logs import LogReader
from tafel.tools.logs.log_compare import compare_logs, field_differences
from tests.test_cli_runtime import dummy, tafel

FEEDBACK_REPS = "InertialModel,CameraMatrixTop,JointCommand,BallModel"


def fingerprint(output: str) -> str:
    found = re.findall(r"^fingerprint (\w+)", output, re.MULTILINE)
    assert len(found) == 1, f"the fingerprint must be printed exactly once:\n{output}"
    return found[0]


def record_and_replay(tmp_path: Path, *run_args: str, reps: str = "all", replay_args: tuple[str, ...] = ()) -> tuple[Path, Path, str, str]:
    original, replayed = tmp_path / "original.mcap", tmp_path / "replayed.mcap"
    live = tafel("run", *run_args, "--speed", "max", "--no-debug", "--record", str(original), "--record-reps", reps, timeout=300)
    assert live.returncode == 0, live.stderr
    again = tafel("run", "--platform", "log", "--log", str(original), "--speed", "max", "--no-debug",
                  "--record", str(replayed), "--record-reps", reps, *replay_args, timeout=300)
    assert again.returncode == 0, again.stderr
    return original, replayed, fingerprint(live.stdout), fingerprint(again.stdout)


@pytest.mark.slow
def test_replay_feeds_only_sensor_data_so_stateful_modules_reproduce(tmp_path: Path) -> None:
    """The inertial filter and the ball model keep state in their own outputs: replay must not overwrite them."""
    original, replayed, live, again = record_and_replay(tmp_path, "--platform", "dummy", "--frames", "500", "--seed", "5",
                                                         reps=FEEDBACK_REPS)
    compared = tafel("log", "compare", str(original), str(replayed))
    assert compared.returncode == 0, compared.stdout
    assert "no difference in" in compared.stdout and "motion/InertialModel: 500 frames" in compared.stdout
    assert live == again


@pytest.mark.slow
def test_compare_finds_the_first_difference_after_a_parameter_change(tmp_path: Path) -> None:
    original, replayed, live, again = record_and_replay(
        tmp_path, "--platform", "dummy", "--frames", "300", reps=FEEDBACK_REPS,
        replay_args=("--set", "parameters.KalmanBallModeler.friction=3.0"))
    assert live != again
    compared = tafel("log", "compare", str(original), str(replayed), "--rep", "BallModel,JointCommand")
    assert compared.returncode == 1
    assert re.search(r"DIFFERS  cognition/BallModel: \d+ of 90 frames differ, first at frame \d+", compared.stdout)
    assert re.search(r"^\s+(vx|vy|x|y): ", compared.stdout, re.MULTILINE), compared.stdout
    assert "motion/InertialModel" not in compared.stdout  # --rep restricts the report
    report = json.loads(tafel("log", "compare", str(original), str(replayed), "--json").stdout)
    ball = report["cognition/BallModel"]
    assert ball["differing"] > 0 and ball["fields"] and report["motion/InertialModel"]["differing"] == 0


@pytest.mark.slow
def test_compare_errors_name_what_is_wrong(tmp_path: Path) -> None:
    original, _replayed, _live, _again = record_and_replay(tmp_path, "--platform", "dummy", "--frames", "50", reps="BallModel")
    missing = tafel("log", "compare", str(original), str(tmp_path / "nope.mcap"))
    assert missing.returncode == 2 and "nope.mcap" in missing.stderr
    wrong = tafel("log", "compare", str(original), str(original), "--rep", "BallModle")
    assert wrong.returncode == 2 and "did you mean 'BallModel'" in wrong.stderr


@pytest.mark.slow
def test_compare_reports_frames_present_in_one_log_only(tmp_path: Path) -> None:
    short, long = tmp_path / "short.mcap", tmp_path / "long.mcap"
    assert dummy("--frames", "100", "--speed", "max", "--record", str(short)).returncode == 0
    assert dummy("--frames", "150", "--speed", "max", "--record", str(long)).returncode == 0
    with LogReader(short) as a, LogReader(long) as b:
        result = compare_logs(a, b, ["FrameInfo"])
    motion = result["motion/FrameInfo"]
    assert (motion.compared, motion.differing, motion.only_first, motion.only_second) == (100, 0, 0, 50)


def test_field_differences_compare_floats_to_the_last_bit() -> None:
    assert field_differences({"x": 1.0}, {"x": 1.0}) == []
    assert field_differences({"x": 1.0}, {"x": math.nextafter(1.0, 2.0)}) == [("x", 1.0, math.nextafter(1.0, 2.0))]
    assert field_differences({"x": 0.0}, {"x": -0.0}) == [("x", 0.0, -0.0)]
    assert field_differences({"x": math.nan}, {"x": math.nan}) == []
    nested = field_differences({"pose": {"x": 1.0, "y": 2.0}, "n": 3}, {"pose": {"x": 1.0, "y": 2.5}, "n": 4})
    assert nested == [("n", 3, 4), ("pose.y", 2.0, 2.5)]
    assert field_differences({"a": [1, 2]}, {"a": [1, 2, 3]}) == [("a (length)", 2, 3)]
    same = np.arange(6, dtype=np.float32).reshape(2, 3)
    assert field_differences({"m": same}, {"m": same.copy()}) == []
    other = same.copy()
    other[1, 2] = np.nextafter(other[1, 2], np.float32(100))
    [(path, _a, _b)] = field_differences({"m": same}, {"m": other})
    assert path == "m"


@pytest.mark.slow
def test_mujoco_replay_reproduces_every_output_to_the_last_bit(tmp_path: Path) -> None:
    """The default program in lockstep, every module output recorded: replay, record, compare."""
    original, replayed, live, again = record_and_replay(tmp_path, "--platform", "mujoco", "--seconds", "3")
    compared = tafel("log", "compare", str(original), str(replayed))
    assert compared.returncode == 0, compared.stdout
    for topic in ("motion/InertialModel", "motion/JointCommand", "cognition/BallModel", "cognition/BallPercept", "motion/CameraMatrixTop"):
        assert re.search(rf"same     {topic}: \d+ frames", compared.stdout), topic
    assert live == again
