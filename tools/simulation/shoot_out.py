"""The penalty shoot-out of the simulated GameController (``referee.py``), as GameController3 runs it
(``shoot_out``: after a tied game, after any game, or alone).

The game phase PENALTYSHOOT, every robot a substitute (penalty 14) but the kicking team's striker, on
the edge of the penalty area facing the ball on the penalty mark, and the defending team's keeper (its
lowest player number), on its goal line in the goal's centre; SET, then PLAYING with the shot's
``PENALTY_SHOT_S`` on the clock (``secs_remaining``). A shot ends with a goal (the team's score and its
bit in ``single_shots``), when the ball stops or leaves the field after the kick, or when the time is up;
then FINISHED, and the other team kicks. ``penalty_shots`` each (the rules: three), then sudden death, at
most ``sudden_death_shots`` each, while both teams can still win, as GameController3 decides it. Each
team shoots at the goal it attacked in the game (the robots' frames stay as they were; GameController3
takes every shot at one goal and swaps the sides in its packet instead, which comes to the same for the
robots). Team messages are not counted and fouls are not called in the shoot-out. Every penalty shot is
a ``Shot``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from tafel.platforms.match_world import Side
from tafel.representations import field as pitch
from tafel.representations.game import GamePhase, Penalty, SetPlay, State
from tafel.tools.simulation.officiating import HALF_LINE_X, HALF_LINE_Y, Event, Officiating, Player

#: GameController3 (champions_cup) and the rules: a penalty shot's time (s), shots per team, sudden-death shots per team
PENALTY_SHOT_S, PENALTY_SHOTS, SUDDEN_DEATH_SHOTS = 30.0, 3, 3
#: when there is a penalty shoot-out: never, after a tied game (knock-out games), after any game
#: (GameController3's test option), or the shoot-out alone
SHOOT_OUT = ("never", "tie", "always", "only")
SHOOT_OUT_AFTER_GAME_S = 4.0  # s of the shoot-out's INITIAL after a game: the robots stand up from sitting, then are placed
KEEPER_FROM_GOAL_LINE = 100.0  # mm: the keeper's torso in front of the goal line's centre (its feet on the line)
SHOT_KICKED = 100.0  # mm the ball moved from the penalty mark: the striker kicked
SHOT_STOPPED, SHOT_STOPPED_S = 20.0, 1.0  # the ball moved at most this many mm in this many s: it stopped
SHOT_TOUCH = 200.0  # mm from the keeper's torso to the ball: the keeper touched it


@dataclass
class Shot:
    """A penalty shot: when it ended (s), the kicking team's number, its striker's and the keeper's player
    numbers (0: none), the outcome (goal; saved: the keeper touched the ball; missed: the ball stopped or
    left the field; time: not kicked within the shot's time), and whether it was a sudden-death shot."""

    time_s: float
    team: int
    striker: int
    keeper: int
    outcome: str = ""
    sudden_death: bool = False


class ShootOut(Officiating):
    """The referee's part that runs the penalty shoot-out (its state is the ``Referee``'s)."""

    shoot_out: str
    """one of ``SHOOT_OUT``"""
    set_s: float
    penalty_shots: int
    sudden_death_shots: int
    shots: list[Shot]
    clock: float
    """s of this half's playing time left, or of the shot's"""
    over: bool
    illegal_communication: list[bool]
    shoot_out_initial_s: float
    shoot_out_goals: list[int]
    winner: int | None
    """the shoot-out's winner (team number)"""
    shot: Shot | None
    """the penalty shot going on"""
    mark: tuple[float, float]
    """world mm: the penalty mark of the shot going on"""
    kicked: bool
    keeper_touched: bool
    ball_track: list[tuple[float, float, float]]
    """(s, world mm, mm): the ball in the shot's last second"""

    def shoot_out_follows(self) -> bool:
        """Whether a shoot-out follows the game that just ended (``shoot_out`` always, or tie and a tie)."""
        return self.shoot_out == "always" or (self.shoot_out == "tie" and self.game.teams[0].score == self.game.teams[1].score)

    def start_shoot_out(self, now: float) -> None:
        """GameController3's StartPenaltyShootout: the phase PENALTYSHOOT in INITIAL, every robot a substitute,
        the first team to kick first, the clocks stopped. The robots stay where they are until the first shot."""
        game = self.game
        game.game_phase, game.first_half, game.set_play = GamePhase.penalty_shoot, False, SetPlay.none
        game.kicking_team, game.secondary_time, self.clock = self.team_numbers[0], 0, 0.0
        for team in game.teams:
            team.penalty_shot, team.single_shots = 0, 0
        self.substitute_all(move=False)
        self.events.append(Event(now, "PENALTY SHOOT-OUT"))
        self.enter(State.initial, now)

    def substitute_all(self, move: bool = True) -> None:
        """Every robot a substitute, waiting off the carpet (as a penalized robot does) when ``move``."""
        for player in self.players:
            robot = self.game.teams[player.team].players[player.number - 1]
            robot.penalty, robot.secs_till_unpenalised = Penalty.substitute, 0
            player.penalized_until_s, player.penalty_left_s = math.inf, 0.0
            if move:
                self.off_the_carpet(player)
        for team in self.game.teams:
            team.goalkeeper = 0

    def shoot_out_tick(self, now: float, dt: float) -> None:
        """The shoot-out's states: INITIAL, then per shot SET (placed), PLAYING (the shot) and FINISHED."""
        state, since = self.game.state, now - self.phase_since
        if state is State.initial and since >= self.shoot_out_initial_s:
            self.next_shot(now)
        elif state is State.set and since >= self.set_s:
            self.enter(State.playing, now)  # GameController3's FreePenaltyShot
            self.kicked = self.keeper_touched = False
            self.ball_track = []
            if self.shot is not None and not self.shot.striker:
                self.end_shot("time", now)  # nobody to kick
        elif state is State.playing:
            self.judge_shot(now, dt)
        elif state is State.finished and since >= 2.0:
            if self.another_shot():
                self.next_shot(now)
            else:
                self.over = True

    def shoot_out_players(self, team: int) -> list[Player]:
        return sorted((p for p in self.players if p.team == team), key=lambda p: p.number)

    def next_shot(self, now: float) -> None:
        """GameController3's SelectPenaltyShotPlayer for both teams, then WaitForPenaltyShot: after a shot the
        other team kicks; its striker (its field players in turn, player 1 only when alone) stands on the
        edge of the penalty area facing the ball on the penalty mark, the other team's keeper (its lowest
        number, in the goalkeeper's jersey) on its goal line; the rest are substitutes. SET, with the shot's
        time on the clock."""
        game = self.game
        if game.state is State.finished:
            game.kicking_team = self.team_numbers[1 - self.team_numbers.index(game.kicking_team)]
        kicking = self.team_numbers.index(game.kicking_team)
        self.substitute_all()
        team = game.teams[kicking]
        squad = self.shoot_out_players(kicking)
        strikers = squad[1:] or squad
        striker = strikers[team.penalty_shot % len(strikers)] if strikers else None
        keepers = self.shoot_out_players(1 - kicking)
        keeper = keepers[0] if keepers else None
        attacking = Side(1.0 if kicking == 0 else -1.0)  # the first team attacks +x
        self.mark = attacking.to_world(HALF_LINE_X - pitch.PENALTY_MARK_DISTANCE, 0.0)[:2]
        self.world.move_ball(*self.mark)
        for player, (x, y) in ((striker, (HALF_LINE_X - pitch.PENALTY_AREA_LENGTH, 0.0)),
                               (keeper, (-HALF_LINE_X + KEEPER_FROM_GOAL_LINE, 0.0))):
            if player is None:
                continue
            robot = game.teams[player.team].players[player.number - 1]
            robot.penalty, player.penalized_until_s = Penalty.none, -1.0
            self.world.move_robot(player.index, *player.side.to_world(x, y, 0.0))
        # the packet's goalkeeper: the one chosen as such, else (as GameController3 encodes it) the first substitute
        for index, chosen in ((kicking, None), (1 - kicking, keeper)):
            substitutes = [p.number for p in self.shoot_out_players(index) if p.penalized_until_s >= 0]
            game.teams[index].goalkeeper = chosen.number if chosen is not None else min(substitutes, default=0)
        team.penalty_shot += 1
        self.shot = Shot(now, game.kicking_team, striker.number if striker else 0, keeper.number if keeper else 0,
                         sudden_death=team.penalty_shot > self.penalty_shots)
        self.clock = PENALTY_SHOT_S
        self.enter(State.set, now)

    def judge_shot(self, now: float, dt: float) -> None:
        """A penalty shot in PLAYING, from the ball's ground truth: a goal, saved or missed once the ball stops
        or leaves the field after the kick, or the time up."""
        self.clock = max(0.0, self.clock - dt)
        bx, by = self.world.ball_position()
        kicking = self.team_numbers.index(self.game.kicking_team)
        attacked = 1 if kicking == 0 else -1
        self.kicked = self.kicked or math.hypot(bx - self.mark[0], by - self.mark[1]) > SHOT_KICKED
        keeper = self.shot.keeper if self.shot is not None else 0
        for player in self.on_field():
            x, y, _ = self.world.robot_pose(player.index)
            if player.team != kicking and player.number == keeper and self.kicked and math.hypot(bx - x, by - y) < SHOT_TOUCH:
                self.keeper_touched = True
        self.ball_track = [*(sample for sample in self.ball_track if now - sample[0] <= SHOT_STOPPED_S), (now, bx, by)]
        stopped = (self.kicked and now - self.ball_track[0][0] >= SHOT_STOPPED_S - 1e-6
                   and all(math.hypot(bx - x, by - y) < SHOT_STOPPED for _, x, y in self.ball_track))
        out = abs(bx) > HALF_LINE_X + pitch.BALL_RADIUS or abs(by) > HALF_LINE_Y + pitch.BALL_RADIUS
        if pitch.goal_of(bx, by) == attacked:
            self.end_shot("goal", now)
        elif out or stopped or self.clock <= 0.0:
            self.end_shot("saved" if self.keeper_touched else "missed" if self.kicked else "time", now)

    def end_shot(self, outcome: str, now: float) -> None:
        """GameController3's Goal (in the shoot-out) or FinishPenaltyShot: the outcome, then FINISHED."""
        kicking = self.team_numbers.index(self.game.kicking_team)
        team = self.game.teams[kicking]
        if outcome == "goal":
            team.single_shots |= 1 << (team.penalty_shot - 1)
            if not self.illegal_communication[kicking]:
                team.score += 1
                self.shoot_out_goals[kicking] += 1
        shot = self.shot or Shot(now, self.game.kicking_team, 0, 0)
        shot.time_s, shot.outcome = now, outcome
        self.shots.append(shot)
        self.shot = None
        self.events.append(Event(now, f"PENALTY SHOT {len(self.shots)} team {shot.team} player {shot.striker}: {outcome.upper()}"))
        self.enter(State.finished, now)
        if not self.another_shot():
            first, second = self.shoot_out_goals
            self.winner = self.team_numbers[0] if first > second else self.team_numbers[1] if second > first else None
            decided = f"team {self.winner} wins" if self.winner is not None else "undecided (the rules: a coin toss)"
            self.events.append(Event(now, f"SHOOT-OUT OVER {first}:{second}, {decided}"))

    def another_shot(self) -> bool:
        """Whether the other team shoots next, as GameController3's WaitForPenaltyShot allows it: in the
        regular shots while both teams can still win; in sudden death the second team always answers and
        the first shoots again only while the score is level."""
        last = self.team_numbers.index(self.game.kicking_team)
        following = 1 - last
        difference = self.shoot_out_goals[last] - self.shoot_out_goals[following]
        shots = [team.penalty_shot for team in self.game.teams]
        if shots[following] < self.penalty_shots:
            return difference <= self.penalty_shots - shots[following] and -difference <= self.penalty_shots - shots[last]
        if shots[following] < self.penalty_shots + self.sudden_death_shots:
            return last == 0 or difference == 0
        return False

    def shoot_out_score(self) -> str:
        return f"{self.shoot_out_goals[0]}:{self.shoot_out_goals[1]}"
