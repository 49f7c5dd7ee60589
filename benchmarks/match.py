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

    python benchmarks/match.py [--short]

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


def play(*args: str) -> dict:
    with tempfile.TemporaryDirectory() as folder:
        result = Path(folder) / "result.json"
        done = subprocess.run([sys.executable, "-m", "tafel.tools.cli", "match", "--speed", "max", "--seed", "1", "--result", str(result),
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


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--short", action="store_true", help="a tenth as long")
    parser.add_argument("--only-speed", action="store_true", help="only the real-time factors with cameras on (no goals or messages)")
    args = parser.parse_args()
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
