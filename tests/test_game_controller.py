"""The GameController's packets, built from the published layout (``RoboCupGameControlData.h``, written
out here as ``struct`` formats), never from the code under test."""

from __future__ import annotations

import math
import struct

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from tafel.core.testing import ModuleHarness
from tafel.modules.communication.game_controller_codec import (
    GAME_SIZE,
    PacketError,
    ReturnPacket,
    decode_game_state,
    decode_return,
    encode_game_state,
    encode_return,
)
from tafel.modules.communication.game_controller_reporter import GameControllerReporter
from tafel.modules.communication.game_state_provider import GameStateProvider
from tafel.modules.motion.chest_button_provider import ChestButtonProvider
from tafel.representations.game import (
    Datagram,
    GameControllerPackets,
    GameControllerReturn,
    GamePhase,
    GameState,
    Penalty,
    SetPlay,
    State,
)
from tafel.representations.modeling import BallModel, RobotPose
from tafel.representations.motion import ChestButton, TouchSensorData
from tafel.representations.motion_control import FallState

# the header's layout: "<4s10Bhh", then two teams of "<6BHH40B"; 118 bytes
GAME = struct.Struct("<4s10Bhh")
TEAM = struct.Struct("<6BHH40B")
RETURN = struct.Struct("<4s4B6f")
PENALTIES = [0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 14, 15]


def packet(*, version: int = 18, number: int = 7, players: int = 5, phase: int = 0, state: int = 3, set_play: int = 4,
           first_half: int = 1, kicking: int = 12, remaining: int = 311, secondary: int = -3,
           teams: tuple[tuple[int, ...], ...] = ((12, 1, 3, 1, 2, 0, 0, 1195), (31, 0, 6, 1, 0, 0, 0, 1200)),
           penalties: dict[tuple[int, int], tuple[int, int]] | None = None) -> bytes:
    data = GAME.pack(b"RGme", version, number, players, 1, 0, phase, state, set_play, first_half, kicking, remaining, secondary)
    for t, team in enumerate(teams):
        robots = []
        for p in range(20):
            robots += (penalties or {}).get((t, p), (0, 0))
        data += TEAM.pack(*team, *robots)
    return data


def test_every_field_of_a_packet_is_read() -> None:
    game = decode_game_state(packet(penalties={(0, 2): (6, 25), (1, 0): (15, 0)}))
    assert (game.packet_number, game.players_per_team, game.competition_phase, game.competition_type) == (7, 5, 1, 0)
    assert (game.game_phase, game.state, game.set_play) == (GamePhase.normal, State.playing, SetPlay.kick_in)
    assert game.first_half and game.kicking_team == 12 and game.secs_remaining == 311 and game.secondary_time == -3
    ours, theirs = game.teams
    assert (ours.team_number, ours.field_player_colour, ours.goalkeeper_colour, ours.goalkeeper, ours.score,
            ours.penalty_shot, ours.single_shots, ours.message_budget) == (12, 1, 3, 1, 2, 0, 0, 1195)
    assert theirs.team_number == 31 and theirs.message_budget == 1200 and len(theirs.players) == 20
    assert ours.players[2].penalty is Penalty.leaving_the_field and ours.players[2].secs_till_unpenalised == 25
    assert theirs.players[0].penalty is Penalty.manual
    game.team_number, game.player_number = 12, 3
    assert game.penalized and game.own_player().secs_till_unpenalised == 25 and game.opponent_team().team_number == 31


def test_a_packet_survives_a_round_trip_byte_for_byte() -> None:
    original = packet(penalties={(0, 4): (5, 30), (1, 19): (7, 0)})
    assert len(original) == GAME_SIZE == 118
    assert encode_game_state(decode_game_state(original)) == original


@pytest.mark.parametrize(("data", "message"), [
    (b"", "header b'' is not b'RGme'"),
    (b"RGrt" + bytes(114), "not a GameController packet"),
    (packet(version=17), "version 17 is not 18"),
    (packet()[:-1], "117 bytes; a version 18 packet has 118"),
    (packet() + b"\0", "119 bytes"),
    (packet(state=9), "state is 9, which the protocol does not define; it defines 0 (initial)"),
    (packet(phase=4), "gamePhase is 4"),
    (packet(set_play=6), "setPlay is 6"),
    (packet(penalties={(1, 3): (12, 0)}), "team 2 player 4's penalty is 12"),
    (packet(players=21), "playersPerTeam is 21; the packet holds at most 20"),
])
def test_bad_packets_are_refused_saying_what_was_wrong(data: bytes, message: str) -> None:
    with pytest.raises(PacketError, match=message.replace("(", r"\(").replace(")", r"\)")):
        decode_game_state(data)


@given(st.integers(0, 255), st.integers(0, 20), st.sampled_from([0, 1, 2, 3]), st.sampled_from(range(6)), st.sampled_from(range(6)),
       st.integers(0, 1), st.integers(0, 255), st.integers(-32768, 32767), st.integers(-32768, 32767),
       st.lists(st.tuples(st.sampled_from(PENALTIES), st.integers(0, 255)), min_size=40, max_size=40),
       st.lists(st.integers(0, 65535), min_size=4, max_size=4))
def test_any_valid_packet_round_trips(number: int, players: int, phase: int, state: int, set_play: int, first_half: int,
                                      kicking: int, remaining: int, secondary: int, robots: list[tuple[int, int]],
                                      counts: list[int]) -> None:
    teams = ((1, 0, 1, 1, 3, 0, counts[0], counts[1]), (2, 1, 0, 2, 0, 1, counts[2], counts[3]))
    penalties = {(i // 20, i % 20): robot for i, robot in enumerate(robots)}
    original = packet(number=number, players=players, phase=phase, state=state, set_play=set_play, first_half=first_half,
                      kicking=kicking, remaining=remaining, secondary=secondary, teams=teams, penalties=penalties)
    assert encode_game_state(decode_game_state(original)) == original


def test_return_packets_follow_the_published_layout() -> None:
    sent = ReturnPacket(player=3, team=12, fallen=True, x=-2500.0, y=1200.5, rotation=-1.25, ball_age=0.5, ball_x=800.0, ball_y=-30.0)
    data = encode_return(sent)
    assert len(data) == 32
    assert RETURN.unpack(data) == (b"RGrt", 4, 3, 12, 1, -2500.0, 1200.5, -1.25, 0.5, 800.0, -30.0)
    assert decode_return(RETURN.pack(b"RGrt", 4, 3, 12, 1, -2500.0, 1200.5, -1.25, 0.5, 800.0, -30.0)) == sent
    never = decode_return(RETURN.pack(b"RGrt", 4, 1, 5, 0, 0, 0, 0, -1.0, 0, 0))
    assert never.ball_age == -1.0 and not never.fallen and math.isclose(never.x, 0.0)
    for bad in (data[:-1], b"RGme" + data[4:], data[:4] + b"\x03" + data[5:]):
        with pytest.raises(PacketError, match="not a version 4 return packet"):
            decode_return(bad)


# ----------------------------------------------------------------------------- GameStateProvider
def received(*datagrams: bytes, team: int = 12, player: int = 3, at_ns: int = 0) -> GameControllerPackets:
    return GameControllerPackets(datagrams=[Datagram(data=d, host="10.0.0.9", port=3838, received_ns=at_ns) for d in datagrams],
                                 team_number=team, player_number=player)


def test_the_packet_for_this_team_becomes_the_game_state() -> None:
    harness = ModuleHarness(GameStateProvider, received(packet(penalties={(0, 2): (6, 25)})))
    game = harness.execute()[GameState]
    assert game.heard and not game.manual and game.source == "10.0.0.9" and game.state is State.playing
    assert (game.team_number, game.player_number) == (12, 3)
    assert game.penalized and game.own_player().secs_till_unpenalised == 25 and game.ignored_packets == 0


@pytest.mark.parametrize("bad", [
    b"", b"RGme", b"XXXX" + packet()[4:], packet(version=17), packet() + b"\0", packet()[:-1],
    packet(teams=((1, 0, 0, 1, 0, 0, 0, 100), (2, 0, 0, 1, 0, 0, 0, 100))),  # other teams' game
    packet(state=9),
])
def test_bad_packets_and_other_teams_games_are_ignored_and_counted(bad: bytes) -> None:
    harness = ModuleHarness(GameStateProvider, received(bad), parameters={"start_state": "initial"})
    game = harness.execute()[GameState]
    assert game.ignored_packets == 1 and not game.heard and game.state is State.initial
    harness.set(received(bad, packet(), bad, at_ns=harness.time_ns))  # the good one among them still counts
    game = harness.execute()[GameState]
    assert game.ignored_packets == 3 and game.heard and game.state is State.playing


def test_two_seconds_without_a_packet_say_the_game_controller_is_not_heard_and_the_state_stays() -> None:
    harness = ModuleHarness(GameStateProvider, received(packet(state=1)))
    assert harness.execute()[GameState].heard
    harness.set(received())
    harness.advance(1.9)
    assert harness.blackboard[GameState].heard
    harness.advance(0.2)
    game = harness.blackboard[GameState]
    assert not game.heard and game.seconds_since_packet >= 2.0 and game.state is State.ready


def test_without_a_game_controller_the_chest_button_steps_through_the_manual_mode() -> None:
    harness = ModuleHarness(GameStateProvider, received(), parameters={"start_state": "initial"})
    seen = []
    for presses in range(4):
        harness.set(ChestButton(presses=presses))
        game = harness.execute()[GameState]
        seen.append((game.state, game.penalized, game.manual))
    assert seen == [(State.initial, False, False), (State.playing, True, True), (State.playing, False, True), (State.playing, True, True)]
    harness.set(ChestButton(presses=5))  # two presses between two frames: both count (free, penalized)
    assert harness.execute()[GameState].penalized


def test_the_chest_button_does_nothing_while_a_game_controller_is_heard() -> None:
    harness = ModuleHarness(GameStateProvider, received(packet(state=0)))
    harness.execute()
    harness.set(received(), ChestButton(presses=1))
    game = harness.execute()[GameState]
    assert game.state is State.initial and not game.penalized and not game.manual


def test_an_unknown_start_state_is_an_error_that_lists_the_states() -> None:
    with pytest.raises(ValueError, match="start_state takes one of initial, ready, set, playing, finished, standby, got 'kickoff'"):
        ModuleHarness(GameStateProvider, received(), parameters={"start_state": "kickoff"})  # refused where it is set


def test_chest_presses_are_counted_once_held_long_enough_and_let_go() -> None:
    pressed, free = TouchSensorData(pressed=np.eye(14)[0]), TouchSensorData()
    harness = ModuleHarness(ChestButtonProvider, free)
    harness.feed({TouchSensorData: [pressed, free, free, *[pressed] * 10, free]})  # a 10 ms blip, then 100 ms
    harness.execute(14)
    assert [b.presses for b in harness.history(ChestButton)] == [0] * 13 + [1]


# ------------------------------------------------------------------------ GameControllerReporter
def test_return_packets_carry_the_robot_and_come_at_the_configured_interval() -> None:
    game = GameState(heard=True, source="10.0.0.9", team_number=12, player_number=3)
    pose = RobotPose(valid=True, x=-1200.0, y=300.0, rotation=0.5)
    harness = ModuleHarness(GameControllerReporter, game, pose, BallModel(valid=True, x=800.0, y=-100.0, time_since_seen=0.2),
                            FallState(), parameters={"interval": 0.5})
    harness.execute(61)  # 2 s at 30 Hz
    sent = [r for r in harness.history(GameControllerReturn) if r.data]
    assert len(sent) == 5 and all(r.host == "10.0.0.9" for r in sent)  # at 0, 0.5, 1.0, 1.5 and 2.0 s
    header, version, player, team, fallen, x, y, rotation, age, ball_x, ball_y = RETURN.unpack(sent[0].data)
    assert (header, version, player, team, fallen) == (b"RGrt", 4, 3, 12, 0)
    assert (x, y, ball_x, ball_y) == (-1200.0, 300.0, 800.0, -100.0) and rotation == pytest.approx(0.5)
    assert age == pytest.approx(0.2, abs=1e-6)


def test_no_return_packet_without_a_game_controller_and_ball_age_minus_one_before_a_ball() -> None:
    harness = ModuleHarness(GameControllerReporter, GameState(heard=False, source="10.0.0.9"))
    harness.execute(40)
    assert not any(r.data for r in harness.history(GameControllerReturn))
    harness.set(GameState(heard=True, source="10.0.0.9", team_number=1, player_number=1))
    data = harness.execute()[GameControllerReturn].data
    assert RETURN.unpack(data)[8] == -1.0
