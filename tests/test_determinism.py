"""Determinism, the selling point: equal runs and faithful replays print equal fingerprints and compare
equal in the default set-up, whatever debug clients, recorders or viewers are attached, and runs side
by side on one machine do not hear each other."""

from __future__ import annotations

import os
import re
import subprocess
from pathlib import Path

import pytest

from tafel.core.framework.config import ConfigError
from tafel.core.framework.manager import Blackboard
from tafel.platforms.network import GameNetwork, NetworkSettings
from tafel.representations.game import GameControllerPackets, GameControllerReturn
from tafel.representations.infrastructure import FrameInfo
from tafel.representations.team import IncomingTeamMessages, OutgoingTeamMessage
from tests.test_cli_runtime import REPO, TAFEL

DEFAULTS = ("--debug-port", "0", "--web-port", "0")  # the debug server and the web view, on free ports


def start(*args: str, cwd: Path = REPO) -> subprocess.Popen:
    env = {**os.environ, "PYTHONPATH": str(REPO), "MUJOCO_GL": os.environ.get("MUJOCO_GL", "egl")}
    return subprocess.Popen([*TAFEL, "run", *args], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, cwd=cwd, env=env)


def fingerprint_of(process: subprocess.Popen) -> str:
    out, err = process.communicate(timeout=300)
    assert process.returncode == 0, out + err
    found = re.search(r"^fingerprint ([0-9a-f]{16})", out, re.MULTILINE)
    assert found, out
    return found.group(1)


def compare(first: Path, second: Path, *extra: str) -> subprocess.CompletedProcess:
    return subprocess.run([*TAFEL, "log", "compare", str(first), str(second), *extra], capture_output=True, text=True,
                          timeout=120, cwd=REPO, env={**os.environ, "PYTHONPATH": str(REPO)})


DUMMY = ("--platform", "dummy", "--frames", "500", "--speed", "max", "--seed", "3")


@pytest.mark.slow
def test_equal_runs_print_one_fingerprint_whatever_is_attached(tmp_path: Path) -> None:
    """Debug server, web view, Foxglove and a recording do not change the state; before, each of them did
    (the debug server's timing and drawings were hashed, and the run heard its own team messages over
    the machine's real network, sometimes one frame later)."""
    prints = {
        "defaults": fingerprint_of(start(*DUMMY, *DEFAULTS)),
        "defaults again": fingerprint_of(start(*DUMMY, *DEFAULTS)),
        "recording": fingerprint_of(start(*DUMMY, *DEFAULTS, "--record", str(tmp_path / "a.mcap"))),
        "foxglove": fingerprint_of(start(*DUMMY, *DEFAULTS, "--foxglove", "127.0.0.1:0")),
        "nothing attached": fingerprint_of(start(*DUMMY, "--no-debug")),
    }
    assert len(set(prints.values())) == 1, prints


@pytest.mark.slow
def test_runs_side_by_side_do_not_hear_each_other(tmp_path: Path) -> None:
    """Two runs at once and one alone, all with the default set-up: team messages stay inside each
    simulation, so all three record the same and print the same fingerprint."""
    logs = [tmp_path / f"{name}.mcap" for name in ("first", "second", "alone")]
    both = [start(*DUMMY, *DEFAULTS, "--record", str(log), "--record-reps", "all") for log in logs[:2]]
    prints = [fingerprint_of(process) for process in both]
    prints.append(fingerprint_of(start(*DUMMY, *DEFAULTS, "--record", str(logs[2]), "--record-reps", "all")))
    assert len(set(prints)) == 1, prints
    for other in logs[1:]:
        result = compare(logs[0], other)
        assert result.returncode == 0, result.stdout
        assert "cognition/IncomingTeamMessages" in result.stdout  # the channel that once differed was compared


@pytest.mark.slow
def test_a_faithful_mujoco_replay_compares_equal_with_timing_and_drawings_recorded(tmp_path: Path) -> None:
    """The default recording holds ModuleTimes and DebugDrawings; a replay's timing differs, and that is
    no difference in state: compare exits 0 and says what it left out (--all compares it too)."""
    live, replay = tmp_path / "live.mcap", tmp_path / "replay.mcap"
    first = fingerprint_of(start("--platform", "mujoco", "--seconds", "2", "--speed", "max", "--seed", "2", *DEFAULTS,
                                 "--record", str(live)))
    second = fingerprint_of(start("--platform", "log", "--log", str(live), "--speed", "max", *DEFAULTS, "--record", str(replay)))
    assert first == second
    result = compare(live, replay)
    assert result.returncode == 0, result.stdout
    assert re.search(r"skipped  \w+/ModuleTimes: not compared", result.stdout), result.stdout
    assert compare(live, replay, "--all").returncode == 1  # timing really differs between the two runs


def test_a_simulated_network_echoes_the_own_message_next_frame_and_opens_no_socket() -> None:
    network = GameNetwork(NetworkSettings(), default_mode="simulated")
    network.open()
    assert network.team is None and network.game_controller is None
    board = Blackboard()
    for rep in (FrameInfo, OutgoingTeamMessage, IncomingTeamMessages, GameControllerPackets, GameControllerReturn):
        board.ensure(rep)
    board.set(FrameInfo(frame_number=1, time_ns=10))
    board.set(OutgoingTeamMessage(data=b"hello"))
    network.send(board)
    network.receive(board, 20)
    assert [d.data for d in board[IncomingTeamMessages].datagrams] == [b"hello"]
    network.receive(board, 30)
    assert board[IncomingTeamMessages].datagrams == []  # heard once
    assert "simulated network" in network.status()
    assert not GameNetwork(NetworkSettings(network="udp"), default_mode="simulated").simulated


def test_an_unknown_network_mode_is_a_clear_error() -> None:
    with pytest.raises(ConfigError, match="^game.network takes one of auto, udp, simulated, got 'tcp'$"):
        NetworkSettings.from_config({"network": "tcp"})
