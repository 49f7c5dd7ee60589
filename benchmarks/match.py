"""Simulated matches (``tafel match``) on this machine: how fast, how many goals, how much talk.

- The real-time factor (simulated seconds per wall second of play; start-up apart, reported too) of
  1v1, 2v2 and 5v5 matches with cameras off (perception from ground truth) and on (every robot renders
  and sees through its cameras). Each plays ``--seconds`` of game from the kickoff's READY on.
- The goals a team of two scores in 5 simulated minutes of play (two halves of 150 s) against a
  team that stands still (it never hears the GameController: it stands where it entered, on its
  touchline), cameras off.
- Beside each real-time factor, the limit this machine allows (``limit_realtime_factor_*``: the cores
  divided by the CPU seconds the world and every robot's process used per simulated second, measured in
  the same match) and what one robot costs (``cpu_s_per_sim_s_per_robot_*``). Targets (issue 34):
  2v2 with cameras at least 1.0, 5v5 with cameras at least 0.4.
- The bytes per team message and the messages each robot and each team sent per minute of PLAYING.
- The fouls the simulated referee called per team and minute of PLAYING, in every match played
  (``fouls_per_minute_*``; the goal is none of the own team's).
- ``--team-play``: instead of all that, Tafel against Tafel, 2v2, cameras off, ``--seconds`` of game
  (600: two halves of 5 minutes) for each of ``--seeds``: per seed the score, each team's completed
  passes (``passes``: the ball kicked by one robot and next touched by a teammate 1 m or more away, no
  opponent's touch between, from ground truth: ``tools/simulation/passes.py``), own goals and fouls; and
  over the seeds the fewest goals and passes of a team. Target (issue 36): goals on both sides, no own
  goal, at least 3 completed passes per team, in every seed (and no fouls, issue 32).

    python benchmarks/match.py [--short]
    python benchmarks/match.py --team-play [--seconds 600] [--seeds 1,2,3]

Prints one JSON line. ``--short`` plays a tenth as long (a smoke test of the benchmark itself).
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent


def play(*args: str, seed: int = 1) -> dict:
    with tempfile.TemporaryDirectory() as folder:
        result = Path(folder) / "result.json"
        done = subprocess.run([sys.executable, "-m", "tafel.tools.cli", "match", "--speed", "max", "--seed", str(seed), "--result", str(result),
                               *args], capture_output=True, text=True, cwd=folder, env={**os.environ, "PYTHONPATH": str(REPO)})
        if not result.exists():
            raise RuntimeError(f"tafel match {' '.join(args)} failed: {done.stderr[-2000:]}")
        return json.loads(result.read_text())


#: the referee's events that begin a game state (the others, a penalty, a free kick or a goal, fall within one)
STATES = ("INITIAL", "STANDBY", "READY", "SET", "PLAYING", "FINISHED")


def playing_s(result: dict) -> float:
    """s of PLAYING in a match: from each PLAYING to the next state (a penalty or a free kick within it
    does not end it)."""
    events = [e for e in result["events"] if e["event"] in STATES] + [{"time_s": result["simulated_s"], "event": "END"}]
    return sum(b["time_s"] - a["time_s"] for a, b in zip(events, events[1:]) if a["event"] == "PLAYING")


def fouls_per_minute(result: dict) -> list[float]:
    """Each team's fouls per minute of PLAYING (team 1 first)."""
    minutes = playing_s(result) / 60.0
    return [round(team["fouls"] / minutes, 3) if minutes else 0.0 for team in result["teams"]]


def team_play(result: dict) -> dict:
    """One Tafel-against-Tafel match's figures: score, each team's goals, passes, own goals and fouls (team 1 first)."""
    teams = result["teams"]
    return {"score": result["score"], "goals": [team["score"] for team in teams], "passes": [team["passes"] for team in teams],
            "own_goals": [team["own_goals"] for team in teams], "fouls": [team["fouls"] for team in teams],
            "pass_distances_m": [round(p["distance_mm"] / 1000.0, 1) for p in result["passes"]], "simulated_s": result["simulated_s"],
            "realtime_factor": result["realtime_factor"]}


def team_play_summary(matches: dict[str, dict]) -> dict:
    """Over the seeds' matches: the fewest goals and passes any team had in a match, all own goals and fouls, and
    whether every match met issue 36's target (goals on both sides, no own goal, 3 passes per team) with no foul."""
    games = list(matches.values())
    least_goals = min((g for m in games for g in m["goals"]), default=0)
    least_passes = min((n for m in games for n in m["passes"]), default=0)
    own_goals, fouls = sum(sum(m["own_goals"]) for m in games), sum(sum(m["fouls"]) for m in games)
    return {"least_goals_per_team": least_goals, "least_passes_per_team": least_passes, "own_goals": own_goals, "fouls": fouls,
            "target_met": bool(games) and least_goals >= 1 and least_passes >= 3 and own_goals == 0 and fouls == 0}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--short", action="store_true", help="a tenth as long")
    parser.add_argument("--only-speed", action="store_true", help="only the real-time factors with cameras on (no goals or messages)")
    parser.add_argument("--team-play", action="store_true", help="only Tafel against Tafel, 2v2, cameras off: goals, passes, fouls per seed")
    parser.add_argument("--seconds", type=float, default=600.0, help="s of game per --team-play match (default 600)")
    parser.add_argument("--seeds", default="1,2,3", help="the --team-play matches' seeds (default 1,2,3)")
    args = parser.parse_args()
    if args.team_play:
        matches = {}
        for seed in (int(s) for s in args.seeds.split(",")):
            seconds = max(2.0, args.seconds * (0.1 if args.short else 1.0))
            matches[f"seed_{seed}"] = team_play(play("--teams", "2v2", "--cameras", "off", "--seconds", f"{seconds:g}", seed=seed))
        print(json.dumps({"team_play_2v2": matches, **team_play_summary(matches), "cpu_count": os.cpu_count(),
                          "load_average_1min": round(os.getloadavg()[0], 2)}))
        return
    scale = 0.1 if args.short else 1.0
    figures: dict[str, object] = {}
    for cameras, seconds in ((("on", 16.0),) if args.only_speed else (("off", 60.0), ("on", 16.0))):
        for teams in ("1v1", "2v2", "5v5"):
            result = play("--teams", teams, "--cameras", cameras, "--seconds", f"{max(2.0, seconds * scale):g}", "--ready-seconds", "6")
            key = f"{teams}_cameras_{cameras}"
            figures[f"realtime_factor_{key}"] = result["realtime_factor"]
            # beside it, what this machine allows: its cores over the CPU every process used per simulated second
            figures[f"limit_realtime_factor_{key}"] = result.get("limit_realtime_factor")
            figures[f"cpu_s_per_sim_s_per_robot_{key}"] = result.get("cpu_s_per_sim_s_per_robot")
            figures[f"startup_s_{key}"] = result["startup_s"]
            figures[f"simulated_s_{key}"] = result["simulated_s"]
            figures[f"fouls_per_minute_{key}"] = fouls_per_minute(result)
    if args.only_speed:
        print(json.dumps({**figures, "cpu_count": os.cpu_count(), "load_average_1min": round(os.getloadavg()[0], 2)}))
        return
    standing = play("--teams", "2v2", "--cameras", "off", "--seconds", f"{300.0 * scale:g}", "--team2-set", "game.enabled=false")
    minutes = playing_s(standing) / 60.0
    messages = standing["teams"][0]["team_messages"]
    figures.update({
        "goals_in_5_minutes_2v2_against_standing_team": standing["teams"][0]["score"],
        "goals_conceded": standing["teams"][1]["score"],
        "passes_2v2_against_standing_team": standing["teams"][0]["passes"],
        "playing_minutes": round(minutes, 2),
        "bytes_per_team_message": standing["bytes_per_team_message"],
        "team_messages_per_minute_per_team": round(messages / minutes, 1) if minutes else 0.0,
        "team_messages_per_minute_per_robot": round(messages / 2 / minutes, 1) if minutes else 0.0,
        "message_budget_left": standing["teams"][0]["message_budget_left"],
        "fouls_per_minute_2v2_against_standing_team": fouls_per_minute(standing),
        "cpu_count": os.cpu_count(),
        "load_average_1min": round(os.getloadavg()[0], 2),
    })
    print(json.dumps(figures))


if __name__ == "__main__":
    main()
