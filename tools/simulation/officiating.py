"""What every part of the simulated GameController (``referee.py``) watches and changes: the match's
robots (``Player``), the calls it announces (``Event``), and ``Officiating``, the base of the referee's
parts (``fouls.py``, ``set_plays.py``, ``shoot_out.py``): the game state, the world it judges from ground
truth, and the few steps they all take (a new state, a robot's team frame, a robot off the carpet).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from tafel.platforms.match_world import MatchWorld, Side
from tafel.representations import field as pitch
from tafel.representations.game import GameState, State

HALF_LINE_X, HALF_LINE_Y = pitch.LENGTH / 2, pitch.WIDTH / 2
#: mm from the centre to the carpet's edge (the rules' 10.4 x 7.4 m): a torso beyond it has left the field
CARPET_X, CARPET_Y = HALF_LINE_X + pitch.BORDER_STRIP, HALF_LINE_Y + pitch.BORDER_STRIP
#: the rules' re-entry point after a standard removal penalty, in the team's frame: level with the own
#: penalty mark, about 0.5 m outside the touchline; another robot there moves it ``RE_ENTRY_STEP`` along the line
RE_ENTRY_X, RE_ENTRY_OUT, RE_ENTRY_STEP = -(HALF_LINE_X - pitch.PENALTY_MARK_DISTANCE), 500.0, 400.0


def in_own_penalty_area(x: float, y: float) -> bool:
    """A point in a team's frame (mm, its own goal at -x) lies in that team's penalty area."""
    return x < -HALF_LINE_X + pitch.PENALTY_AREA_LENGTH and abs(y) < pitch.PENALTY_AREA_WIDTH / 2


def left_the_carpet(x: float, y: float) -> bool:
    """The rules' "Leaving the Field": the torso (world mm) is beyond the carpet, not merely over a line."""
    return abs(x) > CARPET_X or abs(y) > CARPET_Y


@dataclass
class Player:
    """One robot of the match: its team (0 or 1), its number, where it is in the world."""

    team: int
    number: int
    index: int
    side: Side
    penalized_until_s: float = -1.0
    """s when the penalty would end if its time ran all along (-1: not penalized); ``penalty_left_s`` is
    what really counts: it runs in READY and PLAYING only"""
    penalty_left_s: float = 0.0
    returns: int = 0
    return_side: float = 1.0
    """the touchline it goes back to after a penalty, in its team's frame (+1 left, -1 right): the one
    nearest to where it was taken off"""


@dataclass
class Event:
    time_s: float
    what: str


class Officiating:
    """The state the referee's parts share (the ``Referee`` dataclass holds it) and their common steps."""

    world: MatchWorld
    game: GameState
    team_numbers: tuple[int, int]
    players: list[Player]
    events: list[Event]
    phase_since: float
    """s: when the state (or a free kick) began"""
    still_since: float | None

    def enter(self, state: State, now: float) -> None:
        """The game goes into ``state`` at ``now``."""
        self.game.state, self.phase_since, self.still_since = state, now, None
        self.events.append(Event(now, state.name.upper()))

    def team_index(self, number: int) -> int | None:
        return self.team_numbers.index(number) if number in self.team_numbers else None

    def on_field(self) -> list[Player]:
        return [p for p in self.players if p.penalized_until_s < 0]

    def team_pose(self, player: Player) -> tuple[float, float, float]:
        """The robot's torso in its team's field frame (its own goal at -x)."""
        return player.side.to_team(*self.world.robot_pose(player.index))

    def off_the_carpet(self, player: Player) -> None:
        """Take the robot off the carpet, beside its own half, where a penalized robot or a substitute waits."""
        x, y, heading = player.side.to_world(-1000.0 - 500.0 * player.number, -(HALF_LINE_Y + pitch.BORDER_STRIP + 800.0), math.pi / 2)
        self.world.move_robot(player.index, x, y, heading)

    def re_entry(self, player: Player) -> tuple[float, float, float]:
        """Where the rules put ``player`` back after a standard removal penalty (world mm, rad): about 0.5 m
        outside the touchline nearest to where it was taken off, level with its own penalty mark, facing the
        field; further along the touchline, towards the halfway line, while another robot stands there."""
        side, others = player.return_side, [self.world.robot_pose(p.index)[:2] for p in self.on_field() if p is not player]
        x = RE_ENTRY_X
        while True:
            spot = player.side.to_world(x, side * (HALF_LINE_Y + RE_ENTRY_OUT), -side * math.pi / 2)
            if x >= -RE_ENTRY_STEP or all(math.hypot(spot[0] - ox, spot[1] - oy) >= RE_ENTRY_STEP for ox, oy in others):
                return spot
            x += RE_ENTRY_STEP
