"""``tafel match --realism``: the level reaches every robot's renderer, each robot's camera pipeline has a
seed of its own, the world builds one realistic hall, and the result says which level was played."""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import numpy as np
import pytest

from tafel.core.logs import LogReader
from tafel.platforms.realism import LEVELS
from tafel.tools.cli.arguments import REALISM_LEVELS, build_parser
from tafel.tools.logs.decoding import decoded_messages
from tafel.tools.simulation.match import Match

REPO = Path(__file__).resolve().parent.parent


def match_args(*argv: str) -> argparse.Namespace:
    """``tafel match ARGV`` as the command line parses it."""
    return build_parser().parse_args(["match", *argv])


@contextmanager
def built_match(*argv: str) -> Iterator[Match]:
    """A ``Match`` of ``tafel match ARGV``, its world built, no robot started; its sockets closed after."""
    match = Match(match_args(*argv))
    try:
        yield match
    finally:
        match.referee.close()
        match.listener.close()


def test_match_realism_defaults_to_off_takes_each_level_and_the_bare_option_is_full() -> None:
    assert REALISM_LEVELS == LEVELS
    assert match_args().realism == "off"
    assert [match_args("--realism", level).realism for level in LEVELS] == list(LEVELS)
    assert match_args("--realism").realism == "full"  # as tafel run --realism


def test_a_wrong_realism_level_is_refused_with_the_levels_named() -> None:
    done = subprocess.run([sys.executable, "-m", "tafel.tools.cli", "match", "--realism", "fulll"], capture_output=True, text=True,
                          timeout=120, env={**os.environ, "PYTHONPATH": str(REPO)})
    assert done.returncode == 2
    assert "argument --realism: invalid choice: 'fulll' (choose from 'off', 'mild', 'full')" in done.stderr


def test_every_robot_is_started_at_the_matchs_realism_with_a_seed_of_its_own() -> None:
    with built_match("--teams", "2v1", "--realism", "mild", "--seed", "7") as match:
        commands = [match.robot_command(player) for player in match.players]
        assert all("--realism=mild" in command for command in commands)
        seeds = [int(command[command.index("--seed") + 1]) for command in commands]
        assert len(set(seeds)) == len(commands) and min(seeds) == 7
        assert match.world.look is not None
        realistic_geoms = match.world.model.ngeom
    with built_match("--teams", "2v1", "--seed", "7") as match:
        assert all("--realism=off" in match.robot_command(player) for player in match.players)
        assert match.world.look is None
        assert match.world.model.ngeom < realistic_geoms  # no hall clutter, no visible nets


def equal_neighbours(image: np.ndarray) -> float:
    """Share of pixels exactly equal to their right neighbour: nearly all in a plain render (flat carpet,
    flat walls), few once sensor noise and JPEG have been at it."""
    return float((image[:, 1:] == image[:, :-1]).all(axis=2).mean())


@pytest.mark.slow  # a short 1v1 match with cameras: two robot programs and MuJoCo renderers, about a minute
def test_a_realistic_match_degrades_every_robots_images_and_says_so(tmp_path: Path) -> None:
    result_file, logs = tmp_path / "result.json", tmp_path / "logs"
    done = subprocess.run([sys.executable, "-m", "tafel.tools.cli", "match", "--speed", "max", "--teams", "1v1", "--seconds", "2",
                           "--halves", "1", "--ready-seconds", "1", "--realism", "full", "--seed", "5", "--resolution", "160x120",
                           "--record-dir", str(logs), "--record-reps", "CameraImageTop", "--result", str(result_file)],
                          capture_output=True, text=True, timeout=900, cwd=tmp_path, env={**os.environ, "PYTHONPATH": str(REPO)})
    assert result_file.exists(), done.stdout[-3000:] + done.stderr[-3000:]
    result = json.loads(result_file.read_text())
    assert done.returncode == 0 and result["ended"] == "the game is over", done.stderr[-3000:]
    assert result["realism"] == "full" and ", realism full" in done.stdout
    assert "[match] realism full: every robot's camera pipeline seeded by its own seed (5, 6)" in done.stdout
    assert [robot["seed"] for robot in result["robots"]] == [5, 6]
    for name in ("team1_player1", "team2_player1"):
        reader = LogReader(logs / f"{name}.mcap")
        try:
            images = [fields["image"] for _, _, _, fields in decoded_messages(reader, "CameraImageTop", "cognition")]
        finally:
            reader.close()
        assert len(images) > 50 and images[0].shape == (120, 160, 3)
        shares = [equal_neighbours(image) for image in images]
        assert max(shares) < 0.6, f"{name}: plain renders have about 0.97 of their pixels equal to the next; these {max(shares):.2f}"
