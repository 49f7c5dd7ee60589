"""The simulated GameController: it referees a match in the world of ``tafel match`` as GameController3
and a referee would, and speaks the real protocol (``RoboCupGameControlData`` version 18) over UDP on
loopback.

What it runs, in simulated time:

- the states as GameController3 runs them: INITIAL, STANDBY (``standby_s``), READY (until every
  robot has stood still for 2 s or ``ready_s`` has passed; ``secondary_time`` counts it down), SET
  (the ball on the centre spot) and PLAYING; the half's clock runs in PLAYING, and in READY and SET
  except at a half's start (GameController3's main timer);
- goals (the ball wholly over the goal line between the posts): the score, then READY again with the
  kickoff for the team that conceded. A goal straight from a free kick (indirect) does not count: a
  goal kick instead. A team that communicated illegally scores nothing;
- the ball out: over a touchline, a kick-in for the other team where it went out; over a goal line, a
  goal kick (from the goal area's corner) or a corner kick, by who touched it last (the nearest robot).
  A free kick ends when the kicking team touches the ball or after 30 s;
- fouls, from the world's ground truth (``FOULS``): pushing (walking into an opponent away from the
  ball), illegal position in SET (in the other half, or the defenders in the centre circle) and at the
  kick-off (a defender in the centre circle before the ball moved or 10 s passed), the free-kick
  distance (an opponent within 0.75 m of the ball after ``free_kick_grace_s``), leaving the field,
  inactive player (fallen for 10 s), local game stuck (nobody touched the ball for 30 s with robots
  beside it). Penalties last the rules' times (``PENALTY_S``: 45 s, 15 s in SET; the incremental ones
  10 s longer for each incremental penalty the team had before), counted in READY and PLAYING; a
  penalized robot is taken off the carpet, then put back on the touchline of its own half, on the
  side away from the ball, facing the field;
- team messages counted against the team's budget (1200) in STANDBY, READY, SET and PLAYING only, as
  GameController3 counts them; one over 128 bytes, or sent with the budget spent, is illegal
  communication: the team's score goes to 0 and stays there;
- the halves (``half_s`` of playing each) and the end. The teams keep their sides after half time (the
  rules swap them; here the second half starts as the first).

Every call is an ``Event`` (time, what) and every foul a ``Foul`` (time, team, player, penalty, why).
"""

from __future__ import annotations

import math
import socket
from dataclasses import dataclass, field

from tafel.modules.communication.game_controller_codec import MAX_PLAYERS, PacketError, decode_return, encode_game_state
from tafel.platforms.match_world import MatchWorld, Side
from tafel.platforms.network import listening_socket
from tafel.representations import field as pitch
from tafel.representations.game import GamePhase, GameState, Penalty, RobotInfo, SetPlay, State, TeamInfo
from tafel.representations.team import MAX_MESSAGE_BYTES

PACKET_INTERVAL_S = 0.5
MESSAGE_BUDGET = 1200  # the rules: team messages per game
HALF_LINE_X, HALF_LINE_Y = pitch.LENGTH / 2, pitch.WIDTH / 2
#: GameController3's penalty durations (s, its champions_cup parameters); the incremental ones grow
PENALTY_S = {Penalty.player_pushing: 45.0, Penalty.illegal_position: 45.0, Penalty.illegal_position_in_set: 15.0,
             Penalty.leaving_the_field: 45.0, Penalty.inactive_player: 45.0, Penalty.local_game_stuck: 45.0,
             Penalty.request_for_pickup: 45.0}
INCREMENTAL = (Penalty.player_pushing, Penalty.illegal_position, Penalty.leaving_the_field)
PENALTY_INCREMENT_S = 10.0  # s longer for each incremental penalty of the team before
#: the states in which GameController3 counts team messages (and not in a penalty shoot-out)
COUNTED_STATES = (State.standby, State.ready, State.set, State.playing)
KICK_OFF_S, FREE_KICK_S = 10.0, 30.0  # s: the rules
CENTRE_CIRCLE_R, FREE_KICK_DISTANCE = pitch.CENTER_CIRCLE_DIAMETER / 2, 750.0  # mm
CONTACT = 330.0  # mm between two torsos: the robots touch
PUSH_SPEED = 80.0  # mm/s towards the other robot: walking into it
FALLEN_HEIGHT = 0.2  # m: a torso lower than this has fallen
INACTIVE_S, STUCK_S = 10.0, 30.0  # s fallen; s without a touch with robots beside the ball


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


@dataclass
class Event:
    time_s: float
    what: str


@dataclass
class Foul:
    """A call against one robot: when (s), its team's number, its player number, the penalty, and why."""

    time_s: float
    team: int
    player: int
    penalty: Penalty
    reason: str


@dataclass
class Referee:
    world: MatchWorld
    team_numbers: tuple[int, int]
    players: list[Player]
    half_s: float
    game_controller_port: int
    return_port: int
    team_ports: tuple[int, int]
    broadcast: str = "127.255.255.255"
    initial_s: float = 1.0
    standby_s: float = 2.0
    ready_s: float = 45.0
    set_s: float = 3.0
    free_kick_grace_s: float = 5.0
    """s the defenders have to leave the 0.75 m round a free kick's ball"""
    set_grace_s: float = 1.0
    """s into SET when the positions are judged (the robots come to a stop)"""
    #: the game ends when a team has scored this many (drills and tests); None plays both halves
    goals_to_end: int | None = None
    events: list[Event] = field(default_factory=list)
    fouls: list[Foul] = field(default_factory=list)

    def __post_init__(self) -> None:
        sizes = [sum(p.team == t for p in self.players) for t in (0, 1)]
        self.game = GameState(players_per_team=max(sizes), state=State.initial, first_half=True, kicking_team=self.team_numbers[0],
                              secs_remaining=int(self.half_s),
                              teams=[TeamInfo(team_number=n, field_player_colour=t, goalkeeper_colour=2 + t, message_budget=MESSAGE_BUDGET,
                                              players=[RobotInfo() for _ in range(MAX_PLAYERS)]) for t, n in enumerate(self.team_numbers)])
        self.sender = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        self.sender.setsockopt(socket.SOL_SOCKET, socket.SO_BROADCAST, 1)
        self.returns = listening_socket(self.return_port)
        self.team_sockets = [listening_socket(port) for port in self.team_ports]
        self.messages = [0, 0]  # counted against the budget
        self.messages_heard = [0, 0]  # all, whenever sent
        self.message_bytes = 0
        self.illegal_communication = [False, False]
        self.incremental = [0, 0]  # incremental penalties per team so far
        self.set_play_touched = False  # the kicking team touched the ball since the set play began
        self.indirect = False  # the ball was last played from an own free kick and nobody else touched it since
        self.kicker: int | None = None  # index of the robot that took the free kick
        self.last_toucher: int | None = None
        self.last_touch_s = 0.0
        self.fallen_since: dict[int, float] = {}
        self.kick_off_defender: int | None = None  # team index defending the kick-off under way
        self.kick_off_ball_moved = False
        self.set_judged = False
        self.bad_returns = 0
        self.phase_since = 0.0  # s: when the state began
        self.clock = float(self.half_s)  # s of this half's playing time left
        self.last_packet_s = -math.inf
        self.still_since: float | None = None
        self.last_touch = 0  # the team that touched the ball last
        self.over = False
        self.ending = False  # the game ends at the next FINISHED, whichever half it is

    # ------------------------------------------------------------------------------------ tick
    def tick(self, now: float, dt: float) -> None:
        """Referee one tick of ``dt`` s ending at ``now``: listen, judge, send a packet when due."""
        self.listen(now)
        state = self.game.state
        if state in (State.ready, State.set) and self.clock < self.half_s:  # GameController3's main timer
            self.clock = max(0.0, self.clock - dt)
        if state is State.initial and now - self.phase_since >= self.initial_s:
            self.enter(State.standby, now)
        elif state is State.standby and now - self.phase_since >= self.standby_s:
            self.enter(State.ready, now)
        elif state is State.ready:
            self.game.secondary_time = max(0, int(math.ceil(self.ready_s - (now - self.phase_since) - 1e-6)))
            if now - self.phase_since >= self.ready_s or self.all_still(now):
                self.enter(State.set, now)
                self.world.move_ball(0.0, 0.0)
                self.game.secondary_time, self.set_judged = 0, False
        elif state is State.set:
            if not self.set_judged and now - self.phase_since >= self.set_grace_s:
                self.judge_set(now)
            if now - self.phase_since >= self.set_s:
                self.enter(State.playing, now)
                kicking = self.team_index(self.game.kicking_team)
                self.kick_off_defender = None if kicking is None else 1 - kicking
                self.kick_off_ball_moved = False
                self.last_touch_s = now
        elif state is State.playing:
            self.play(now, dt)
        elif state is State.finished and now - self.phase_since >= 2.0:
            if self.game.first_half and not self.ending:
                self.game.first_half, self.clock = False, float(self.half_s)
                self.game.kicking_team = self.team_numbers[1]
                self.enter(State.initial, now)
            else:
                self.over = True
        self.penalties(now, dt)
        self.game.secs_remaining = int(math.ceil(self.clock))
        if now - self.last_packet_s >= PACKET_INTERVAL_S - 1e-9:
            self.game.packet_number = (self.game.packet_number + 1) % 256
            self.sender.sendto(encode_game_state(self.game), (self.broadcast, self.game_controller_port))
            self.last_packet_s = now

    def enter(self, state: State, now: float) -> None:
        self.game.state, self.phase_since, self.still_since = state, now, None
        self.events.append(Event(now, state.name.upper()))

    def team_index(self, number: int) -> int | None:
        return self.team_numbers.index(number) if number in self.team_numbers else None

    def on_field(self) -> list[Player]:
        return [p for p in self.players if p.penalized_until_s < 0]

    def team_pose(self, player: Player) -> tuple[float, float, float]:
        """The robot's torso in its team's field frame (its own goal at -x)."""
        return player.side.to_team(*self.world.robot_pose(player.index))

    def play(self, now: float, dt: float) -> None:
        self.clock -= dt
        if self.clock <= 0:
            self.clock = 0.0
            self.enter(State.finished, now)
            return
        self.note_touch(now)
        if self.game.set_play is not SetPlay.none and (now - self.phase_since > FREE_KICK_S or self.set_play_touched):
            self.game.set_play, self.game.secondary_time = SetPlay.none, 0
        elif self.game.set_play is not SetPlay.none:
            self.game.secondary_time = max(0, int(math.ceil(FREE_KICK_S - (now - self.phase_since) - 1e-6)))
        bx, by = self.world.ball_position()
        over_goal_line = abs(bx) > HALF_LINE_X + pitch.BALL_RADIUS
        if pitch.goal_of(bx, by):
            scorer = 0 if bx > 0 else 1  # the first team attacks +x
            if self.indirect:
                self.events.append(Event(now, f"NO GOAL {self.team_numbers[scorer]}: straight from a free kick"))
                self.ball_out(bx, by, now)
                return
            if not self.illegal_communication[scorer]:
                self.game.teams[scorer].score += 1
            self.events.append(Event(now, f"GOAL {self.team_numbers[scorer]}"))
            self.game.kicking_team, self.game.set_play = self.team_numbers[1 - scorer], SetPlay.none
            if self.goals_to_end is not None and self.game.teams[scorer].score >= self.goals_to_end:
                self.ending = True
                self.enter(State.finished, now)
            else:
                self.enter(State.ready, now)
            return
        if over_goal_line or abs(by) > HALF_LINE_Y + pitch.BALL_RADIUS:
            self.ball_out(bx, by, now)
        self.judge_play(now)

    def ball_out(self, bx: float, by: float, now: float) -> None:
        """Put the ball back as the rules' set plays do, for the team that did not touch it last."""
        kicking = 1 - self.last_touch
        if abs(by) > HALF_LINE_Y + pitch.BALL_RADIUS:
            play, x, y = SetPlay.kick_in, max(-HALF_LINE_X + 100.0, min(HALF_LINE_X - 100.0, bx)), math.copysign(HALF_LINE_Y - 50.0, by)
        else:
            defending = 1 if bx > 0 else 0  # the team whose goal line it crossed
            if kicking == defending:
                play, x = SetPlay.goal_kick, math.copysign(HALF_LINE_X - pitch.GOAL_AREA_LENGTH, bx)
                y = math.copysign(pitch.GOAL_AREA_WIDTH / 2, by)
            else:
                play, x, y = SetPlay.corner_kick, math.copysign(HALF_LINE_X - 50.0, bx), math.copysign(HALF_LINE_Y - 50.0, by)
        self.world.move_ball(x, y)
        self.game.set_play, self.game.kicking_team, self.game.secondary_time = play, self.team_numbers[kicking], int(FREE_KICK_S)
        self.phase_since, self.set_play_touched, self.indirect, self.kicker = now, False, False, None
        self.kick_off_defender = None
        self.events.append(Event(now, f"{play.name.upper()} {self.team_numbers[kicking]}"))

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
        if self.game.set_play in (SetPlay.goal_kick, SetPlay.corner_kick, SetPlay.kick_in, SetPlay.pushing_free_kick):
            if player.team == kicking and not self.set_play_touched:
                self.set_play_touched, self.indirect, self.kicker = True, True, player.index
        elif self.indirect and player.index != self.kicker:
            self.indirect = False

    # ------------------------------------------------------------------------------------ fouls
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

    def judge_play(self, now: float) -> None:
        """The fouls of PLAYING, from where the robots are and how they move."""
        bx, by = self.world.ball_position()
        kicking = self.team_index(self.game.kicking_team)
        if self.kick_off_defender is not None and (now - self.phase_since >= KICK_OFF_S or self.kick_off_ball_moved
                                                   or math.hypot(bx, by) > 200.0):
            self.kick_off_defender = None
        free_kick = (self.game.set_play is not SetPlay.none and not self.set_play_touched
                     and now - self.phase_since >= self.free_kick_grace_s)
        for player in self.on_field():
            x, y, _ = self.world.robot_pose(player.index)
            if abs(x) > HALF_LINE_X + 300.0 or abs(y) > HALF_LINE_Y + 300.0:
                self.penalize(player, Penalty.leaving_the_field, now, "left the field")
            elif player.team == self.kick_off_defender and math.hypot(x, y) < CENTRE_CIRCLE_R:
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

    # ------------------------------------------------------------------------------- penalties
    def penalize(self, player: Player, penalty: Penalty, now: float, reason: str = "") -> None:
        robot = self.game.teams[player.team].players[player.number - 1]
        seconds = PENALTY_S.get(penalty, 45.0)
        if penalty in INCREMENTAL:
            seconds += PENALTY_INCREMENT_S * self.incremental[player.team]
            self.incremental[player.team] += 1
        robot.penalty, player.penalized_until_s, player.penalty_left_s = penalty, now + seconds, seconds
        self.fallen_since.pop(player.index, None)
        x, y, heading = player.side.to_world(-1000.0 - 500.0 * player.number, -(HALF_LINE_Y + pitch.BORDER_STRIP + 800.0), math.pi / 2)
        self.world.move_robot(player.index, x, y, heading)  # off the carpet while it waits
        team = self.team_numbers[player.team]
        self.events.append(Event(now, f"PENALTY {penalty.name} team {team} player {player.number}"))
        self.fouls.append(Foul(now, team, player.number, penalty, reason))

    def penalties(self, now: float, dt: float) -> None:
        """Count the penalties down (in READY and PLAYING, as GameController3 does) and bring robots back."""
        counting = self.game.state in (State.ready, State.playing)
        for player in self.players:
            robot = self.game.teams[player.team].players[player.number - 1]
            if player.penalized_until_s < 0:
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

    def all_still(self, now: float) -> bool:
        """Every robot has stood still for 2 s (after at least 5 s of READY): all are in position."""
        moving = any(math.hypot(*self.world.robot_velocity(p.index)) > 60.0 for p in self.players if p.penalized_until_s < 0)
        if moving or now - self.phase_since < 5.0:
            self.still_since = None
            return False
        self.still_since = now if self.still_since is None else self.still_since
        return now - self.still_since >= 2.0

    # ------------------------------------------------------------------------------------- UDP
    def listen(self, now: float = 0.0) -> None:
        while True:
            try:
                data = self.returns.recv(1024)
            except (BlockingIOError, InterruptedError):
                break
            try:
                answer = decode_return(data)
            except PacketError:
                self.bad_returns += 1
                continue
            for player in self.players:
                if self.team_numbers[player.team] == answer.team and player.number == answer.player:
                    player.returns += 1
        for team, sock in enumerate(self.team_sockets):
            while True:
                try:
                    data = sock.recv(2048)
                except (BlockingIOError, InterruptedError):
                    break
                self.messages_heard[team] += 1
                self.message_bytes += len(data)
                if self.game.state not in COUNTED_STATES or self.game.game_phase is GamePhase.penalty_shoot:
                    continue  # GameController3 does not count these
                self.messages[team] += 1
                budget = self.game.teams[team].message_budget
                if (budget == 0 or len(data) > MAX_MESSAGE_BYTES) and not self.illegal_communication[team]:
                    self.illegal_communication[team], self.game.teams[team].score = True, 0
                    why = f"{len(data)} bytes" if len(data) > MAX_MESSAGE_BYTES else "the budget spent"
                    self.events.append(Event(now, f"ILLEGAL COMMUNICATION team {self.team_numbers[team]}: {why}"))
                    self.fouls.append(Foul(now, self.team_numbers[team], 0, Penalty.none, f"illegal communication: {why}"))
                self.game.teams[team].message_budget = max(0, budget - 1)

    def close(self) -> None:
        for sock in (self.sender, self.returns, *self.team_sockets):
            sock.close()

    def score(self) -> str:
        return f"{self.game.teams[0].score}:{self.game.teams[1].score}"
