"""The game as the referee's GameController says it is, and the GameController's UDP protocol.

- ``GameState`` is ``RoboCupGameControlData`` version 18 as this robot understands it. The enums'
  values are the protocol's numbers; team and player numbers are the protocol's too (players count
  from 1).
- ``GameControllerPackets`` (received this frame, from the platform) and ``GameControllerReturn``
  (to send, to the platform) carry the bytes, so a log replays exactly what was heard.
- The codec: ``RoboCupGameControlData`` version 18 (the referee's packets, port 3838) and
  ``RoboCupGameControlReturnData`` version 4 (the robots' answers, port 3939). Layouts as in
  ``RoboCupGameControlData.h`` of the GameController: little-endian, no padding. Bytes that are not a
  packet of the protocol (wrong header, version or size, values the protocol does not define) raise
  ``PacketError`` saying what was wrong.
"""

from __future__ import annotations

import enum
import struct
from dataclasses import dataclass, field

from tafel.core import representation
from tafel.core.framework.errors import TafelError
from tafel.core.framework.representation import counter

NO_TEAM = 255  # ``kicking_team`` when no team kicks


class State(enum.Enum):
    initial = 0
    ready = 1
    set = 2
    playing = 3
    finished = 4
    standby = 5


class GamePhase(enum.Enum):
    normal = 0
    penalty_shoot = 1
    overtime = 2
    timeout = 3


class SetPlay(enum.Enum):
    none = 0
    goal_kick = 1
    pushing_free_kick = 2
    corner_kick = 3
    kick_in = 4
    penalty_kick = 5


class Penalty(enum.Enum):
    none = 0
    illegal_ball_contact = 1
    player_pushing = 2
    illegal_motion_in_set = 3
    inactive_player = 4
    illegal_position = 5
    leaving_the_field = 6
    request_for_pickup = 7
    local_game_stuck = 8
    illegal_position_in_set = 9
    player_stance = 10
    illegal_motion_in_standby = 11
    substitute = 14
    manual = 15


@dataclass
class RobotInfo:
    """One player as the GameController sees it; ``secs_till_unpenalised`` in s."""

    penalty: Penalty = Penalty.none
    secs_till_unpenalised: int = 0


@dataclass
class TeamInfo:
    """One team: its number, jersey colours, goalkeeper's player number, score, penalty shots, and the
    team messages it may still send (``message_budget``)."""

    team_number: int = 0
    field_player_colour: int = 0
    goalkeeper_colour: int = 0
    goalkeeper: int = 1
    score: int = 0
    penalty_shot: int = 0
    single_shots: int = 0
    message_budget: int = 0
    players: list[RobotInfo] = field(default_factory=list)


@representation
class GameState:
    """What the GameController last said, and whether it is heard (a packet for this team within 2 s).

    ``secs_remaining`` and ``secondary_time`` are in s; ``teams`` holds both teams in the packet's
    order; ``team_number`` and ``player_number`` are this robot's (from configuration).
    """

    heard: bool = False
    seconds_since_packet: float = 0.0
    manual: bool = False
    """the state comes from the chest button (the rules' manual mode), not from a GameController"""
    ignored_packets: int = counter()
    """packets ignored so far: not the protocol, or for other teams"""
    source: str = ""
    """the address of the GameController last heard"""
    packet_number: int = 0
    players_per_team: int = 0
    competition_phase: int = 0
    competition_type: int = 0
    game_phase: GamePhase = GamePhase.normal
    state: State = State.initial
    set_play: SetPlay = SetPlay.none
    first_half: bool = True
    kicking_team: int = NO_TEAM
    secs_remaining: int = 0
    secondary_time: int = 0
    teams: list[TeamInfo] = field(default_factory=list)
    team_number: int = 0
    player_number: int = 0

    def own_team(self) -> TeamInfo | None:
        return next((team for team in self.teams if team.team_number == self.team_number), None)

    def opponent_team(self) -> TeamInfo | None:
        return next((team for team in self.teams if team.team_number != self.team_number), None)

    def own_player(self) -> RobotInfo | None:
        team = self.own_team()
        if team is None or not 1 <= self.player_number <= len(team.players):
            return None
        return team.players[self.player_number - 1]

    @property
    def penalized(self) -> bool:
        player = self.own_player()
        return player is not None and player.penalty is not Penalty.none

    def status_text(self) -> str:
        """One phrase for the status line: the state, the score, who says so."""
        own, other = self.own_team(), self.opponent_team()
        score = f" {own.score}:{other.score}" if own is not None and other is not None else ""
        source = "manual" if self.manual else "GameController" if self.heard else "no GameController"
        return f"{self.state.name.upper()}{' penalized' if self.penalized else ''}{score} ({source})"


@dataclass
class Datagram:
    """One UDP datagram as received: its bytes, the sender's address and port, and when (ns, program clock)."""

    data: bytes = b""
    host: str = ""
    port: int = 0
    received_ns: int = 0


@representation
class GameControllerPackets:
    """What arrived on the GameController port (3838) since the last cognition frame (platform), and who
    this robot is: its team and player number, from the ``[game]`` table of the configuration."""

    datagrams: list[Datagram]
    team_number: int = 0
    player_number: int = 0


@representation
class GameControllerReturn:
    """A return packet to send this frame (``data`` empty: none) to ``host`` on port 3939."""

    data: bytes = b""
    host: str = ""


GAME_CONTROLLER_PORT = 3838
RETURN_PORT = 3939
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
        teams.append(TeamInfo(*values[:8], players=robots))
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
