"""The simulated GameController: it referees a match in the world of ``tafel match`` as GameController3
and a referee would, and speaks the real protocol (``RoboCupGameControlData`` version 18) over UDP on
loopback.

What it runs, in simulated time (here: the states, the clock, goals, team messages and the packets; its
parts in their own files):

- the states as GameController3 runs them: INITIAL, STANDBY (``standby_s``), READY (until every
  robot has stood still for 2 s or ``ready_s`` has passed; ``secondary_time`` counts it down), SET
  (the ball on the centre spot) and PLAYING; the half's clock runs in PLAYING, and in READY and SET
  except at a half's start (GameController3's main timer);
- goals (the ball wholly over the goal line between the posts): the score, then READY again with the
  kickoff for the team that conceded. A goal straight from a free kick (indirect) does not count: a
  goal kick instead. A team that communicated illegally scores nothing;
- set plays (``set_plays.py``): the kick-off, the free kicks when the ball goes out, and the ones it is
  told to call (``calls``);
- fouls from the world's ground truth and their penalties (``fouls.py``);
- team messages counted against the team's budget (1200) in STANDBY, READY, SET and PLAYING only, as
  GameController3 counts them; one over 128 bytes, or sent with the budget spent, is illegal
  communication: the team's score goes to 0 and stays there;
- the halves (``half_s`` of playing each; ``halves`` 1 for drills and tests) and the end. The teams keep
  their sides after half time (the rules swap them; here the second half starts as the first);
- a penalty shoot-out as GameController3 runs it (``shoot_out.py``: after a tied game, after any game,
  or alone).

Every call is an ``Event`` (time, what), every foul a ``Foul``, every penalty shot a ``Shot``, and each
set play that keeps the defending team away a ``Restriction``.
"""

from __future__ import annotations

import math
import socket
from dataclasses import dataclass, field

from tafel.modules.communication.game_controller_codec import MAX_PLAYERS, PacketError, decode_return, encode_game_state
from tafel.platforms.match_world import MatchWorld
from tafel.platforms.network import listening_socket
from tafel.representations import field as pitch
from tafel.representations.game import GamePhase, GameState, Penalty, RobotInfo, SetPlay, State, TeamInfo
from tafel.representations.team import MAX_MESSAGE_BYTES
from tafel.tools.simulation.fouls import Foul
from tafel.tools.simulation.officiating import HALF_LINE_X, HALF_LINE_Y, Event, Player
from tafel.tools.simulation.set_plays import Call, Restriction, SetPlays
from tafel.tools.simulation.shoot_out import PENALTY_SHOTS, SHOOT_OUT, SHOOT_OUT_AFTER_GAME_S, SUDDEN_DEATH_SHOTS, ShootOut, Shot

PACKET_INTERVAL_S = 0.5
MESSAGE_BUDGET = 1200  # the rules: team messages per game
#: the states in which GameController3 counts team messages (and not in a penalty shoot-out)
COUNTED_STATES = (State.standby, State.ready, State.set, State.playing)


@dataclass
class Referee(ShootOut, SetPlays):
    """The GameController of a simulated match: its settings, then every call it made; ``tick`` referees."""

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
    halves: int = 2
    shoot_out: str = "never"
    """one of ``SHOOT_OUT``"""
    penalty_shots: int = PENALTY_SHOTS
    sudden_death_shots: int = SUDDEN_DEATH_SHOTS
    seed: int = 0
    """the shoot-out's coin toss (the match's ``--seed``)"""
    calls: list[Call] = field(default_factory=list)
    events: list[Event] = field(default_factory=list)
    fouls: list[Foul] = field(default_factory=list)
    shots: list[Shot] = field(default_factory=list)
    restrictions: list[Restriction] = field(default_factory=list)

    def __post_init__(self) -> None:
        if self.shoot_out not in SHOOT_OUT:
            raise ValueError(f"shoot_out takes one of {', '.join(SHOOT_OUT)}, got {self.shoot_out!r}")
        sizes = [sum(p.team == t for p in self.players) for t in (0, 1)]
        self.game = GameState(players_per_team=max(sizes), state=State.initial, first_half=True, kicking_team=self.team_numbers[0],
                              secs_remaining=int(self.half_s),
                              teams=[TeamInfo(team_number=n, field_player_colour=t, goalkeeper_colour=2 + t, message_budget=MESSAGE_BUDGET,
                                              players=[RobotInfo() for _ in range(MAX_PLAYERS)]) for t, n in enumerate(self.team_numbers)])
        self.sender = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        self.sender.setsockopt(socket.SOL_SOCKET, socket.SO_BROADCAST, 1)
        self.returns = listening_socket(self.return_port)
        self.team_sockets = [listening_socket(port) for port in self.team_ports]
        self.bad_returns = 0
        self.messages = [0, 0]  # counted against the budget
        self.messages_heard = [0, 0]  # all, whenever sent
        self.message_bytes = 0
        self.illegal_communication = [False, False]
        self.phase_since = 0.0
        self.clock = float(self.half_s)
        self.last_packet_s = -math.inf
        self.still_since = None
        self.over = False
        self.ending = False  # the game ends at the next FINISHED, whichever half it is
        # the fouls' state (fouls.py)
        self.incremental, self.set_judged, self.last_touch_s = [0, 0], False, 0.0
        self.fall_watches, self.activity, self.placed, self.tracks = {}, {}, {}, {}
        # the set plays' state (set_plays.py)
        self.calls = sorted(self.calls, key=lambda call: call.time_s)
        self.restriction = None
        self.set_play_touched, self.indirect, self.kicker = False, False, None
        self.last_touch, self.last_toucher = 0, None
        self.kick_off_defender, self.kick_off_ball_moved = None, False
        # the shoot-out's state (shoot_out.py)
        self.shoot_out_goals, self.winner, self.shot = [0, 0], None, None
        self.mark, self.kicked, self.keeper_touched, self.ball_track = (0.0, 0.0), False, False, []
        self.post_hit, self.striker_released = False, False
        self.shoot_out_initial_s = self.initial_s
        if self.shoot_out == "only":
            self.start_shoot_out(0.0)

    def tick(self, now: float, dt: float) -> None:
        """Referee one tick of ``dt`` s ending at ``now``: listen, judge, send a packet when due."""
        self.listen(now)
        state = self.game.state
        if state in (State.ready, State.set) and self.clock < self.half_s and self.game.game_phase is GamePhase.normal:
            self.clock = max(0.0, self.clock - dt)  # GameController3's main timer
        if self.game.game_phase is GamePhase.penalty_shoot:
            self.shoot_out_tick(now, dt)
        elif state is State.initial and now - self.phase_since >= self.initial_s:
            self.enter(State.standby, now)
        elif state is State.standby and now - self.phase_since >= self.standby_s:
            self.enter(State.ready, now)
        elif state is State.ready:
            self.judge_activity(now)
            self.game.secondary_time = max(0, int(math.ceil(self.ready_s - (now - self.phase_since) - 1e-6)))
            if now - self.phase_since >= self.ready_s or self.all_still(now):
                self.enter(State.set, now)
                self.world.move_ball(0.0, 0.0)
                self.game.secondary_time, self.set_judged = 0, False
        elif state is State.set:
            if not self.set_judged and now - self.phase_since >= self.set_grace_s:
                self.judge_set(now)
            self.judge_activity(now)
            if self.set_judged:
                self.judge_motion_in_set(self.players, now)
            if now - self.phase_since >= self.set_s:
                self.enter(State.playing, now)
                self.start_kick_off(now)
        elif state is State.playing:
            self.play(now, dt)
        elif state is State.finished and now - self.phase_since >= 2.0:
            if self.game.first_half and not self.ending and self.halves > 1:
                self.game.first_half, self.clock = False, float(self.half_s)
                self.game.kicking_team = self.team_numbers[1]
                self.enter(State.initial, now)
            elif self.shoot_out_follows():
                self.shoot_out_initial_s = SHOOT_OUT_AFTER_GAME_S
                self.start_shoot_out(now)
            else:
                self.over = True
        self.penalties(now, dt)
        self.game.secs_remaining = int(math.ceil(self.clock))
        if now - self.last_packet_s >= PACKET_INTERVAL_S - 1e-9:
            self.game.packet_number = (self.game.packet_number + 1) % 256
            self.sender.sendto(encode_game_state(self.game), (self.broadcast, self.game_controller_port))
            self.last_packet_s = now

    def play(self, now: float, dt: float) -> None:
        """PLAYING: the clock, touches, set plays, goals, the ball out, and the fouls."""
        self.clock -= dt
        if self.clock <= 0:
            self.clock = 0.0
            self.enter(State.finished, now)
            return
        self.note_touch(now)
        self.free_kick_clock(now)
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
            self.lift(now, "goal")
            self.game.kicking_team, self.game.set_play = self.team_numbers[1 - scorer], SetPlay.none
            if self.goals_to_end is not None and self.game.teams[scorer].score >= self.goals_to_end:
                self.ending = True
                self.enter(State.finished, now)
            else:
                self.enter(State.ready, now)
            return
        if over_goal_line or abs(by) > HALF_LINE_Y + pitch.BALL_RADIUS:
            self.ball_out(bx, by, now)
        elif self.calls and now >= self.calls[0].time_s:
            self.take_call(bx, by, now)
        self.watch_restriction(now)
        self.judge_play(now, self.kick_off_defender, self.free_kick_kept(now))
        self.judge_activity(now)

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
        """Read the robots' return packets and the teams' messages; count the messages against the budget."""
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
        """The game's score (the shoot-out's goals, which the packet adds to it as GameController3 does, apart)."""
        first, second = (team.score - goals for team, goals in zip(self.game.teams, self.shoot_out_goals))
        return f"{first}:{second}"
