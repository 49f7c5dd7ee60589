"""The simulated GameController: it referees a match in the world of ``tafel match`` and speaks the real
protocol (``RoboCupGameControlData`` version 18) over UDP on loopback.

What it handles, in simulated time:

- INITIAL, then READY (the robots walk to their kickoff positions) until every robot has stood still
  for 2 s or ``ready_s`` has passed, then SET (the ball on the centre spot) and PLAYING;
- goals (the ball wholly over the goal line between the posts): the score, then READY again with the
  kickoff for the team that conceded;
- the ball out: over a touchline, a kick-in for the other team where it went out; over a goal line, a
  goal kick (from the goal area's corner) or a corner kick, by who touched it last (the nearest robot);
- robots leaving the field (the torso 300 mm beyond the lines): LEAVING_THE_FIELD for ``penalty_s``,
  taken off the carpet meanwhile, then put back on a touchline of their own half facing the field;
- the halves (``half_s`` of PLAYING each, the clock stops otherwise) and the end. The teams keep
  their sides after half time (the rules swap them; here the second half starts as the first).
- Every team message heard on a team's port counts against its ``messageBudget`` (1200 a game).
"""

from __future__ import annotations

import math
import socket
from dataclasses import dataclass, field

from tafel.platforms.match_world import MatchWorld, Side
from tafel.platforms.network import listening_socket
from tafel.representations import field as pitch
from tafel.representations.game import (
    MAX_PLAYERS,
    GameState,
    PacketError,
    Penalty,
    RobotInfo,
    SetPlay,
    State,
    TeamInfo,
    decode_return,
    encode_game_state,
)

PACKET_INTERVAL_S = 0.5
MESSAGE_BUDGET = 1200  # the rules: team messages per game
HALF_LINE_X, HALF_LINE_Y = pitch.LENGTH / 2, pitch.WIDTH / 2


@dataclass
class Player:
    """One robot of the match: its team (0 or 1), its number, where it is in the world."""

    team: int
    number: int
    index: int
    side: Side
    penalized_until_s: float = -1.0
    returns: int = 0


@dataclass
class Event:
    time_s: float
    what: str


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
    ready_s: float = 30.0
    set_s: float = 3.0
    penalty_s: float = 30.0
    #: the game ends when a team has scored this many (drills and tests); None plays both halves
    goals_to_end: int | None = None
    events: list[Event] = field(default_factory=list)

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
        self.messages = [0, 0]
        self.message_bytes = 0
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
        self.listen()
        state = self.game.state
        if state is State.initial and now - self.phase_since >= self.initial_s:
            self.enter(State.ready, now)
        elif state is State.ready and (now - self.phase_since >= self.ready_s or self.all_still(now)):
            self.enter(State.set, now)
            self.world.move_ball(0.0, 0.0)
        elif state is State.set and now - self.phase_since >= self.set_s:
            self.enter(State.playing, now)
        elif state is State.playing:
            self.play(now, dt)
        elif state is State.finished and now - self.phase_since >= 2.0:
            if self.game.first_half and not self.ending:
                self.game.first_half, self.clock = False, float(self.half_s)
                self.game.kicking_team = self.team_numbers[1]
                self.enter(State.initial, now)
            else:
                self.over = True
        self.penalties(now)
        self.game.secs_remaining = int(math.ceil(self.clock))
        if now - self.last_packet_s >= PACKET_INTERVAL_S - 1e-9:
            self.game.packet_number = (self.game.packet_number + 1) % 256
            self.sender.sendto(encode_game_state(self.game), (self.broadcast, self.game_controller_port))
            self.last_packet_s = now

    def enter(self, state: State, now: float) -> None:
        self.game.state, self.phase_since, self.still_since = state, now, None
        self.events.append(Event(now, state.name.upper()))

    def play(self, now: float, dt: float) -> None:
        self.clock -= dt
        if self.clock <= 0:
            self.clock = 0.0
            self.enter(State.finished, now)
            return
        if self.game.set_play is not SetPlay.none and now - self.phase_since > 30.0:
            self.game.set_play, self.game.secondary_time = SetPlay.none, 0
        self.note_touch()
        bx, by = self.world.ball_position()
        over_goal_line = abs(bx) > HALF_LINE_X + pitch.BALL_RADIUS
        if pitch.goal_of(bx, by):
            scorer = 0 if bx > 0 else 1  # the first team attacks +x
            self.game.teams[scorer].score += 1
            self.events.append(Event(now, f"GOAL {self.team_numbers[scorer]}"))
            self.game.kicking_team = self.team_numbers[1 - scorer]
            if self.goals_to_end is not None and self.game.teams[scorer].score >= self.goals_to_end:
                self.ending = True
                self.enter(State.finished, now)
            else:
                self.enter(State.ready, now)
        elif over_goal_line or abs(by) > HALF_LINE_Y + pitch.BALL_RADIUS:
            self.ball_out(bx, by, now)
        for player in self.players:
            x, y, _ = self.world.robot_pose(player.index)
            if player.penalized_until_s < 0 and (abs(x) > HALF_LINE_X + 300.0 or abs(y) > HALF_LINE_Y + 300.0):
                self.penalize(player, Penalty.leaving_the_field, now)

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
        self.game.set_play, self.game.kicking_team, self.game.secondary_time = play, self.team_numbers[kicking], 30
        self.phase_since = now
        self.events.append(Event(now, f"{play.name.upper()} {self.team_numbers[kicking]}"))

    def note_touch(self) -> None:
        """The team of the robot nearest the ball, when one is close enough to touch it."""
        bx, by = self.world.ball_position()
        near = [(math.hypot(bx - x, by - y), p.team) for p in self.players for x, y, _ in [self.world.robot_pose(p.index)]]
        distance, team = min(near, default=(math.inf, self.last_touch))
        if distance < 250.0:
            self.last_touch = team

    # ------------------------------------------------------------------------------- penalties
    def penalize(self, player: Player, penalty: Penalty, now: float) -> None:
        robot = self.game.teams[player.team].players[player.number - 1]
        robot.penalty, player.penalized_until_s = penalty, now + self.penalty_s
        x, y, heading = player.side.to_world(-1000.0 - 500.0 * player.number, -(HALF_LINE_Y + pitch.BORDER_STRIP + 800.0), math.pi / 2)
        self.world.move_robot(player.index, x, y, heading)  # off the carpet while it waits
        self.events.append(Event(now, f"PENALTY {penalty.name} team {self.team_numbers[player.team]} player {player.number}"))

    def penalties(self, now: float) -> None:
        for player in self.players:
            robot = self.game.teams[player.team].players[player.number - 1]
            if player.penalized_until_s < 0:
                continue
            robot.secs_till_unpenalised = max(0, int(math.ceil(player.penalized_until_s - now)))
            if now >= player.penalized_until_s:
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
    def listen(self) -> None:
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
                self.messages[team] += 1
                self.message_bytes += len(data)
                self.game.teams[team].message_budget = max(0, self.game.teams[team].message_budget - 1)

    def close(self) -> None:
        for sock in (self.sender, self.returns, *self.team_sockets):
            sock.close()

    def score(self) -> str:
        return f"{self.game.teams[0].score}:{self.game.teams[1].score}"
