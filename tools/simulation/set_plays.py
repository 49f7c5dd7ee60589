"""The set plays of the simulated GameController (``referee.py``): the kick-off's restriction, the free
kicks it calls when the ball goes out, and the ones it is told to call.

- the ball out: over a touchline, a kick-in for the other team where it went out; over a goal line, a
  goal kick (from the goal area's corner) or a corner kick, by who touched it last (the nearest robot).
  A free kick ends when the kicking team touches the ball or after 30 s; a goal straight from it
  (indirect) does not count;
- a pushing free kick for the pushed team, the ball left where it is, when the pusher's torso was within
  ``PUSHING_NEAR_BALL`` of the ball (the rules; not while a free kick runs; a push into the pusher's own
  penalty area would be a penalty kick, which this referee does not run: the pusher's penalty alone);
- set plays the referee calls when told (``calls``, for drills and tests: a kick-in, goal kick, corner
  kick or pushing free kick for a team at a given time, once PLAYING; the ball placed as the set play
  places it).

Each set play that keeps the defending team away (the opponents' kick-off: out of the centre circle; a
free kick: 0.75 m from the ball) is a ``Restriction`` with the nearest any defender came while it lasted;
``fouls.py`` calls the fouls of those who came too near.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from tafel.representations import field as pitch
from tafel.representations.game import GamePhase, SetPlay, State
from tafel.tools.simulation.fouls import Fouls, Push
from tafel.tools.simulation.officiating import HALF_LINE_X, HALF_LINE_Y, Event, in_own_penalty_area

KICK_OFF_S, FREE_KICK_S = 10.0, 30.0  # s: the rules
FREE_KICKS = (SetPlay.goal_kick, SetPlay.pushing_free_kick, SetPlay.corner_kick, SetPlay.kick_in)
PUSHING_NEAR_BALL = 500.0  # mm from the pusher's torso to the ball: the rules' "approximately 0.5 m"


@dataclass
class Call:
    """A set play the referee calls at ``time_s`` s of the match (once PLAYING) for team number ``team``."""

    time_s: float
    set_play: SetPlay
    team: int


@dataclass
class Restriction:
    """A set play that keeps the defending team away while it lasts: the opponents' kick-off (out of the
    centre circle) or a free kick (0.75 m from the ball). ``nearest_mm``: the nearest any defender's torso
    came to the centre spot or the ball while it lasted, and who (a free kick's fouls are called only after
    ``free_kick_grace_s``, to leave the ball); ``nearest_at_start_mm``: how near the nearest one was when
    it began."""

    start_s: float
    set_play: str
    kicking_team: int
    end_s: float = -1.0
    ended: str = ""
    nearest_mm: float = math.inf
    nearest_player: int = 0
    nearest_at_start_mm: float = math.inf


class SetPlays(Fouls):
    """The referee's part that runs the set plays (its state is the ``Referee``'s)."""

    free_kick_grace_s: float
    calls: list[Call]
    restrictions: list[Restriction]
    restriction: Restriction | None
    """the one going on"""
    set_play_touched: bool
    """the kicking team touched the ball since the set play began"""
    indirect: bool
    """the ball was last played from an own free kick and nobody else touched it since"""
    kicker: int | None
    """index of the robot that took the free kick"""
    last_touch: int
    """the team that touched the ball last"""
    last_toucher: int | None
    kick_off_defender: int | None
    """team index defending the kick-off under way"""
    kick_off_ball_moved: bool

    def enter(self, state: State, now: float) -> None:
        """A new state ends the set play going on."""
        super().enter(state, now)
        self.lift(now, state.name.upper())

    def start_kick_off(self, now: float) -> None:
        """PLAYING begins with the kicking team's kick-off: the other team keeps out of the centre circle."""
        kicking = self.team_index(self.game.kicking_team)
        self.kick_off_defender = None if kicking is None else 1 - kicking
        self.kick_off_ball_moved = False
        self.last_touch_s = now
        if kicking is not None:
            self.restrict("kick_off", kicking, now)

    def free_kick_clock(self, now: float) -> None:
        """A free kick ends when the kicking team touched the ball or after ``FREE_KICK_S``; until then
        the packet's ``secondary_time`` counts it down."""
        if self.game.set_play is not SetPlay.none and (now - self.phase_since > FREE_KICK_S or self.set_play_touched):
            self.game.set_play, self.game.secondary_time = SetPlay.none, 0
            self.lift(now, "touched" if self.set_play_touched else f"{FREE_KICK_S:g} s")
        elif self.game.set_play is not SetPlay.none:
            self.game.secondary_time = max(0, int(math.ceil(FREE_KICK_S - (now - self.phase_since) - 1e-6)))

    def ball_out(self, bx: float, by: float, now: float) -> None:
        """Put the ball back as the rules' set plays do, for the team that did not touch it last."""
        kicking = 1 - self.last_touch
        if abs(by) > HALF_LINE_Y + pitch.BALL_RADIUS:
            play = SetPlay.kick_in
        else:
            defending = 1 if bx > 0 else 0  # the team whose goal line it crossed
            play = SetPlay.goal_kick if kicking == defending else SetPlay.corner_kick
        self.start_set_play(play, kicking, *self.set_play_spot(play, kicking, bx, by), now)

    def judge_pushing(self, now: float, bx: float, by: float) -> Push | None:
        """Pushing (``Fouls``), and the pushing free kick it brings near the ball (the module's docstring)."""
        push = super().judge_pushing(now, bx, by)
        if push is None or self.game.set_play is not SetPlay.none or self.game.game_phase is GamePhase.penalty_shoot:
            return push
        near_ball = math.hypot(push.pusher_at[0] - bx, push.pusher_at[1] - by) <= PUSHING_NEAR_BALL
        if near_ball and not in_own_penalty_area(*push.pusher.side.to_team(*push.pushed_at)[:2]):
            self.start_set_play(SetPlay.pushing_free_kick, push.pushed.team, bx, by, now)
        return push

    def take_call(self, bx: float, by: float, now: float) -> None:
        """The first of ``calls`` is due: start its set play, the ball last at (bx, by)."""
        call = self.calls.pop(0)
        kicking = self.team_index(call.team)
        if kicking is not None:
            self.start_set_play(call.set_play, kicking, *self.set_play_spot(call.set_play, kicking, bx, by), now)

    @staticmethod
    def set_play_spot(play: SetPlay, kicking: int, bx: float, by: float) -> tuple[float, float]:
        """Where the rules put the ball (world mm) for a free kick of team index ``kicking`` (the first team
        attacks +x), the ball last at (bx, by): a kick-in on the touchline beside it, a goal kick on the
        corner of the kicking team's goal area, a corner kick in the corner of the goal it attacks, a
        pushing free kick where it is."""
        side = 1.0 if kicking == 0 else -1.0  # the goal the kicking team attacks
        if play is SetPlay.kick_in:
            return max(-HALF_LINE_X + 100.0, min(HALF_LINE_X - 100.0, bx)), math.copysign(HALF_LINE_Y - 50.0, by)
        if play is SetPlay.goal_kick:
            return -side * (HALF_LINE_X - pitch.GOAL_AREA_LENGTH), math.copysign(pitch.GOAL_AREA_WIDTH / 2, by)
        if play is SetPlay.corner_kick:
            return side * (HALF_LINE_X - 50.0), math.copysign(HALF_LINE_Y - 50.0, by)
        return bx, by

    def start_set_play(self, play: SetPlay, kicking: int, x: float, y: float, now: float) -> None:
        """A free kick for team index ``kicking`` with the ball put at (x, y) world mm."""
        self.world.move_ball(x, y)
        self.game.set_play, self.game.kicking_team, self.game.secondary_time = play, self.team_numbers[kicking], int(FREE_KICK_S)
        self.phase_since, self.set_play_touched, self.indirect, self.kicker = now, False, False, None
        self.kick_off_defender = None
        self.events.append(Event(now, f"{play.name.upper()} {self.team_numbers[kicking]}"))
        self.lift(now, play.name)
        self.restrict(play.name, kicking, now)

    def restrict(self, set_play: str, kicking: int, now: float) -> None:
        """A set play keeps team index ``1 - kicking`` away from now on: note how near its robots are."""
        self.restriction = Restriction(now, set_play, self.team_numbers[kicking])
        self.restrictions.append(self.restriction)
        self.restriction.nearest_at_start_mm = min((d for d, _ in self.defenders_near()), default=math.inf)

    def lift(self, now: float, why: str) -> None:
        """The set play that kept the defenders away is over (``why``)."""
        if self.restriction is not None:
            self.restriction.end_s, self.restriction.ended, self.restriction = now, why, None

    def watch_restriction(self, now: float) -> None:
        """In PLAYING: end the kick-off's restriction once the ball moved or ``KICK_OFF_S`` passed, and note
        how near the defenders come while a restriction lasts."""
        bx, by = self.world.ball_position()
        if self.kick_off_defender is not None and (now - self.phase_since >= KICK_OFF_S or self.kick_off_ball_moved
                                                   or math.hypot(bx, by) > 200.0):
            self.kick_off_defender = None
            self.lift(now, f"{KICK_OFF_S:g} s" if now - self.phase_since >= KICK_OFF_S else "ball moved")
        restriction = self.restriction
        if restriction is not None:
            for distance, number in self.defenders_near():
                if distance < restriction.nearest_mm:
                    restriction.nearest_mm, restriction.nearest_player = distance, number

    def free_kick_kept(self, now: float) -> bool:
        """Whether the kicking team's opponents must now be 0.75 m from the ball: a free kick not yet taken,
        ``free_kick_grace_s`` after it began."""
        return self.game.set_play is not SetPlay.none and not self.set_play_touched and now - self.phase_since >= self.free_kick_grace_s

    def defenders_near(self) -> list[tuple[float, int]]:
        """(mm, player number) of every robot of the team the restriction going on keeps away, from what it
        keeps them from: the centre spot at a kick-off, the ball at a free kick."""
        if self.restriction is None:
            return []
        kicking = self.team_index(self.restriction.kicking_team)
        tx, ty = (0.0, 0.0) if self.restriction.set_play == "kick_off" else self.world.ball_position()
        return [(math.hypot(x - tx, y - ty), p.number) for p in self.on_field() if p.team != kicking
                for x, y, _ in [self.world.robot_pose(p.index)]]

    def note_touch(self, now: float) -> None:
        """The robot nearest the ball touches it when near enough: who played it last, whether the free
        kick was taken, and whether the ball is still on its way from it (indirect)."""
        bx, by = self.world.ball_position()
        near = [(math.hypot(bx - x, by - y), p) for p in self.on_field() for x, y, _ in [self.world.robot_pose(p.index)]]
        distance, player = min(near, key=lambda item: item[0], default=(math.inf, None))
        if player is None or distance >= 250.0:
            return
        self.last_touch, self.last_toucher, self.last_touch_s = player.team, player.index, now
        if self.kick_off_defender is not None and math.hypot(bx, by) > 200.0:
            self.kick_off_ball_moved = True
        kicking = self.team_index(self.game.kicking_team)
        if self.game.set_play in FREE_KICKS:
            if player.team == kicking and not self.set_play_touched:
                self.set_play_touched, self.indirect, self.kicker = True, True, player.index
        elif self.indirect and player.index != self.kicker:
            self.indirect = False
