"""The command line starts fast: each subcommand imports only what it uses.

``tafel console -c CMD`` once took 5 s on a cold cache because building the parser imported MuJoCo
and the match code. Each check runs in a fresh interpreter and looks at ``sys.modules`` afterwards.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parent.parent
SMALL_LOG = REPO / "tests" / "data" / "ball_situation.mcap"
#: what no light command may import: the simulators, OpenCV, Ray and the match and scenario code
HEAVY = ("mujoco", "pybullet", "cv2", "ray", "tafel.platforms.match_world", "tafel.platforms.match_robot",
         "tafel.platforms.mujoco_sim", "tafel.platforms.pybullet_sim", "tafel.tools.simulation.match", "tafel.tools.simulation.referee",
         "tafel.tools.simulation.officiating", "tafel.tools.simulation.fouls", "tafel.tools.simulation.set_plays",
         "tafel.tools.simulation.shoot_out",
         "tafel.tools.simulation.scenarios", "tafel.tools.simulation.scenario_file", "tafel.tools.simulation.scenario_predicates", "tafel.tools.simulation.replay_batch")

PROBE = """
import contextlib, io, json, sys
from tafel.tools.cli import main
out = io.StringIO()
with contextlib.redirect_stdout(out), contextlib.redirect_stderr(io.StringIO()):
    try:
        status = main(sys.argv[1:])
    except SystemExit as exc:
        status = exc.code
print(json.dumps({"status": status, "modules": sorted(sys.modules), "out": out.getvalue()}))
"""


def imported_by(*argv: str) -> dict:
    """Run ``tafel ARGV`` in a fresh interpreter; its exit status, output and every module it imported."""
    result = subprocess.run([sys.executable, "-c", PROBE, *argv], capture_output=True, text=True, timeout=120, cwd=REPO,
                            env={**os.environ, "PYTHONPATH": str(REPO)})
    assert result.returncode == 0, result.stderr
    return json.loads(result.stdout.splitlines()[-1])


def heavy_in(modules: list[str]) -> list[str]:
    return sorted(m for m in modules if any(m == h or m.startswith(h + ".") for h in HEAVY))


@pytest.mark.parametrize("argv", [
    ["--help"],
    ["console", "--port", "1", "-c", "help"],  # nobody listens on port 1: the console fails at once
    ["log", "info", str(SMALL_LOG)],
    ["match", "--help"],                       # even the match command's help needs no simulator
    ["scenarios", "--help"],
])
def test_light_commands_import_no_simulator_and_no_match_code(argv: list[str]) -> None:
    probe = imported_by(*argv)
    assert probe["status"] in (0, 2), probe["out"]  # 2: the console found no server, as it should
    assert heavy_in(probe["modules"]) == []


def test_log_info_still_reads_the_log() -> None:
    probe = imported_by("log", "info", str(SMALL_LOG))
    assert probe["status"] == 0
    assert "BallPercept" in probe["out"]


def test_every_subcommand_is_still_registered() -> None:
    probe = imported_by("--help")
    assert probe["status"] == 0
    for command in ("run", "view", "platforms", "modules", "log", "console", "match", "scenarios", "replay-batch"):
        assert command in probe["out"]


def test_help_imports_the_code_of_no_subcommand() -> None:
    """``tafel --help`` builds every subcommand's parser but loads none of the code that runs one: not the
    launch of a run, not the viewers, log tools or deploy, not the debug server."""
    probe = imported_by("--help")
    assert probe["status"] == 0
    code = ("tafel.tools.launch.run", "tafel.tools.launch.program", "tafel.tools.launch.servers", "tafel.tools.cli.listing",
            "tafel.tools.viewers", "tafel.tools.logs", "tafel.tools.robot", "tafel.debug")
    loaded = [m for m in probe["modules"] if any(m == c or m.startswith(c + ".") for c in code)]
    assert loaded == []


def test_every_subcommand_names_code_that_exists() -> None:
    """``COMMANDS`` names each subcommand's code by module and function, imported only when it runs: a
    misspelt name would surface only then, so each is looked up here."""
    from tafel.tools.cli.dispatch import COMMANDS, LazyCommand, build_parser

    parser_commands = set(build_parser()._subparsers._group_actions[0].choices)  # type: ignore[union-attr]
    assert set(COMMANDS) == parser_commands
    lazy = [command for command in COMMANDS.values() if isinstance(command, LazyCommand)]
    assert len(lazy) == len(COMMANDS) - 1  # view rewrites its arguments into run's
    for command in lazy:
        assert callable(command.target()), command
