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
- the halves (``half_s`` of playing each; ``halves`` 1 for drills and tests) and the end. The teams keep
  their sides after half time (the rules swap them; here the second half starts as the first);
- a penalty shoot-out as GameController3 runs it (``shoot_out``: after a tied game, after any game, or
  alone): the game phase PENALTYSHOOT, every robot a substitute (penalty 14) but the kicking team's
  striker, on the edge of the penalty area facing the ball on the penalty mark, and the defending
  team's keeper (its lowest player number), on its goal line in the goal's centre; SET, then PLAYING
  with the shot's ``PENALTY_SHOT_S`` on the clock (``secs_remaining``). A shot ends with a goal (the
  team's score and its bit in ``single_shots``), when the ball stops or leaves the field after the
  kick, or when the time is up; then FINISHED, and the other team kicks. ``penalty_shots`` each (the
  rules: three), then sudden death, at most ``sudden_death_shots`` each, while both teams can still win,
  as GameController3 decides it. Each team shoots at the goal it attacked in the game (the robots'
  frames stay as they were; GameController3 takes every shot at one goal and swaps the sides in its
  packet instead, which comes to the same for the robots). Team messages are not counted and fouls
  are not called in the shoot-out;
- set plays the referee calls when told (``calls``, for drills and tests: a kick-in, goal kick, corner
  kick or pushing free kick for a team at a given time, once PLAYING; the ball placed as the set play
  places it).

Every call is an ``Event`` (time, what), every foul a ``Foul`` (time, team, player, penalty, why),
every penalty shot a ``Shot``, and each set play that keeps the defending team away (the opponents'
kick-off: out of the centre circle; a free kick: 0.75 m from the ball) a ``Restriction`` with the
nearest any defender came while it lasted.
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
FREE_KICKS = (SetPlay.goal_kick, SetPlay.pushing_free_kick, SetPlay.corner_kick, SetPlay.kick_in)
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
    halves: int = 2
    shoot_out: str = "never"
    """one of ``SHOOT_OUT``"""
    penalty_shots: int = PENALTY_SHOTS
    sudden_death_shots: int = SUDDEN_DEATH_SHOTS
    calls: list[Call] = field(default_factory=list)
    events: list[Event] = field(default_factory=list)
    fouls: list[Foul] = field(default_factory=list)
    shots: list[Shot] = field(default_factory=list)
    restrictions: list[Restriction] = field(default_factory=list)

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
        if self.shoot_out not in SHOOT_OUT:
            raise ValueError(f"shoot_out takes one of {', '.join(SHOOT_OUT)}, got {self.shoot_out!r}")
        self.calls = sorted(self.calls, key=lambda call: call.time_s)
        self.restriction: Restriction | None = None  # the one going on
        self.shoot_out_goals = [0, 0]
        self.winner: int | None = None  # the shoot-out's winner (team number)
        self.shot: Shot | None = None  # the penalty shot going on
        self.mark = (0.0, 0.0)  # world mm: the penalty mark of the shot going on
        self.kicked = self.keeper_touched = False
        self.ball_track: list[tuple[float, float, float]] = []  # (s, world mm, mm): the ball in the shot's last second
        self.shoot_out_initial_s = self.initial_s
        if self.shoot_out == "only":
            self.start_shoot_out(0.0)

    # ------------------------------------------------------------------------------------ tick
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
                if kicking is not None:
                    self.restrict("kick_off", kicking, now)
        elif state is State.playing:
            self.play(now, dt)
        elif state is State.finished and now - self.phase_since >= 2.0:
            if self.game.first_half and not self.ending and self.halves > 1:
                self.game.first_half, self.clock = False, float(self.half_s)
                self.game.kicking_team = self.team_numbers[1]
                self.enter(State.initial, now)
            elif self.shoot_out == "always" or (self.shoot_out == "tie" and self.game.teams[0].score == self.game.teams[1].score):
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

    def enter(self, state: State, now: float) -> None:
        self.game.state, self.phase_since, self.still_since = state, now, None
        self.events.append(Event(now, state.name.upper()))
        self.lift(now, state.name.upper())

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
            self.lift(now, "touched" if self.set_play_touched else f"{FREE_KICK_S:g} s")
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
            call = self.calls.pop(0)
            kicking = self.team_index(call.team)
            if kicking is not None:
                self.start_set_play(call.set_play, kicking, *self.set_play_spot(call.set_play, kicking, bx, by), now)
        self.judge_play(now)

    def ball_out(self, bx: float, by: float, now: float) -> None:
        """Put the ball back as the rules' set plays do, for the team that did not touch it last."""
        kicking = 1 - self.last_touch
        if abs(by) > HALF_LINE_Y + pitch.BALL_RADIUS:
            play = SetPlay.kick_in
        else:
            defending = 1 if bx > 0 else 0  # the team whose goal line it crossed
            play = SetPlay.goal_kick if kicking == defending else SetPlay.corner_kick
        self.start_set_play(play, kicking, *self.set_play_spot(play, kicking, bx, by), now)

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
        if self.game.set_play in (SetPlay.goal_kick, SetPlay.corner_kick, SetPlay.kick_in, SetPlay.pushing_free_kick):
            if player.team == kicking and not self.set_play_touched:
                self.set_play_touched, self.indirect, self.kicker = True, True, player.index
        elif self.indirect and player.index != self.kicker:
            self.indirect = False

    # ------------------------------------------------------------------------- penalty shoot-out
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
                x, y, heading = player.side.to_world(-1000.0 - 500.0 * player.number, -(HALF_LINE_Y + pitch.BORDER_STRIP + 800.0),
                                                     math.pi / 2)
                self.world.move_robot(player.index, x, y, heading)
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
            self.lift(now, f"{KICK_OFF_S:g} s" if now - self.phase_since >= KICK_OFF_S else "ball moved")
        restriction = self.restriction
        if restriction is not None:
            for distance, number in self.defenders_near():
                if distance < restriction.nearest_mm:
                    restriction.nearest_mm, restriction.nearest_player = distance, number
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
        """The game's score (the shoot-out's goals, which the packet adds to it as GameController3 does, apart)."""
        first, second = (team.score - goals for team, goals in zip(self.game.teams, self.shoot_out_goals))
        return f"{first}:{second}"
