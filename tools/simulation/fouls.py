"""The fouls the simulated GameController (``referee.py``) calls from the world's ground truth, and the
penalties they bring.

- pushing: walking into an opponent away from the ball (a duel for the ball is no push);
- illegal position in SET (in the other half, or the defenders in the centre circle) and at the
  kick-off (a defender in the centre circle before the ball moved or 10 s passed), and the free-kick
  distance (an opponent within 0.75 m of the ball after ``free_kick_grace_s``): ``set_plays.py`` says
  when these hold;
- leaving the field, inactive player (fallen for 10 s), local game stuck (nobody touched the ball for
  30 s with robots beside it).

Penalties last the rules' times (``PENALTY_S``: 45 s, 15 s in SET; the incremental ones 10 s longer for
each incremental penalty the team had before), counted in READY and PLAYING; a penalized robot is taken
off the carpet, then put back on the touchline of its own half, on the side away from the ball, facing
the field. Every foul is a ``Foul`` (time, team, player, penalty, why).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from tafel.representations import field as pitch
from tafel.representations.game import GamePhase, Penalty, State
from tafel.tools.simulation.officiating import HALF_LINE_X, HALF_LINE_Y, Event, Officiating, Player

#: GameController3's penalty durations (s, its champions_cup parameters); the incremental ones grow
PENALTY_S = {Penalty.player_pushing: 45.0, Penalty.illegal_position: 45.0, Penalty.illegal_position_in_set: 15.0,
             Penalty.illegal_motion_in_set: 15.0, Penalty.leaving_the_field: 45.0, Penalty.inactive_player: 45.0,
             Penalty.local_game_stuck: 45.0, Penalty.request_for_pickup: 45.0}
INCREMENTAL = (Penalty.player_pushing, Penalty.illegal_position, Penalty.leaving_the_field)
PENALTY_INCREMENT_S = 10.0  # s longer for each incremental penalty of the team before
CENTRE_CIRCLE_R, FREE_KICK_DISTANCE = pitch.CENTER_CIRCLE_DIAMETER / 2, 750.0  # mm
CONTACT = 330.0  # mm between two torsos: the robots touch
PUSH_SPEED = 80.0  # mm/s towards the other robot: walking into it
FALLEN_HEIGHT = 0.2  # m: a torso lower than this has fallen
INACTIVE_S, STUCK_S = 10.0, 30.0  # s fallen; s without a touch with robots beside the ball


@dataclass
class Foul:
    """A call against one robot: when (s), its team's number, its player number, the penalty, and why."""

    time_s: float
    team: int
    player: int
    penalty: Penalty
    reason: str


class Fouls(Officiating):
    """The referee's part that calls fouls and counts penalties down (its state is the ``Referee``'s)."""

    fouls: list[Foul]
    incremental: list[int]
    """incremental penalties per team so far"""
    fallen_since: dict[int, float]
    set_judged: bool
    last_touch_s: float
    """s: the ball's last touch (or the last call of a local game stuck)"""

    def judge_set(self, now: float) -> None:
        """In SET every robot stands in its own half, the defenders outside the centre circle."""
        self.set_judged = True
        kicking = self.team_index(self.game.kicking_team)
        for player in self.on_field():
            x, y, _ = self.team_pose(player)
            if x > 0.0:
                self.penalize(player, Penalty.illegal_position_in_set, now, "in the opponent half in SET")
            elif player.team != kicking and math.hypot(x, y) < CENTRE_CIRCLE_R and kicking is not None:
                self.penalize(player, Penalty.illegal_position_in_set, now, "in the centre circle at the opponents' kick-off")

    def judge_play(self, now: float, kick_off_defender: int | None, free_kick: bool) -> None:
        """The fouls of PLAYING, from where the robots are and how they move; team index ``kick_off_defender``
        is kept out of the centre circle, and while ``free_kick`` the kicking team's opponents from the ball."""
        bx, by = self.world.ball_position()
        kicking = self.team_index(self.game.kicking_team)
        for player in self.on_field():
            x, y, _ = self.world.robot_pose(player.index)
            if abs(x) > HALF_LINE_X + 300.0 or abs(y) > HALF_LINE_Y + 300.0:
                self.penalize(player, Penalty.leaving_the_field, now, "left the field")
            elif player.team == kick_off_defender and math.hypot(x, y) < CENTRE_CIRCLE_R:
                self.penalize(player, Penalty.illegal_position, now, "entered the centre circle at the opponents' kick-off")
            elif free_kick and player.team != kicking and math.hypot(x - bx, y - by) < FREE_KICK_DISTANCE - 50.0:
                self.penalize(player, Penalty.illegal_position, now,
                              f"within 0.75 m of the ball at the opponents' {self.game.set_play.name}")
            elif self.inactive(player, now):
                self.penalize(player, Penalty.inactive_player, now, f"fallen for {INACTIVE_S:g} s")
        self.judge_pushing(now, bx, by)
        if now - self.last_touch_s >= STUCK_S:
            near = sorted((math.hypot(bx - x, by - y), p.index) for p in self.on_field() for x, y, _ in [self.world.robot_pose(p.index)])
            if near and near[0][0] < 500.0:
                self.penalize(self.players[near[0][1]], Penalty.local_game_stuck, now, f"nobody played the ball for {STUCK_S:g} s")
            self.last_touch_s = now

    def judge_pushing(self, now: float, bx: float, by: float) -> None:
        """An opponent walked into: the robot moving towards the other, away from the ball (a duel for the
        ball is no push)."""
        field = self.on_field()
        for k, a in enumerate(field):
            for b in field[k + 1:]:
                if a.team == b.team:
                    continue
                ax, ay, _ = self.world.robot_pose(a.index)
                bx_, by_, _ = self.world.robot_pose(b.index)
                distance = math.hypot(bx_ - ax, by_ - ay)
                if distance >= CONTACT or min(math.hypot(bx - ax, by - ay), math.hypot(bx - bx_, by - by_)) < 400.0:
                    continue
                ux, uy = (bx_ - ax) / max(distance, 1.0), (by_ - ay) / max(distance, 1.0)
                va, vb = self.world.robot_velocity(a.index), self.world.robot_velocity(b.index)
                towards_b, towards_a = va[0] * ux + va[1] * uy, -(vb[0] * ux + vb[1] * uy)
                if max(towards_b, towards_a) > PUSH_SPEED:
                    pusher = a if towards_b >= towards_a else b
                    self.penalize(pusher, Penalty.player_pushing, now,
                                  f"walked into team {self.team_numbers[(b if pusher is a else a).team]} player "
                                  f"{(b if pusher is a else a).number}")
                    return

    def inactive(self, player: Player, now: float) -> bool:
        """Fallen for ``INACTIVE_S`` s (the torso low all that time)."""
        position, _ = self.world.robots[player.index].torso_pose(self.world.data)
        if float(position[2]) >= FALLEN_HEIGHT:
            self.fallen_since.pop(player.index, None)
            return False
        since = self.fallen_since.setdefault(player.index, now)
        return now - since >= INACTIVE_S

    def penalize(self, player: Player, penalty: Penalty, now: float, reason: str = "") -> None:
        robot = self.game.teams[player.team].players[player.number - 1]
        seconds = PENALTY_S.get(penalty, 45.0)
        if penalty in INCREMENTAL:
            seconds += PENALTY_INCREMENT_S * self.incremental[player.team]
            self.incremental[player.team] += 1
        robot.penalty, player.penalized_until_s, player.penalty_left_s = penalty, now + seconds, seconds
        self.fallen_since.pop(player.index, None)
        self.off_the_carpet(player)  # while it waits
        team = self.team_numbers[player.team]
        self.events.append(Event(now, f"PENALTY {penalty.name} team {team} player {player.number}"))
        self.fouls.append(Foul(now, team, player.number, penalty, reason))

    def penalties(self, now: float, dt: float) -> None:
        """Count the penalties down (in READY and PLAYING, as GameController3 does) and bring robots back."""
        # not in the shoot-out: a robot penalized there stays off until its shot ends (the next shot's substitutes)
        counting = self.game.state in (State.ready, State.playing) and self.game.game_phase is not GamePhase.penalty_shoot
        for player in self.players:
            robot = self.game.teams[player.team].players[player.number - 1]
            if player.penalized_until_s < 0 or robot.penalty is Penalty.substitute:
                continue
            if counting:
                player.penalty_left_s -= dt
            robot.secs_till_unpenalised = max(0, int(math.ceil(player.penalty_left_s - 1e-6)))
            if player.penalty_left_s <= 1e-9 and counting:
                bx, by, _ = player.side.to_team(*self.world.ball_position())
                side = -1.0 if by > 0 else 1.0  # the touchline farther from the ball
                x, y, heading = player.side.to_world(-1500.0, side * HALF_LINE_Y, -side * math.pi / 2)
                self.world.move_robot(player.index, x, y, heading)
                robot.penalty, robot.secs_till_unpenalised, player.penalized_until_s = Penalty.none, 0, -1.0
