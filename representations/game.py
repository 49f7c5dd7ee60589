"""The game as the referee's GameController says it is, and the bytes its UDP protocol carries.

- ``GameState`` is ``RoboCupGameControlData`` version 18 as this robot understands it. The enums'
  values are the protocol's numbers; team and player numbers are the protocol's too (players count
  from 1).
- ``GameControllerPackets`` (received this frame, from the platform) and ``GameControllerReturn``
  (to send, to the platform) carry the bytes, so a log replays exactly what was heard.
- The ports are the rules' (the platforms open them, the tools listen on them). The codec, bytes to
  ``GameState`` and back, is ``modules/communication/game_controller_codec.py``, beside the modules
  that use it.
"""

from __future__ import annotations

import enum
from dataclasses import dataclass, field

from tafel.core import representation
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


GAME_CONTROLLER_PORT = 3838  # the GameController broadcasts here
RETURN_PORT = 3939  # the robots' return packets go here
