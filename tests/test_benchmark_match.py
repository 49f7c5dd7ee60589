"""benchmarks/match.py's figures from a match's result: the minutes of PLAYING behind fouls and messages per minute."""

from __future__ import annotations

from types import ModuleType

import pytest

from tests.support.benchmarks import load_benchmark


def benchmark() -> ModuleType:
    return load_benchmark("match")


def test_playing_time_runs_on_through_penalties_and_free_kicks_and_fouls_count_per_minute_of_it() -> None:
    """Before, PLAYING ended at the next event of any kind: after a penalty or a goal kick the rest of the
    half was not counted, and the fouls per minute came out several times too high."""
    events = [("READY", 3.0), ("SET", 22.5), ("PLAYING", 25.5), ("PENALTY player_pushing team 2 player 2", 40.0),
              ("GOAL_KICK 2", 60.0), ("FINISHED", 145.5), ("INITIAL", 147.5), ("READY", 150.5), ("SET", 170.0),
              ("PLAYING", 173.0), ("GOAL 1", 203.0), ("READY", 203.0), ("SET", 220.0), ("PLAYING", 223.0), ("FINISHED", 253.0)]
    result = {"events": [{"time_s": t, "event": e} for e, t in events], "simulated_s": 255.0,
              "teams": [{"fouls": 0}, {"fouls": 1}]}
    match = benchmark()
    assert match.playing_s(result) == pytest.approx(120.0 + 30.0 + 30.0)
    assert match.fouls_per_minute(result) == [0.0, pytest.approx(1 / 3, abs=1e-3)]


def test_team_play_reports_each_teams_passes_and_the_target_needs_them_in_every_seed() -> None:
    match = benchmark()

    def result(score: str, goals: list[int], passes: list[int], own_goals: list[int] = [0, 0], fouls: list[int] = [0, 0]) -> dict:  # noqa: B006
        return {"score": score, "simulated_s": 640.0, "realtime_factor": 1.1,
                "teams": [{"score": g, "passes": n, "own_goals": o, "fouls": f} for g, n, o, f in zip(goals, passes, own_goals, fouls)],
                "passes": [{"distance_mm": 1840.0}]}

    good = match.team_play(result("2:1", [2, 1], [4, 3]))
    assert good["passes"] == [4, 3] and good["goals"] == [2, 1] and good["pass_distances_m"] == [1.8]
    assert match.team_play_summary({"seed_1": good, "seed_2": good})["target_met"]
    few = match.team_play(result("1:1", [1, 1], [5, 2]))
    summary = match.team_play_summary({"seed_1": good, "seed_2": few})
    assert summary["least_passes_per_team"] == 2 and not summary["target_met"]
    own = match.team_play(result("2:1", [2, 1], [4, 3], own_goals=[0, 1]))
    assert not match.team_play_summary({"seed_1": own})["target_met"]
    fouled = match.team_play(result("2:1", [2, 1], [4, 3], fouls=[1, 0]))
    assert not match.team_play_summary({"seed_1": fouled})["target_met"]
