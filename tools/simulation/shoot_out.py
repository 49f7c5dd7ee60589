"""The penalty shoot-out of the simulated GameController (``referee.py``), as GameController3 runs it
(``shoot_out``: after a tied game, after any game, or alone) and as the rules' referee judges it.

The game phase PENALTYSHOOT, every robot a substitute (penalty 14) but the kicking team's striker, on
the edge of the penalty area facing the ball on the penalty mark, and the defending team's keeper (its
lowest player number), on its goal line in the goal's centre; SET, then PLAYING with the shot's
``PENALTY_SHOT_S`` on the clock (``secs_remaining``). The team listed first kicks first (the rules and
GameController3's StartPenaltyShootout). A shot ends (the rules' penalty kick):

- with a goal (the team's score and its bit in ``single_shots``);
- when the ball has stopped or left the field after the striker's kick: saved (the keeper touched it),
  post (it hit a goal post), wide (it crossed the goal line beside the goal), else missed;
- at once when the striker plays the ball a second time after it clearly moved (``second touch``);
- at once with a goal awarded when the keeper leaves its goal line or falls before the striker kicked
  (a foul, in ``fouls``, its penalty ``none``: the rules end the shot instead);
- when the ``PENALTY_SHOT_S`` are up and the striker has not kicked (``time``), or when the striker is
  penalized before its kick (``foul``).

Then FINISHED, and the other team kicks. Fouls called in the shoot-out (GameController3 allows these
there): motion in SET (a robot walked from where it was placed; 15 s, in place), and in PLAYING pushing,
leaving the field and a fallen or inactive striker (the rules spare the keeper: it may dive and lie); a
robot penalized in the shoot-out stays penalized until the shot ends. ``penalty_shots`` each (the rules: three), then sudden death, at most
``sudden_death_shots`` each: GameController3 stops the regular shots once a team can no longer draw
level, and in sudden death the rules rank each pair of shots (goal, saved, post, wide, any other kick, no
kick) and the better one wins; still level after all of them, a coin toss (seeded, ``seed``) decides.
Each team shoots at the goal it attacked in the game (the robots' frames stay as they were; GameController3
takes every shot at one goal, chosen by the teams or a coin toss, and swaps the sides in its packet
instead, which comes to the same for the robots). Team messages are not counted. Every penalty shot is
a ``Shot``.
"""

from __future__ import annotations

import math
import random
from dataclasses import dataclass

from tafel.platforms.match_world import Side
from tafel.representations import field as pitch
from tafel.representations.game import GamePhase, Penalty, SetPlay, State
from tafel.tools.simulation.fouls import FALLEN_HEIGHT, Foul, Fouls
from tafel.tools.simulation.officiating import HALF_LINE_X, HALF_LINE_Y, Event, Player, left_the_carpet

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
#: mm from the striker's torso to the ball: it plays the ball (within), it has let the ball go (beyond)
STRIKER_TOUCH, STRIKER_RELEASE = 220.0, 400.0
#: mm the keeper's torso may be in front of the goal line's centre (placed at ``KEEPER_FROM_GOAL_LINE``, plus the
#: walk's sway along the line) and behind it: beyond, its feet no longer touch the line
KEEPER_LINE_FRONT, KEEPER_LINE_BEHIND = 250.0, 100.0
SHOT_OVERTIME_S = 15.0  # s after the shot's time a ball kicked in time may still roll: then the shot ends whatever it does
POST_HIT = pitch.BALL_RADIUS + pitch.GOAL_POST_DIAMETER / 2 + 10.0  # mm from a post's centre to the ball's: it hit the post
#: the rules' ranking of a sudden-death shot (0 best: goal, saved, post, wide, any other kick, no kick); the better of a pair wins
RANK = {"goal": 0, "saved": 1, "post": 2, "wide": 3, "missed": 4, "second touch": 4, "time": 5, "foul": 5}


@dataclass
class Shot:
    """A penalty shot: when it ended (s), the kicking team's number, its striker's and the keeper's player
    numbers (0: none), the outcome (goal; saved: the keeper touched the ball; post: it hit a post; wide: it
    crossed the goal line beside the goal; missed: it stopped or left the field otherwise; second touch: the
    striker played it again; time: not kicked within the shot's time; foul: the striker penalized before
    its kick), and whether it was a sudden-death shot."""

    time_s: float
    team: int
    striker: int
    keeper: int
    outcome: str = ""
    sudden_death: bool = False


class ShootOut(Fouls):
    """The referee's part that runs the penalty shoot-out (its state is the ``Referee``'s)."""

    shoot_out: str
    """one of ``SHOOT_OUT``"""
    set_s: float
    set_grace_s: float
    penalty_shots: int
    sudden_death_shots: int
    seed: int
    """the coin toss's seed"""
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
    post_hit: bool
    striker_released: bool
    """the striker's torso got ``STRIKER_RELEASE`` from the ball after the kick"""

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
        elif state is State.set:
            self.judge_shot_set(now, since)
            if since >= self.set_s:
                self.enter(State.playing, now)  # GameController3's FreePenaltyShot
                self.kicked = self.keeper_touched = self.post_hit = self.striker_released = False
                self.ball_track = []
                if self.shot is not None and self.shot_player(True) is None:
                    self.end_shot("foul" if self.shot.striker else "time", now)  # the striker penalized in SET; nobody to kick
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
        self.enter(State.set, now)  # where the robots stand once SET settled is their place (``placed``)

    def shot_player(self, striker: bool) -> Player | None:
        """The shot's striker (or keeper) while it is on the field."""
        if self.shot is None:
            return None
        kicking = self.team_numbers.index(self.shot.team)
        team, number = (kicking, self.shot.striker) if striker else (1 - kicking, self.shot.keeper)
        return next((p for p in self.on_field() if p.team == team and p.number == number), None)

    def judge_shot_set(self, now: float, since: float) -> None:
        """SET of a penalty shot: neither robot may walk (the rules; GameController3's motion in Set, 15 s).
        Where each stands once it settled (``set_grace_s``) is its place; walking from it is the foul."""
        if since >= self.set_grace_s:
            players = [p for p in (self.shot_player(True), self.shot_player(False)) if p is not None]
            self.judge_motion_in_set(players, now, "walked in SET of a penalty shot")

    def judge_shot(self, now: float, dt: float) -> None:
        """A penalty shot in PLAYING, from the ground truth: the keeper's line before the kick, the fouls, the
        striker's second touch, then a goal, saved, post, wide or missed once the ball stops or leaves the
        field after the kick, or the time up without a kick."""
        self.clock = max(0.0, self.clock - dt)
        bx, by = self.world.ball_position()
        kicking = self.team_numbers.index(self.game.kicking_team)
        attacked = 1 if kicking == 0 else -1
        self.kicked = self.kicked or math.hypot(bx - self.mark[0], by - self.mark[1]) > SHOT_KICKED
        if not self.kicked and self.keeper_left_line(now):
            return
        self.judge_shot_fouls(now, bx, by)
        if self.game.state is not State.playing:
            return
        striker, keeper = self.shot_player(True), self.shot_player(False)
        if striker is None and not self.kicked:
            self.end_shot("foul", now)  # penalized before the kick: nobody kicks
            return
        if keeper is not None and self.kicked:
            x, y, _ = self.world.robot_pose(keeper.index)
            self.keeper_touched = self.keeper_touched or math.hypot(bx - x, by - y) < SHOT_TOUCH
        post_x = attacked * (HALF_LINE_X + pitch.GOAL_POST_DIAMETER / 2)
        post_y = (pitch.GOAL_INNER_WIDTH + pitch.GOAL_POST_DIAMETER) / 2
        self.post_hit = self.post_hit or any(math.hypot(bx - post_x, by - side * post_y) < POST_HIT for side in (-1, 1))
        self.ball_track = [*(sample for sample in self.ball_track if now - sample[0] <= SHOT_STOPPED_S + 1e-6), (now, bx, by)]
        stopped = (self.kicked and now - self.ball_track[0][0] >= SHOT_STOPPED_S - 1e-6
                   and all(math.hypot(bx - x, by - y) < SHOT_STOPPED for _, x, y in self.ball_track))
        over_goal_line = attacked * bx > HALF_LINE_X + pitch.BALL_RADIUS
        out = abs(bx) > HALF_LINE_X + pitch.BALL_RADIUS or abs(by) > HALF_LINE_Y + pitch.BALL_RADIUS
        if pitch.goal_of(bx, by) == attacked:
            self.end_shot("goal", now)
        elif self.second_touch(striker, bx, by):
            self.end_shot("second touch", now)
        elif out or stopped or (self.clock <= 0.0 and (not self.kicked or now - self.phase_since >= PENALTY_SHOT_S + SHOT_OVERTIME_S)):
            self.end_shot("saved" if self.keeper_touched else "post" if self.post_hit else "wide" if over_goal_line
                          else "missed" if self.kicked else "time", now)

    def keeper_left_line(self, now: float) -> bool:
        """The rules: until the striker kicked, the keeper keeps contact with its goal line, between the posts,
        on its feet; else the shot ends at once and the goal is awarded. True when it did."""
        keeper = self.shot_player(False)
        if keeper is None:
            return False
        x, y, _ = self.team_pose(keeper)
        in_front = x + HALF_LINE_X  # mm from the goal line's centre into the field
        upright = float(self.world.robots[keeper.index].torso_pose(self.world.data)[0][2]) >= FALLEN_HEIGHT
        why = ("fell" if not upright else "left its goal line" if not -KEEPER_LINE_BEHIND <= in_front <= KEEPER_LINE_FRONT
               or abs(y) > pitch.GOAL_INNER_WIDTH / 2 else "")
        if not why:
            return False
        team = self.team_numbers[keeper.team]
        self.events.append(Event(now, f"KEEPER team {team} player {keeper.number} {why} before the kick: GOAL AWARDED"))
        self.fouls.append(Foul(now, team, keeper.number, Penalty.none, f"keeper {why} before the penalty shot's kick: goal awarded"))
        self.end_shot("goal", now)
        return True

    def judge_shot_fouls(self, now: float, bx: float, by: float) -> None:
        """The fouls GameController3 allows in a penalty shot's PLAYING: leaving the field, pushing, and a
        fallen or inactive striker (the rules spare the keeper)."""
        keeper = self.shot_player(False)
        for player in self.on_field():
            x, y, _ = self.world.robot_pose(player.index)
            if left_the_carpet(x, y):
                self.penalize(player, Penalty.leaving_the_field, now, "left the field in a penalty shot")
        self.judge_pushing(now, bx, by)
        self.judge_activity(now, spared=keeper)

    def second_touch(self, striker: Player | None, bx: float, by: float) -> bool:
        """The rules: the striker may not play the ball again once it clearly moved. After the kick, its torso
        within ``STRIKER_TOUCH`` of the ball plays it again once it had let the ball go (``STRIKER_RELEASE``
        away), or once the ball is ``STRIKER_RELEASE`` from the mark (it walked after the ball: a dribble)."""
        if striker is None or not self.kicked:
            return False
        x, y, _ = self.world.robot_pose(striker.index)
        distance = math.hypot(bx - x, by - y)
        self.striker_released = self.striker_released or distance > STRIKER_RELEASE
        dribbled = math.hypot(bx - self.mark[0], by - self.mark[1]) > STRIKER_RELEASE
        return (self.striker_released or dribbled) and distance < STRIKER_TOUCH

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
            self.decide(now)

    def decide(self, now: float) -> None:
        """The shoot-out's winner: more goals; level after sudden death, the better ranked last pair of shots;
        level even so, a coin toss (the rules)."""
        first, second = self.shoot_out_goals
        how = ""
        if first != second:
            self.winner = self.team_numbers[0] if first > second else self.team_numbers[1]
        elif (pair := self.last_pair()) is not None and RANK[pair[0].outcome] != RANK[pair[1].outcome]:
            better = pair[0] if RANK[pair[0].outcome] < RANK[pair[1].outcome] else pair[1]
            self.winner, how = better.team, f" ({better.outcome} ranks above {(pair[1] if better is pair[0] else pair[0]).outcome})"
        else:
            self.winner, how = random.Random(self.seed).choice(self.team_numbers), " (a coin toss)"
        self.events.append(Event(now, f"SHOOT-OUT OVER {first}:{second}, team {self.winner} wins{how}"))

    def last_pair(self) -> tuple[Shot, Shot] | None:
        """The last sudden-death shot of each team, when both kicked as often."""
        shots = [team.penalty_shot for team in self.game.teams]
        if shots[0] != shots[1] or shots[0] <= self.penalty_shots or len(self.shots) < 2:
            return None
        return self.shots[-2], self.shots[-1]

    def another_shot(self) -> bool:
        """Whether the other team shoots next, as GameController3's WaitForPenaltyShot allows it: in the
        regular shots while both teams can still win; in sudden death the second team always answers, and
        the first shoots again only while the pair of shots ranked the same (the rules' ranking)."""
        last = self.team_numbers.index(self.game.kicking_team)
        following = 1 - last
        difference = self.shoot_out_goals[last] - self.shoot_out_goals[following]
        shots = [team.penalty_shot for team in self.game.teams]
        if shots[following] < self.penalty_shots:
            return difference <= self.penalty_shots - shots[following] and -difference <= self.penalty_shots - shots[last]
        if shots[following] < self.penalty_shots + self.sudden_death_shots:
            if last == 0:
                return True
            pair = self.last_pair()
            return difference == 0 and (pair is None or RANK[pair[0].outcome] == RANK[pair[1].outcome])
        return False

    def shoot_out_score(self) -> str:
        return f"{self.shoot_out_goals[0]}:{self.shoot_out_goals[1]}"
