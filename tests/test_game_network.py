"""The game's UDP end to end: ``tafel run`` programs hear a GameController, answer it, notice when it is
gone, refuse to send beyond the rules, and hear each other's team messages (real sockets on loopback)."""

from __future__ import annotations

import re
import socket
import struct
import time
from collections.abc import Iterator

import pytest

from tafel.core.framework.manager import Blackboard
from tafel.platforms.network import GAME_SETTINGS, GameNetwork, NetworkSettings
from tafel.representations.game import GameControllerReturn
from tafel.representations.infrastructure import FrameInfo
from tafel.representations.team import OutgoingTeamMessage
from tafel.tools.simulation.match import free_udp_port
from tests.test_debug_server import Program
from tests.test_game_controller import RETURN, packet

pytestmark = pytest.mark.slow


def fields(text: str) -> dict[str, str]:
    """The top-level fields of ``representation:print``."""
    return dict(re.findall(r"^  (\w+): (.*)$", text, re.MULTILINE))


def game_of(program: Program) -> dict[str, str]:
    return fields(program.ask("representation:print GameState"))


def wait_for(condition, seconds: float, what: str) -> None:  # noqa: ANN001 - a callable returning a truth value
    deadline = time.monotonic() + seconds
    while not condition():
        assert time.monotonic() < deadline, f"not within {seconds} s: {what}"
        time.sleep(0.1)


@pytest.fixture
def ports() -> dict[str, int]:
    return {"game_controller_port": free_udp_port(), "return_port": free_udp_port(), "team_port": free_udp_port()}


def robot(ports: dict[str, int], team: int, player: int, *extra: str) -> Program:
    settings = [f"game.{key}={value}" for key, value in ports.items()] + [f"game.team_number={team}", f"game.player_number={player}",
                                                                         'game.network="udp"']
    return Program(*(a for s in settings for a in ("--set", s)), *extra)


@pytest.fixture
def game_controller(ports: dict[str, int]) -> Iterator[socket.socket]:
    """The GameController's side: it sends from a socket that listens for the return packets."""
    sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    sock.bind(("127.0.0.1", ports["return_port"]))
    sock.settimeout(0.05)
    yield sock
    sock.close()


def returns(sock: socket.socket) -> list[bytes]:
    got = []
    while True:
        try:
            got.append(sock.recv(1024))
        except TimeoutError:
            return got


def test_a_robot_hears_its_game_controller_answers_it_and_notices_when_it_is_gone(ports: dict[str, int],
                                                                                  game_controller: socket.socket) -> None:
    program = robot(ports, 12, 3, "--set", "parameters.GameStateProvider.start_state=initial",
                    "--set", "parameters.GameControllerReporter.interval=0.5")
    try:
        assert fields(program.ask("representation:print GameState"))["state"] == "initial"
        target = ("127.0.0.1", ports["game_controller_port"])
        bad = [b"RGme" + bytes(10), packet(version=15), packet(teams=((1, 0, 0, 1, 0, 0, 0, 100), (2, 0, 0, 1, 0, 0, 0, 100)))]
        started, answers = time.monotonic(), []
        while time.monotonic() - started < 4.0:  # a GameController sends twice a second
            game_controller.sendto(packet(state=1, kicking=12), target)
            last_sent = time.monotonic()
            for data in bad:
                game_controller.sendto(data, target)
            answers += returns(game_controller)
            time.sleep(0.45)
        answers += returns(game_controller)
        game = game_of(program)
        assert game["heard"] == "True" and game["state"] == "ready" and game["source"] == "127.0.0.1"
        assert int(game["ignored_packets"]) >= 3 * 7  # every bad packet counted, and the loop went on
        assert 5 <= len(answers) <= 2 * 4 + 1, len(answers)  # at most two a second
        header, version, player, team, *_ = RETURN.unpack(answers[-1])
        assert (header, version, player, team) == (b"RGrt", 4, 3, 12)

        wait_for(lambda: game_of(program)["heard"] == "False", 4.0, "GameState says the GameController is gone")
        assert time.monotonic() - last_sent >= 1.9  # not before 2 s
        game = game_of(program)
        assert game["state"] == "ready" and float(game["seconds_since_packet"]) >= 2.0
        late = returns(game_controller)
        time.sleep(1.2)
        assert returns(game_controller) == [] or late == []  # no answers to a GameController that is gone
    finally:
        program.stop()


def test_teammates_hear_each_other_and_agree_on_one_striker(ports: dict[str, int]) -> None:
    first = robot(ports, 5, 2)
    second = robot(ports, 5, 3)
    try:
        wait_for(lambda: fields(first.ask("representation:print TeamMates"))["received"] != "0"
                 and fields(second.ask("representation:print TeamMates"))["received"] != "0", 10.0, "both hear the other")
        for program, other in ((first, "3"), (second, "2")):
            assert re.search(rf"player: {other}\b", program.ask("representation:print TeamMates"))
        with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as sender:  # junk and a stranger's message on the team port
            sender.setsockopt(socket.SOL_SOCKET, socket.SO_BROADCAST, 1)
            for data in (b"hello", b"TF\x01" + bytes(27)):
                sender.sendto(data, ("127.255.255.255", ports["team_port"]))
        wait_for(lambda: int(fields(first.ask("representation:print TeamMates"))["malformed"]) >= 2, 3.0, "junk counted")

        def roles() -> list[str]:
            return sorted(fields(p.ask("representation:print PlayerRole"))["role"] for p in (first, second))

        wait_for(lambda: roles() == ["striker", "supporter"], 6.0, f"one striker and one supporter, not {roles()}")
        status = first.ask("network:status")
        assert "team 5 player 2" in status and f"team port {ports['team_port']}" in status
    finally:
        first.stop()
        second.stop()


def test_the_network_refuses_what_the_rules_forbid_and_survives_a_taken_port(ports: dict[str, int]) -> None:
    receiver = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    receiver.bind(("127.0.0.1", ports["return_port"]))
    receiver.settimeout(0.2)
    settings = NetworkSettings(team_number=3, player_number=1, broadcast="127.255.255.255", **ports)
    network = GameNetwork(settings)
    network.open()
    try:
        board = Blackboard()
        for rep in (GameControllerReturn, OutgoingTeamMessage, FrameInfo):
            board.ensure(rep)
        board.set(FrameInfo(time_ns=10**9))  # the platform's clock decides the rate, not the wall clock
        board.set(GameControllerReturn(data=b"x" * 32, host="127.0.0.1"))
        board.set(OutgoingTeamMessage(data=b"y" * 129))
        for _ in range(10):  # ten frames within a few milliseconds: two answers, the most in any second
            network.send(board)
        assert returns(receiver) == [b"x" * 32] * 2
        assert (network.returns_sent, network.returns_refused, network.messages_refused, network.messages_sent) == (2, 8, 10, 0)
        board.set(GameControllerReturn(data=b"z", host="no.such.host.invalid"))
        board.set(FrameInfo(time_ns=int(2.5e9)))
        network.send(board)  # cannot be resolved: counted, not raised
        assert network.send_errors == 1
    finally:
        network.close()
        receiver.close()


def test_bad_game_settings_are_clear_errors() -> None:
    from tafel.core.framework.config import ConfigError

    with pytest.raises(ConfigError, match=r"^game.team_number takes a team number from 1 to 254 \(the GameController's\), got 0$"):
        NetworkSettings.from_config({"team_number": 0})
    with pytest.raises(ConfigError, match="unknown keys team; it knows"):
        NetworkSettings.from_config({"team": 3})
    with pytest.raises(ConfigError, match="^game.return_port takes a UDP port from 0 to 65535, got '3939'$"):
        NetworkSettings.from_config({"return_port": "3939"})
    with pytest.raises(ConfigError, match="^game.player_number takes a whole number from 1 to 20, got 21$"):
        NetworkSettings.from_config({"player_number": 21})
    # a string was taken as on, a number as an address: refused now
    with pytest.raises(ConfigError, match="^game.enabled takes on/off or true/false, got 'no'$"):
        NetworkSettings.from_config({"enabled": "no"})
    with pytest.raises(ConfigError, match="^game.broadcast takes an IPv4 address such as 255.255.255.255, got 5$"):
        NetworkSettings.from_config({"broadcast": 5})
    assert set(GAME_SETTINGS) == set(NetworkSettings.__dataclass_fields__)  # every setting is checked
    assert struct.calcsize("<4s4B6f") == 32


def test_sim_button_steps_the_manual_mode_in_a_simulation(ports: dict[str, int]) -> None:
    program = robot(ports, 4, 2, "--platform", "mujoco", "--cameras", "off", "--set", "parameters.GameStateProvider.start_state=initial")
    try:
        def state() -> tuple[str, str, bool]:
            text = program.ask("representation:print GameState")
            return fields(text)["state"], fields(text)["manual"], "penalty: manual" in text

        assert state() == ("initial", "False", False)
        for expected in [("playing", "True", True), ("playing", "True", False), ("playing", "True", True)]:
            assert "chest button pressed" in program.ask("sim:button")
            wait_for(lambda expected=expected: state() == expected, 5.0, f"{expected} after a press, not {state()}")
    finally:
        program.stop()
