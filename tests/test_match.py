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
from tafel.tools.logs.decoding import decoded_messages

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


def robot_programs_running(record_dir: Path) -> list[str]:
    """Command lines of this match's robots (those recording into ``record_dir``) still running on this
    machine; other tests' matches, run at the same time by another worker, are not this test's business."""
    found = []
    for entry in Path("/proc").iterdir():
        try:
            command = (entry / "cmdline").read_bytes().replace(b"\0", b" ").decode()
        except (OSError, ValueError):
            continue
        if "--platform match" in command and "tafel.tools.cli run" in command and str(record_dir) in command:
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
    assert robot_programs_running(tmp_path / "logs") == []
    assert [e["event"] for e in result["events"]].count("PLAYING") >= 2  # both halves (and kickoffs after goals)
    assert len(result["robots"]) == 4 and all(r["exit_status"] == 0 for r in result["robots"])
    for robot in result["robots"]:
        track = poses(Path(robot["log"]))
        assert track and track[-1][0] >= result["simulated_s"] - 1.0, robot
        assert robot["returns"] >= 0.8 * result["simulated_s"]  # a return packet a second: the GameController heard every robot
    for team in result["teams"]:
        assert 0 < team["team_messages"] and team["message_budget_left"] == 1200 - team["team_messages"]
    assert result["bytes_per_team_message"] == 30.0
    # completed passes (tools/simulation/passes.py, from ground truth): each team's count, each pass between teammates
    for number, team in zip((1, 2), result["teams"]):
        assert team["passes"] == sum(p["team"] == number for p in result["passes"]) and team["own_goals"] >= 0
    assert all(p["kicker"] != p["receiver"] and p["distance_mm"] >= 1000 for p in result["passes"]), result["passes"]


def test_the_same_seed_plays_the_same_match(tmp_path: Path) -> None:
    runs = []
    for run in ("first", "second"):
        folder = tmp_path / run
        folder.mkdir()
        result, done = match(folder, "--teams", "1v1", "--seconds", "2", "--halves", "1", "--cameras", "off", "--seed", "7", "--ready-seconds", "3",
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


# --------------------------------------------------------------------------- the rules, refereed from ground truth
@pytest.fixture(scope="module")
def set_plays(tmp_path_factory: pytest.TempPathFactory) -> dict:
    """One short 2v2 (one half, cameras off) staged by the referee: team 1's kick-off, with READY cut short so
    that team 2's robots are still on their way to the ball while it is on; at 17 s a pushing free kick for
    team 1 at the centre spot, where team 2's striker waits; open play until the half ends at 27 s."""
    folder = tmp_path_factory.mktemp("set_plays")
    result, done = match(folder, "--teams", "2v2", "--halves", "1", "--seconds", "18", "--ready-seconds", "3", "--cameras", "off",
                         "--seed", "1", "--call", "17:pushing_free_kick:1")
    assert done.returncode == 0 and result["ended"] == "the game is over", done.stdout[-2000:] + done.stderr[-3000:]
    return result


def restriction(result: dict, set_play: str) -> dict:
    return next(r for r in result["set_plays"] if r["set_play"] == set_play)


def test_at_the_opponents_kick_off_nobody_enters_the_centre_circle_until_the_ball_moved_or_10_s(set_plays: dict) -> None:
    kick_off = restriction(set_plays, "kick_off")
    assert kick_off["kicking_team"] == 1 and kick_off["end_s"] - kick_off["start_s"] >= 5.0, kick_off  # seconds of it
    assert kick_off["nearest_mm"] < kick_off["nearest_at_start_mm"] - 1000.0  # team 2 walked towards the ball ...
    assert kick_off["nearest_mm"] >= 750.0  # ... and stayed out of the centre circle (the torso's distance from the centre)
    assert not [f for f in set_plays["fouls"] if "centre circle" in f["reason"]]


def test_at_an_opponent_free_kick_every_defender_keeps_0_75_m_from_the_ball_until_it_is_taken(set_plays: dict) -> None:
    free_kick = restriction(set_plays, "pushing_free_kick")
    assert free_kick["kicking_team"] == 1 and free_kick["start_s"] == 17.0 and free_kick["end_s"] - free_kick["start_s"] >= 2.0
    assert free_kick["nearest_at_start_mm"] < 2000.0  # team 2 was near the ball when it was called ...
    assert free_kick["nearest_mm"] >= 750.0, free_kick  # ... and kept 0.75 m until team 1 touched it (or the half ended)
    assert not [f for f in set_plays["fouls"] if "0.75 m" in f["reason"]]


def test_in_that_match_robots_walk_around_each_other_and_nobody_commits_a_foul(set_plays: dict) -> None:
    assert not [f for f in set_plays["fouls"] if f["penalty"] == "player_pushing"]
    assert set_plays["fouls"] == [] and [team["fouls"] for team in set_plays["teams"]] == [0, 0]


def test_a_penalty_shoot_out_alone_the_teams_kick_in_turn_and_the_referee_judges_each_shot(tmp_path: Path) -> None:
    result, done = match(tmp_path, "--teams", "1v1", "--shoot-out", "--penalty-shots", "1", "--sudden-death-shots", "0",
                         "--cameras", "off", "--seed", "1")
    assert done.returncode == 0 and result["ended"] == "the game is over", done.stdout[-2000:] + done.stderr[-3000:]
    shoot_out, shots = result["shoot_out"], result["shoot_out"]["shots"]
    assert [(s["team"], s["striker"], s["keeper"]) for s in shots] == [(1, 1, 1), (2, 1, 1)]
    # the striker took each shot: none ran out of time, no foul ended one
    assert all(s["outcome"] in ("goal", "saved", "post", "wide", "missed", "second touch") for s in shots)
    playing = [e["time_s"] for e in result["events"] if e["event"] == "PLAYING"]
    assert len(playing) == 2 and all(0.0 < s["time_s"] - start < 30.0 for s, start in zip(shots, playing))
    goals = [sum(s["team"] == team and s["outcome"] == "goal" for s in shots) for team in (1, 2)]
    assert shoot_out["score"] == f"{goals[0]}:{goals[1]}" and result["score"] == "0:0"
    if goals[0] != goals[1]:
        assert shoot_out["winner"] == (1 if goals[0] > goals[1] else 2)
    else:  # level after one shot each and no sudden death: the rules' coin toss
        assert shoot_out["winner"] in (1, 2) and result["events"][-1]["event"].endswith("(a coin toss)")
    assert f"penalty shot 1: team 1 player 1 against keeper 1: {shots[0]['outcome']}" in done.stdout
    assert f"shoot-out {shoot_out['score']}" in done.stdout
    # GameController3 counts no team messages in the shoot-out
    assert all(team["team_messages"] == 0 < team["team_messages_heard"] for team in result["teams"])
