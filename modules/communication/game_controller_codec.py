"""The GameController's UDP protocol as bytes: a plain helper of the communication modules, not a module.

``RoboCupGameControlData`` version 18 (the referee's packets, port 3838) and
``RoboCupGameControlReturnData`` version 4 (the robots' answers, port 3939). Layouts as in
``RoboCupGameControlData.h`` of the GameController: little-endian, no padding. Bytes that are not a
packet of the protocol (wrong header, version or size, values the protocol does not define) raise
``PacketError`` saying what was wrong.

It lives here, beside ``GameStateProvider`` and ``GameControllerReporter`` that use it, rather than in
``representations/game.py``: the representations carry the bytes (``GameControllerPackets``,
``GameControllerReturn``) and the decoded data (``GameState``); the platforms only move the bytes, and
the tools (the simulated referee, ``tafel team``) may import modules.
"""

from __future__ import annotations

import struct
from dataclasses import dataclass

from tafel.core.framework.errors import TafelError
from tafel.representations.game import GamePhase, GameState, Penalty, RobotInfo, SetPlay, State, TeamInfo

HEADER, VERSION = b"RGme", 18
RETURN_HEADER, RETURN_VERSION = b"RGrt", 4
SEND_SLACK_S = 1e-3  # s a sender's interval may come short: frames of 1/30 s add up to a hair under 0.5 s
MAX_PLAYERS = 20  # RobotInfo slots per team in the packet
_GAME = struct.Struct("<4s10Bhh")  # header, version, packetNumber, playersPerTeam, competitionPhase, competitionType,
#                                   gamePhase, state, setPlay, firstHalf, kickingTeam, secsRemaining, secondaryTime
_TEAM = struct.Struct(f"<6BHH{2 * MAX_PLAYERS}B")  # teamNumber, fieldPlayerColour, goalkeeperColour, goalkeeper, score,
#                                                    penaltyShot, singleShots, messageBudget, (penalty, secsTillUnpenalised) x 20
_RETURN = struct.Struct("<4s4B6f")  # header, version, playerNum, teamNum, fallen, pose[3], ballAge, ball[2]
GAME_SIZE = _GAME.size + 2 * _TEAM.size  # 118
RETURN_SIZE = _RETURN.size  # 32


class PacketError(TafelError):
    """Bytes that are not a packet of the protocol; the message says what was wrong."""


def _enum(kind: type, value: int, what: str) -> object:
    try:
        return kind(value)
    except ValueError:
        known = ", ".join(f"{m.value} ({m.name})" for m in kind)  # type: ignore[attr-defined]
        raise PacketError(f"{what} is {value}, which the protocol does not define; it defines {known}") from None


def decode_game_state(data: bytes) -> GameState:
    """A ``RoboCupGameControlData`` packet as a ``GameState`` (``heard`` and this robot's numbers unset)."""
    if len(data) < 4 or data[:4] != HEADER:
        raise PacketError(f"header {bytes(data[:4])!r} is not {HEADER!r}: not a GameController packet")
    if len(data) < 5 or data[4] != VERSION:
        raise PacketError(f"version {data[4] if len(data) > 4 else 'missing'} is not {VERSION}")
    if len(data) != GAME_SIZE:
        raise PacketError(f"{len(data)} bytes; a version {VERSION} packet has {GAME_SIZE}")
    (_, _, packet_number, players_per_team, competition_phase, competition_type, game_phase, state, set_play, first_half,
     kicking_team, secs_remaining, secondary_time) = _GAME.unpack_from(data)
    if players_per_team > MAX_PLAYERS:
        raise PacketError(f"playersPerTeam is {players_per_team}; the packet holds at most {MAX_PLAYERS}")
    teams = []
    for index in range(2):
        values = _TEAM.unpack_from(data, _GAME.size + index * _TEAM.size)
        robots = [RobotInfo(_enum(Penalty, values[8 + 2 * i], f"team {index + 1} player {i + 1}'s penalty"),  # type: ignore[arg-type]
                            values[9 + 2 * i]) for i in range(MAX_PLAYERS)]
        number, field_player_colour, goalkeeper_colour, goalkeeper, score, penalty_shot, single_shots, message_budget = values[:8]
        teams.append(TeamInfo(team_number=number, field_player_colour=field_player_colour, goalkeeper_colour=goalkeeper_colour,
                              goalkeeper=goalkeeper, score=score, penalty_shot=penalty_shot, single_shots=single_shots,
                              message_budget=message_budget, players=robots))
    return GameState(packet_number=packet_number, players_per_team=players_per_team, competition_phase=competition_phase,
                     competition_type=competition_type, game_phase=_enum(GamePhase, game_phase, "gamePhase"),  # type: ignore[arg-type]
                     state=_enum(State, state, "state"), set_play=_enum(SetPlay, set_play, "setPlay"),  # type: ignore[arg-type]
                     first_half=bool(first_half), kicking_team=kicking_team, secs_remaining=secs_remaining,
                     secondary_time=secondary_time, teams=teams)


def encode_game_state(game: GameState) -> bytes:
    """The packet a GameController sends for ``game`` (the simulated GameController sends these)."""
    if len(game.teams) != 2:
        raise PacketError(f"a packet holds two teams, not {len(game.teams)}")
    data = _GAME.pack(HEADER, VERSION, game.packet_number % 256, game.players_per_team, game.competition_phase,
                      game.competition_type, game.game_phase.value, game.state.value, game.set_play.value,
                      int(game.first_half), game.kicking_team, game.secs_remaining, game.secondary_time)
    for team in game.teams:
        robots = (team.players + [RobotInfo()] * MAX_PLAYERS)[:MAX_PLAYERS]
        data += _TEAM.pack(team.team_number, team.field_player_colour, team.goalkeeper_colour, team.goalkeeper, team.score,
                           team.penalty_shot, team.single_shots, team.message_budget,
                           *(v for r in robots for v in (r.penalty.value, r.secs_till_unpenalised)))
    return data


@dataclass(frozen=True)
class ReturnPacket:
    """What a robot tells the GameController: pose (mm, mm, rad; field frame, +x towards the goal its team
    attacks), the ball's age (s, -1: never seen) and position (mm, relative to the robot)."""

    player: int
    team: int
    fallen: bool
    x: float
    y: float
    rotation: float
    ball_age: float
    ball_x: float
    ball_y: float


def encode_return(packet: ReturnPacket) -> bytes:
    return _RETURN.pack(RETURN_HEADER, RETURN_VERSION, packet.player, packet.team, int(packet.fallen), packet.x, packet.y,
                        packet.rotation, packet.ball_age, packet.ball_x, packet.ball_y)


def decode_return(data: bytes) -> ReturnPacket:
    if len(data) != RETURN_SIZE or data[:4] != RETURN_HEADER or data[4] != RETURN_VERSION:
        raise PacketError(f"not a version {RETURN_VERSION} return packet ({RETURN_HEADER!r}, {RETURN_SIZE} bytes): "
                          f"{len(data)} bytes starting {bytes(data[:5])!r}")
    _, _, player, team, fallen, x, y, rotation, ball_age, ball_x, ball_y = _RETURN.unpack(data)
    return ReturnPacket(player, team, bool(fallen), x, y, rotation, ball_age, ball_x, ball_y)
