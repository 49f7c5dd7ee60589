"""The game as the referee's GameController says it is (``RoboCupGameControlData``, version 18).

The enums' values are the protocol's numbers. Team and player numbers are the protocol's too:
players count from 1.
"""

from __future__ import annotations

import enum
from dataclasses import dataclass, field

from tafel.core import representation

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
