"""benchmarks/match.py's figures from a match's result: the minutes of PLAYING behind fouls and messages per minute."""

from __future__ import annotations

import importlib.util
from pathlib import Path
from types import ModuleType

import pytest

REPO = Path(__file__).resolve().parent.parent


def benchmark() -> ModuleType:
    spec = importlib.util.spec_from_file_location("match_benchmark", REPO / "benchmarks" / "match.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


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
