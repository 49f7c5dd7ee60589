"""The fouls the simulated GameController (``referee.py``) calls from the world's ground truth, and the
penalties they bring.

- pushing: walking into a touching opponent, with the rules' exceptions (standing, getting up, the keeper in
  its penalty area, front to front with the ball between, a side touched on the way to the ball);
- illegal position in SET (in the other half, or the defenders in the centre circle) and at the
  kick-off (a defender in the centre circle before the ball moved or 10 s passed), and the free-kick
  distance (an opponent within 0.75 m of the ball after ``free_kick_grace_s``): ``set_plays.py`` says
  when these hold;
- motion in SET (the rules' "Forbidden Motion in Set"): a robot whose torso walked ``MOTION_IN_SET`` or
  turned ``MOTION_IN_SET_TURN`` from where it stood once SET settled (head and arm motion, standing sway
  and getting up are allowed); GameController3's motionInSet, 15 s, penalized in place: the robot is put
  back where it stood and stays there, and the penalty ends by itself;
- fallen or inactive robot (the rules' "Fallen or Inactive Robots", GameController3's fallenInactive,
  45 s, not incremental), in READY, SET and PLAYING: a fallen robot that does not begin to get up within
  5 s (its body's joints still, ``GET_UP_S``), or that is not up after 2 attempts (3 when another robot
  came near it meanwhile: disturbed); an upright robot that ceased activity for 10 s (``INACTIVE_S``: it
  neither walked nor turned, its head did not move, and the ball was in neither camera's view);
- leaving the field (the torso beyond the 10.4 x 7.4 m carpet, as the rules have it: over a line is no foul),
  local game stuck (nobody touched the ball for 30 s with robots beside it).

Penalties last the rules' times (``PENALTY_S``: 45 s, 15 s in SET; the incremental ones 10 s longer for
each incremental penalty the team had before), counted in READY and PLAYING; a penalized robot is taken
off the carpet, then put back where the rules put it (``Officiating.re_entry``: 0.5 m outside the touchline
nearest to where it was, level with its own penalty mark, facing the field; motion in SET aside: in place). Every foul is a ``Foul`` (time, team, player, penalty, why).
"""

from __future__ import annotations

import math
from collections import deque
from dataclasses import dataclass

import numpy as np

from tafel.representations import field as pitch
from tafel.representations.game import GamePhase, Penalty, State
from tafel.representations.motion import JOINT_NAMES
from tafel.representations.nao import CAMERAS, HORIZONTAL_FOV, VERTICAL_FOV
from tafel.tools.simulation.officiating import Event, Officiating, Player, in_own_penalty_area, left_the_carpet

#: GameController3's penalty durations (s, its champions_cup parameters); the incremental ones grow
PENALTY_S = {Penalty.player_pushing: 45.0, Penalty.illegal_position: 45.0, Penalty.illegal_position_in_set: 15.0,
             Penalty.illegal_motion_in_set: 15.0, Penalty.leaving_the_field: 45.0, Penalty.inactive_player: 45.0,
             Penalty.local_game_stuck: 45.0, Penalty.request_for_pickup: 45.0}
INCREMENTAL = (Penalty.player_pushing, Penalty.illegal_position, Penalty.leaving_the_field)
PENALTY_INCREMENT_S = 10.0  # s longer for each incremental penalty of the team before
CENTRE_CIRCLE_R, FREE_KICK_DISTANCE = pitch.CENTER_CIRCLE_DIAMETER / 2, 750.0  # mm
CONTACT = 330.0  # mm between two torsos: the robots touch
PUSH_SPEED = 80.0  # mm/s towards the other robot over PUSH_WINDOW_S: walking into it
PUSH_WINDOW_S = 0.5  # s: about a step, over which a robot's approach is measured
PUSH_FRONT = math.radians(50.0)  # rad: contact within this of a robot's heading is at its front, beyond at its side
BALL_BETWEEN = 150.0  # mm: the ball this near the line between two robots' torsos (and between them) is between them
FALLEN_HEIGHT = 0.2  # m: a torso lower than this has fallen
LYING_UP = 0.5  # the torso's up axis, vertical part: below it (tilted over 60 degrees) the robot lies
SITTING_UP = 0.7  # ... above it the torso is upright (sitting, kneeling or standing)
STOOD_HEIGHT, STOOD_S = 0.25, 1.0  # m a torso upright above this for s: the robot stood up, its fall is over
GET_UP_S = 5.0  # s (the rules): a fallen robot begins to get up within this
GET_UP_ATTEMPTS, GET_UP_ATTEMPTS_DISTURBED = 2, 3  # the rules: attempts to stand up, more when disturbed
RISEN = 0.06  # m the torso rose above its lowest since the fall: an attempt got it up (or it sat up)
ATTEMPT_FAILED_S = 0.3  # s lying still again after it had risen: the attempt failed
DISTURBED = 400.0  # mm between torsos: another robot disturbs the get-up
JOINT_MOVED = 0.1  # rad a body joint (the head's and hands' aside) turned: the robot moves its body
BODY_JOINTS = np.array([k for k, name in enumerate(JOINT_NAMES) if not name.startswith("Head") and not name.endswith("Hand")])
HEAD_JOINTS = np.array([JOINT_NAMES.index("HeadYaw"), JOINT_NAMES.index("HeadPitch")])
#: activity (the rules: it walks or turns, it searches for or looks at the ball): mm walked, rad turned, rad of head motion
ACTIVE_WALK, ACTIVE_TURN, ACTIVE_HEAD = 50.0, 0.2, 0.1
JUDGED_STATES = (State.ready, State.set, State.playing)  # where GameController3 allows fallenInactive
INACTIVE_S, STUCK_S = 10.0, 30.0  # s without activity (the rules); s without a touch with robots beside the ball
#: mm a robot's torso moved, and rad it turned, from where it stood in SET: it walked (motion in SET)
MOTION_IN_SET, MOTION_IN_SET_TURN = 150.0, 0.35


@dataclass
class FallWatch:
    """A fallen robot, watched until it stood up again: since when (s), its body's joints (rad) when they
    last moved and when (s), its torso's lowest height (m) while lying since the fall or the last failed
    attempt, whether it has risen from there, the failed attempts, whether another robot came near, and since when
    it has stood (s)."""

    since_s: float
    joints: np.ndarray
    moved_s: float
    lowest: float = math.inf
    lain: bool = False
    """it has lain (its torso tilted over 60 degrees) since the fall or the last failed attempt"""
    risen: bool = False
    failed: int = 0
    disturbed: bool = False
    stood_s: float | None = None


@dataclass
class ActivityWatch:
    """An upright robot's last activity: when (s), where its torso stood then (world mm, mm, rad) and its
    head's yaw and pitch (rad)."""

    active_s: float
    x: float
    y: float
    heading: float
    head: np.ndarray


@dataclass
class Foul:
    """A call against one robot: when (s), its team's number, its player number, the penalty, and why."""

    time_s: float
    team: int
    player: int
    penalty: Penalty
    reason: str


@dataclass
class Push:
    """A pushing foul: who pushed whom, and where their torsos were (world mm) before the pusher was taken off."""

    pusher: Player
    pushed: Player
    pusher_at: tuple[float, float]
    pushed_at: tuple[float, float]


class Fouls(Officiating):
    """The referee's part that calls fouls and counts penalties down (its state is the ``Referee``'s)."""

    fouls: list[Foul]
    incremental: list[int]
    """incremental penalties per team so far"""
    fall_watches: dict[int, FallWatch]
    """the fallen robots (by index)"""
    activity: dict[int, ActivityWatch]
    """the robots' last activity (by index)"""
    placed: dict[int, tuple[float, float, float]]
    """world mm, mm, rad: where each robot stood once SET settled (by index), for motion in SET"""
    set_judged: bool
    last_touch_s: float
    """s: the ball's last touch (or the last call of a local game stuck)"""
    tracks: dict[int, deque[tuple[float, float, float]]]
    """per robot index: its torso's (s, x mm, y mm) over the last ``PUSH_WINDOW_S`` of PLAYING, for pushing"""

    def enter(self, state: State, now: float) -> None:
        """A new state: a SET's places are taken afresh; activity and falls, judged in READY, SET and PLAYING
        only, are watched afresh after any other state."""
        super().enter(state, now)
        self.placed.clear()
        if state not in JUDGED_STATES:
            self.activity.clear()
            self.fall_watches.clear()

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

    def judge_motion_in_set(self, players: list[Player], now: float, reason: str = "walked in SET") -> None:
        """SET: the ``players`` may move their heads and arms, sway and get up, but not walk: where each stands
        (upright, not fallen) is its place; its torso ``MOTION_IN_SET`` from it, or turned ``MOTION_IN_SET_TURN``,
        is the rules' motion in SET (GameController3's motionInSet, 15 s, in place)."""
        for player in players:
            if player.penalized_until_s >= 0:
                continue
            x, y, heading = self.world.robot_pose(player.index)
            position, rotation = self.world.robots[player.index].torso_pose(self.world.data)
            if float(position[2]) < FALLEN_HEIGHT or float(rotation[2, 2]) < LYING_UP or player.index in self.fall_watches:
                self.placed.pop(player.index, None)  # getting up is allowed: its place is where it stands up
                continue
            px, py, ph = self.placed.setdefault(player.index, (x, y, heading))
            if math.hypot(x - px, y - py) > MOTION_IN_SET or abs(math.remainder(heading - ph, math.tau)) > MOTION_IN_SET_TURN:
                self.penalize(player, Penalty.illegal_motion_in_set, now, reason)

    def judge_play(self, now: float, kick_off_defender: int | None, free_kick: bool) -> None:
        """The fouls of PLAYING, from where the robots are and how they move; team index ``kick_off_defender``
        is kept out of the centre circle, and while ``free_kick`` the kicking team's opponents from the ball."""
        bx, by = self.world.ball_position()
        kicking = self.team_index(self.game.kicking_team)
        for player in self.on_field():
            x, y, _ = self.world.robot_pose(player.index)
            if left_the_carpet(x, y):
                self.penalize(player, Penalty.leaving_the_field, now, "left the field")
            elif player.team == kick_off_defender and math.hypot(x, y) < CENTRE_CIRCLE_R:
                self.penalize(player, Penalty.illegal_position, now, "entered the centre circle at the opponents' kick-off")
            elif free_kick and player.team != kicking and math.hypot(x - bx, y - by) < FREE_KICK_DISTANCE - 50.0:
                self.penalize(player, Penalty.illegal_position, now,
                              f"within 0.75 m of the ball at the opponents' {self.game.set_play.name}")
        self.judge_pushing(now, bx, by)
        if now - self.last_touch_s >= STUCK_S:
            near = sorted((math.hypot(bx - x, by - y), p.index) for p in self.on_field() for x, y, _ in [self.world.robot_pose(p.index)])
            if near and near[0][0] < 500.0:
                self.penalize(self.players[near[0][1]], Penalty.local_game_stuck, now, f"nobody played the ball for {STUCK_S:g} s")
            self.last_touch_s = now

    def judge_pushing(self, now: float, bx: float, by: float) -> Push | None:
        """The rules' pushing (forceful contact with an opponent): a robot whose torso approached a touching
        (``CONTACT``) opponent faster than ``PUSH_SPEED`` over the last ``PUSH_WINDOW_S`` (a step: a walk's
        sway alone reaches 250 mm/s for an instant) walked into it. Of two, only the one that approached
        faster pushed. The rules' exceptions: a stationary robot (also one kicking: its torso stays), one
        getting up (fallen), a goalkeeper in its own penalty area, front to front contact with the ball
        between, and a robot proceeding to the ball that touches with its side. Returns the push it called."""
        field = self.on_field()
        for index in set(self.tracks) - {player.index for player in field}:
            del self.tracks[index]  # taken off the field: its way back is no walk
        for player in field:
            x, y, _ = self.world.robot_pose(player.index)
            track = self.tracks.setdefault(player.index, deque())
            if track and now - track[-1][0] > PUSH_WINDOW_S:
                track.clear()  # PLAYING anew: the referee may have placed it meanwhile
            track.append((now, x, y))
            while len(track) > 2 and now - track[1][0] >= PUSH_WINDOW_S:
                track.popleft()
        for k, a in enumerate(field):
            for b in field[k + 1:]:
                if a.team == b.team:
                    continue
                ax, ay, _ = self.world.robot_pose(a.index)
                bx_, by_, _ = self.world.robot_pose(b.index)
                if math.hypot(bx_ - ax, by_ - ay) >= CONTACT:
                    continue
                # only the faster one can have pushed: excused, the other was pushed, not pushing
                speed, pusher, pushed = max((self.approach(a, b), a, b), (self.approach(b, a), b, a), key=lambda t: t[0])
                if speed > PUSH_SPEED and not self.may_touch(pusher, pushed, bx, by):
                    push = Push(pusher, pushed, self.world.robot_pose(pusher.index)[:2], self.world.robot_pose(pushed.index)[:2])
                    self.penalize(pusher, Penalty.player_pushing, now, f"walked into team {self.team_numbers[pushed.team]} player {pushed.number}")
                    return push
        return None

    def walked(self, player: Player) -> tuple[float, float, float]:
        """mm, mm, s: how far the robot's torso moved over its track (``PUSH_WINDOW_S``), and in what time."""
        track = self.tracks.get(player.index)
        if not track:
            return 0.0, 0.0, 0.0
        (t0, x0, y0), (t1, x1, y1) = track[0], track[-1]
        return x1 - x0, y1 - y0, t1 - t0

    def approach(self, player: Player, other: Player) -> float:
        """mm/s the robot's torso moved towards the other's over its track (``PUSH_WINDOW_S``)."""
        dx, dy, seconds = self.walked(player)
        if seconds <= 0.0:
            return 0.0
        x, y, _ = self.world.robot_pose(player.index)
        ox, oy, _ = self.world.robot_pose(other.index)
        return (dx * (ox - x) + dy * (oy - y)) / max(math.hypot(ox - x, oy - y), 1.0) / seconds

    def may_touch(self, player: Player, other: Player, bx: float, by: float) -> bool:
        """The rules' exceptions to pushing for ``player`` touching ``other`` (the ball at ``bx``, ``by``)."""
        if player.index in self.fall_watches:
            return True  # getting up
        x, y, heading = self.world.robot_pose(player.index)
        tx, ty, _ = self.team_pose(player)
        keeper = self.game.teams[player.team].goalkeeper == player.number
        if keeper and in_own_penalty_area(tx, ty):
            return True
        ox, oy, other_heading = self.world.robot_pose(other.index)
        to_other = math.atan2(oy - y, ox - x)
        front = abs(math.remainder(to_other - heading, math.tau)) < PUSH_FRONT
        other_front = abs(math.remainder(to_other + math.pi - other_heading, math.tau)) < PUSH_FRONT
        distance = max(math.hypot(ox - x, oy - y), 1.0)
        along = ((bx - x) * (ox - x) + (by - y) * (oy - y)) / distance
        across = abs((bx - x) * (oy - y) - (by - y) * (ox - x)) / distance
        if front and other_front and 0.0 < along < distance and across < BALL_BETWEEN:
            return True
        if not front:  # its side touches: excused while it proceeds to the ball
            dx, dy, _ = self.walked(player)
            moved, ball = math.hypot(dx, dy), math.hypot(bx - x, by - y)
            return moved > 0.0 and (dx * (bx - x) + dy * (by - y)) > 0.5 * moved * max(ball, 1.0)
        return False

    def judge_activity(self, now: float, spared: Player | None = None) -> None:
        """The rules' fallen or inactive robot, for every robot on the field but ``spared``: GameController3's
        fallenInactive (45 s, not incremental)."""
        for player in self.on_field():
            if player is not spared and player.penalized_until_s < 0:
                why = self.fallen(player, now) or self.inactive(player, now)
                if why:
                    self.penalize(player, Penalty.inactive_player, now, why)

    def fallen(self, player: Player, now: float) -> str:
        """Why a fallen robot is called (else ""): it did not begin to get up within ``GET_UP_S`` (its body's
        joints still that long while it is down), or it is not up after ``GET_UP_ATTEMPTS`` attempts
        (``GET_UP_ATTEMPTS_DISTURBED`` when another robot came near). An attempt failed when the robot, having
        risen (sat up, or its torso ``RISEN`` above its lowest), lies still again."""
        robot, index = self.world.robots[player.index], player.index
        position, rotation = robot.torso_pose(self.world.data)
        height, up = float(position[2]), float(rotation[2, 2])
        joints = robot.joint_angles(self.world.data)[BODY_JOINTS]
        watch = self.fall_watches.get(index)
        lying = height < FALLEN_HEIGHT or up < LYING_UP
        if watch is None:
            if not lying:
                return ""
            watch = self.fall_watches[index] = FallWatch(now, joints, now)
        if height >= STOOD_HEIGHT and up >= SITTING_UP:
            watch.stood_s = now if watch.stood_s is None else watch.stood_s
            if now - watch.stood_s >= STOOD_S:
                del self.fall_watches[index]
                return ""
        else:
            watch.stood_s = None
        if float(np.max(np.abs(joints - watch.joints))) > JOINT_MOVED:
            watch.joints, watch.moved_s = joints, now
        if up < LYING_UP and not watch.risen:
            watch.lain, watch.lowest = True, min(watch.lowest, height)
        if watch.lain and not watch.risen:
            watch.risen = up >= SITTING_UP or height > watch.lowest + RISEN
        elif watch.risen and up < LYING_UP and now - watch.moved_s >= ATTEMPT_FAILED_S:  # lies still again
            watch.failed, watch.risen, watch.lowest = watch.failed + 1, False, height
        x, y, _ = self.world.robot_pose(index)
        watch.disturbed = watch.disturbed or any(
            math.hypot(ox - x, oy - y) < DISTURBED for other in self.on_field() if other is not player
            for ox, oy, _ in [self.world.robot_pose(other.index)])
        attempts = GET_UP_ATTEMPTS_DISTURBED if watch.disturbed else GET_UP_ATTEMPTS
        if watch.failed >= attempts:
            return f"fallen robot: not up after {watch.failed} attempts"
        if now - watch.moved_s >= GET_UP_S:
            return f"fallen robot: no get-up within {GET_UP_S:g} s"
        return ""

    def inactive(self, player: Player, now: float) -> str:
        """Why an inactive robot is called (else ""): it ceased activity for ``INACTIVE_S``. Active is (the
        rules) walking or turning (``ACTIVE_WALK``, ``ACTIVE_TURN`` from where it last was active), searching
        for the ball (the head moved ``ACTIVE_HEAD``) or looking at it (the ball in a camera's view)."""
        x, y, heading = self.world.robot_pose(player.index)
        head = self.world.robots[player.index].joint_angles(self.world.data)[HEAD_JOINTS]
        watch = self.activity.get(player.index)
        if (watch is None or math.hypot(x - watch.x, y - watch.y) > ACTIVE_WALK
                or abs(math.remainder(heading - watch.heading, math.tau)) > ACTIVE_TURN
                or float(np.max(np.abs(head - watch.head))) > ACTIVE_HEAD or self.sees_ball(player)):
            self.activity[player.index] = ActivityWatch(now, x, y, heading, head)
            return ""
        if now - watch.active_s >= INACTIVE_S:
            return f"inactive robot: no activity for {INACTIVE_S:g} s"
        return ""

    def sees_ball(self, player: Player) -> bool:
        """The ball's centre in the top or bottom camera's field of view (ground truth)."""
        robot, data = self.world.robots[player.index], self.world.data
        ball = data.xpos[self.world.ball.body]
        for camera in CAMERAS:
            forward, left, up = robot.camera_rotation(data, camera.name).T
            direction = ball - data.cam_xpos[robot.model.camera(robot.camera(camera.name)).id]
            ahead = float(direction @ forward)
            if (ahead > 0.0 and abs(math.atan2(float(direction @ left), ahead)) <= HORIZONTAL_FOV / 2
                    and abs(math.atan2(float(direction @ up), ahead)) <= VERTICAL_FOV / 2):
                return True
        return False

    def penalize(self, player: Player, penalty: Penalty, now: float, reason: str = "") -> None:
        robot = self.game.teams[player.team].players[player.number - 1]
        seconds = PENALTY_S.get(penalty, 45.0)
        if penalty in INCREMENTAL:
            seconds += PENALTY_INCREMENT_S * self.incremental[player.team]
            self.incremental[player.team] += 1
        robot.penalty, player.penalized_until_s, player.penalty_left_s = penalty, now + seconds, seconds
        self.fall_watches.pop(player.index, None)
        self.activity.pop(player.index, None)
        if penalty is Penalty.illegal_motion_in_set:  # the rules: penalized in place, put back where it stood
            x, y, heading = self.placed.pop(player.index, self.world.robot_pose(player.index))
            self.world.move_robot(player.index, x, y, heading)
        else:
            player.return_side = 1.0 if self.team_pose(player)[1] >= 0.0 else -1.0
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
                if robot.penalty is not Penalty.illegal_motion_in_set:  # that one ends where the robot stands
                    self.world.move_robot(player.index, *self.re_entry(player))
                robot.penalty, robot.secs_till_unpenalised, player.penalized_until_s = Penalty.none, 0, -1.0
