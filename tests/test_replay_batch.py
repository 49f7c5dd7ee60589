"""``tafel replay-batch`` end to end: recorded logs replayed in worker processes, with and without a change."""

from __future__ import annotations

import csv
import os
import subprocess
import sys
from pathlib import Path

import pytest

from tafel.tools.simulation.replay_batch import expand

REPO = Path(__file__).resolve().parent.parent


def tafel(*args: str, cwd: Path, timeout: float = 300) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "tafel.tools.cli", *args], capture_output=True, text=True, timeout=timeout, cwd=cwd,
                          env={**os.environ, "PYTHONPATH": str(REPO)})


@pytest.fixture(scope="module")
def games(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """Two short recordings of the default program on the dummy platform, everything recorded."""
    folder = tmp_path_factory.mktemp("games")
    for seed in (1, 2):
        done = tafel("run", "--platform", "dummy", "--frames", "300", "--seed", str(seed), "--speed", "max", "--no-debug",
                     "--record", str(folder / f"game{seed}.mcap"), "--record-reps", "all", cwd=folder)
        assert done.returncode == 0, done.stderr
    return folder


def rows(path: Path) -> list[dict[str, str]]:
    with path.open() as f:
        return list(csv.DictReader(f))


@pytest.mark.slow
def test_without_a_change_no_log_differs(games: Path, tmp_path: Path) -> None:
    done = tafel("replay-batch", str(games / "*.mcap"), "--compare", "--metric", "BallModel.valid", "--out", str(tmp_path / "same.csv"),
                 "--workers", "2", cwd=tmp_path)
    assert done.returncode == 0, done.stdout + done.stderr
    assert "0 of 2 logs differ from their recorded outputs" in done.stdout
    found = rows(tmp_path / "same.csv")
    assert [Path(r["log"]).name for r in found] == ["game1.mcap", "game2.mcap"]
    assert all(r["status"] == "ok" and r["channels_differing"] == "0" and int(r["channels"]) > 20 for r in found)
    assert all(r["BallModel.valid recorded"] == r["BallModel.valid replayed"] for r in found)


@pytest.mark.slow
def test_a_parameter_change_is_found_in_every_log_with_the_first_differing_field(games: Path, tmp_path: Path) -> None:
    done = tafel("replay-batch", str(games / "game1.mcap"), str(games / "game2.mcap"), "--compare",
                 "--set", "parameters.KalmanBallModeler.measurement_std=80", "--metric", "BallModel.x",
                 "--out", str(tmp_path / "changed.csv"), "--artifacts", str(tmp_path / "replays"), cwd=tmp_path)
    assert done.returncode == 1, done.stdout + done.stderr
    assert "2 of 2 logs differ from their recorded outputs" in done.stdout
    for row in rows(tmp_path / "changed.csv"):
        assert row["first_difference"].startswith("cognition/BallModel frame 1: position_std"), row
        assert "cognition/BallModel" in row["differing"].split() and "motion/InertialModel" not in row["differing"].split()
        assert row["BallModel.x recorded"] != row["BallModel.x replayed"]
        assert Path(row["replay"]).is_file()  # --artifacts keeps the replays


@pytest.mark.slow
def test_bad_input_is_named_and_loses_nothing(games: Path, tmp_path: Path) -> None:
    missing = tafel("replay-batch", str(tmp_path / "nothing*.mcap"), cwd=tmp_path)
    assert missing.returncode == 2 and "nothing*.mcap: no such log (the pattern matches no file)" in missing.stderr
    metric = tafel("replay-batch", str(games / "game1.mcap"), "--metric", "BallModle.valid", cwd=tmp_path)
    assert metric.returncode == 2 and "--metric BallModle.valid: no log holds 'BallModle'; did you mean 'BallModel'" in metric.stderr
    (tmp_path / "broken.mcap").write_bytes(b"not a log at all")
    done = tafel("replay-batch", str(tmp_path / "broken.mcap"), str(games / "game1.mcap"), "--compare", "--out", str(tmp_path / "mixed.csv"),
                 cwd=tmp_path)
    assert done.returncode == 2, done.stdout + done.stderr  # a log that cannot be replayed
    broken, good = rows(tmp_path / "mixed.csv")
    assert broken["status"] == "error" and "not an MCAP log" in broken["error"]
    assert good["status"] == "ok" and good["channels_differing"] == "0"  # the good log was still replayed


def test_globs_expand_in_order_and_name_each_file_once(tmp_path: Path) -> None:
    for name in ("game2.mcap", "game1.mcap", "notes.txt"):
        (tmp_path / name).write_bytes(b"")
    games = tmp_path
    found = expand([str(games / "game*.mcap"), str(games / "game1.mcap")])
    assert [p.name for p in found] == ["game1.mcap", "game2.mcap"]
    with pytest.raises(ValueError, match="no such log"):
        expand([str(games / "absent.mcap")])
