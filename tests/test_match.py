"""``tafel match`` end to end: robot programs in processes of their own, the world in lockstep with them,
the simulated GameController on loopback UDP. Judged by the match's result, the robots' own logs and
the processes left behind."""

from __future__ import annotations

import json
import math
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

from tafel.core.logs import LogReader
from tafel.tools.logs.log_tools import decoded_messages

REPO = Path(__file__).resolve().parent.parent
pytestmark = pytest.mark.slow
#: what the tests read of the robots' logs; recording everything at 100 Hz costs a fifth of a match's speed
LEAN = ("--record-reps", "RobotPose,GameState,MotionRequest")


def match(tmp_path: Path, *args: str, timeout: float = 600.0) -> tuple[dict, subprocess.CompletedProcess]:
    result = tmp_path / "result.json"
    done = subprocess.run([sys.executable, "-m", "tafel.tools.cli", "match", "--speed", "max", "--result", str(result), *args],
                          capture_output=True, text=True, timeout=timeout, cwd=tmp_path, env={**os.environ, "PYTHONPATH": str(REPO)})
    assert result.exists(), done.stdout[-3000:] + done.stderr[-3000:]
    return json.loads(result.read_text()), done


def robot_programs_running() -> list[str]:
    """Command lines of match robots still running on this machine."""
    found = []
    for entry in Path("/proc").iterdir():
        try:
            command = (entry / "cmdline").read_bytes().replace(b"\0", b" ").decode()
        except (OSError, ValueError):
            continue
        if "--platform match" in command and "tafel.tools.cli run" in command:
            found.append(command)
    return found


def poses(log: Path) -> list[tuple[float, dict]]:
    """(s, RobotPose fields) of every cognition frame of a robot's log."""
    reader = LogReader(log)
    try:
        return [(time_ns * 1e-9, fields) for _, _, time_ns, fields in decoded_messages(reader, "RobotPose", "cognition")]
    finally:
        reader.close()


def event_time(result: dict, name: str, after: float = 0.0) -> float:
    return next(e["time_s"] for e in result["events"] if e["event"] == name and e["time_s"] >= after)


def test_a_lone_robot_walks_to_its_kickoff_position_in_ready_and_scores_after_playing_starts(tmp_path: Path) -> None:
    result, done = match(tmp_path, "--teams", "1v0", "--seconds", "60", "--goals", "1", "--cameras", "off", "--seed", "3",
                         "--ready-seconds", "40", "--record-dir", str(tmp_path / "logs"), *LEAN)
    assert done.returncode == 0 and result["ended"] == "the game is over", done.stderr[-3000:]
    assert "team 1 player 1: debug server 127.0.0.1:" in done.stdout
    assert re.search(r"team 1 talks on UDP \d+, .*: tafel team --team 1 --port \d+ --game-controller-port \d+", done.stdout)
    ready, kickoff = event_time(result, "READY"), event_time(result, "PLAYING")
    goals = [e["time_s"] for e in result["events"] if e["event"] == "GOAL 1"]
    assert goals and goals[0] > kickoff, result["events"]
    assert [e["event"] for e in result["events"]][-2:] == ["GOAL 1", "FINISHED"]  # --goals 1: the game ends with the goal
    assert result["teams"][0]["score"] >= 1 and result["score"].endswith(":0")
    # in READY it walked from the touchline to where the team kicking off puts its striker, and stood there at SET
    track = poses(tmp_path / "logs" / "team1_player1.mcap")
    at_ready = next(p for t, p in track if t >= ready)
    at_set = [p for t, p in track if event_time(result, "SET") <= t < kickoff]
    assert math.hypot(at_ready["x"] + 3600.0, at_ready["y"] + 3000.0) < 400.0  # where it entered
    assert all(math.hypot(p["x"] + 300.0, p["y"]) < 350.0 for p in at_set), at_set[0]
    assert result["robots"][0]["returns"] > 0 and result["teams"][0]["team_messages"] > 0
    # what the match cost, to read its real-time factor against: the cores over the CPU per simulated second
    per_second = result["cpu_s_per_sim_s_per_robot"] + result["cpu_s_per_sim_s_world"]
    assert result["cpu_s_per_sim_s_per_robot"] > 0 and result["limit_realtime_factor"] == pytest.approx(result["cpu_count"] / per_second, rel=0.02)


#: simulated s of the two-against-two test: three minutes, as issue 19 asks (READY and SET included)
TWO_AGAINST_TWO_S = 180.0


def test_a_two_against_two_match_ends_cleanly_with_readable_logs(tmp_path: Path) -> None:
    result, done = match(tmp_path, "--teams", "2v2", "--seconds", f"{(TWO_AGAINST_TWO_S - 20.0):g}", "--cameras", "off", "--seed", "1",
                         "--ready-seconds", "6", "--record-dir", str(tmp_path / "logs"), *LEAN)
    assert done.returncode == 0 and result["ended"] == "the game is over", done.stdout[-2000:] + done.stderr[-3000:]
    assert result["simulated_s"] >= TWO_AGAINST_TWO_S - 10.0
    assert robot_programs_running() == []
    assert [e["event"] for e in result["events"]].count("PLAYING") >= 2  # both halves (and kickoffs after goals)
    assert len(result["robots"]) == 4 and all(r["exit_status"] == 0 for r in result["robots"])
    for robot in result["robots"]:
        track = poses(Path(robot["log"]))
        assert track and track[-1][0] >= result["simulated_s"] - 1.0, robot
        assert robot["returns"] >= 0.8 * result["simulated_s"]  # a return packet a second: the GameController heard every robot
    for team in result["teams"]:
        assert 0 < team["team_messages"] and team["message_budget_left"] == 1200 - team["team_messages"]
    assert result["bytes_per_team_message"] == 30.0


def test_the_same_seed_plays_the_same_match(tmp_path: Path) -> None:
    runs = []
    for run in ("first", "second"):
        folder = tmp_path / run
        folder.mkdir()
        result, done = match(folder, "--teams", "1v1", "--seconds", "2", "--cameras", "off", "--seed", "7", "--ready-seconds", "3",
                             "--record-dir", str(folder / "logs"), *LEAN)
        assert done.returncode == 0, done.stderr[-3000:]
        runs.append((result, [poses(folder / "logs" / f"team{t}_player1.mcap") for t in (1, 2)]))
    (first, first_tracks), (second, second_tracks) = runs
    assert first["events"] == second["events"] and first["score"] == second["score"]
    assert first_tracks == second_tracks  # every robot's belief, frame by frame


def test_bad_team_sizes_are_refused_with_what_would_be_right(tmp_path: Path) -> None:
    done = subprocess.run([sys.executable, "-m", "tafel.tools.cli", "match", "--teams", "6v6"], capture_output=True, text=True,
                          env={**os.environ, "PYTHONPATH": str(REPO)}, cwd=tmp_path)
    assert done.returncode == 2 and "--teams takes NvM with 0 to 5 robots a team (1v1, 2v2, 5v5, 1v0), got '6v6'" in done.stderr
