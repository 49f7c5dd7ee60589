"""The soccer behaviour's options, root first: ``PlaySoccer`` follows the GameController, ``Play`` the
rules' set plays, then each role's option and ``GoTo``. Each state's method checks its transitions,
then acts; ``b`` is the ``SoccerBehavior`` module (its blackboard, parameters and helpers).

The set plays restrict the roles through ``b.keep_out`` (field discs nobody of the team may enter now)
and ``b.indirect`` (an own free kick: never straight at the goal), which the states of ``PlaySoccer``
and ``Play`` set before they call the role.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

from tafel.modules.behavior.kicking import approach_and_kick
from tafel.modules.behavior.options.framework import Next, Option, common, state
from tafel.modules.behavior.passing import lane_clearance
from tafel.modules.behavior.paths import outside
from tafel.representations import field as pitch
from tafel.representations.game import GamePhase, SetPlay, State
from tafel.representations.geometry import Pose2D
from tafel.representations.motion_control import MotionType, WalkKick
from tafel.representations.obstacles import ObstacleKind
from tafel.representations.team import Role

if TYPE_CHECKING:
    from tafel.modules.behavior.soccer_behavior import SoccerBehavior

OWN_GOAL_X = -pitch.LENGTH / 2
#: the rules' set plays with a free kick: the other team keeps FREE_KICK_DISTANCE from the ball
FREE_KICKS = (SetPlay.goal_kick, SetPlay.pushing_free_kick, SetPlay.corner_kick, SetPlay.kick_in)
FREE_KICK_DISTANCE = 750.0  # mm, the rules
FREE_KICK_S = 30.0  # s: then the set play is over, touched or not (the GameController says so too)
KICK_OFF_S = 10.0  # s of PLAYING the defending team stays out of the centre circle, unless the ball moved
BALL_MOVED = 200.0  # mm from the centre spot: the kick-off ball has moved
LOST_TURN = 0.3  # rad/s: turning (the head looks around) while the robot does not know where it is
#: READY from the opponent half: the robot crosses the halfway line first (to CROSSED mm into the own half), at
#: least CROSS_BESIDE mm beside the centre, where the other team's kick-off places stand: in SET a robot in the
#: other half is penalized
CROSSED, CROSS_BESIDE = 250.0, pitch.CENTER_CIRCLE_DIAMETER / 2 + 500.0
#: s the shoot-out striker stands after its kick before it judges it; mm from its feet a ball that did not go lies
SHOT_SETTLE_S, SHOT_MISSED = 1.0, 300.0
#: rad the shoot-out kick's direction by the pose may differ from the one by where the referee placed the striker
SHOT_POSE_TRUST = 0.6
#: mm the supporter waits at least in front of the opponent goal line (out of the keeper's way) and inside the touchlines
SUPPORT_GOAL_GAP, SUPPORT_TOUCHLINE_GAP = 1200.0, 400.0
#: rad between the way to the kick's spot and the kick's heading beyond which the striker would walk there backwards,
#: where it sees nothing (robots are seen within 100 degrees of the heading): it faces the way instead while the
#: spot is farther than FACE_BACK_WAY mm (then it turns to the kick)
BACKWARDS, FACE_BACK_WAY = math.radians(100.0), 150.0


class GoTo(Option["SoccerBehavior"]):
    """Walk to a field pose, out of the areas the rules close and around the robots in the way."""

    @dataclass
    class Args:
        x: float
        """field mm"""
        y: float
        """field mm"""
        rotation: float
        """field rad"""

    args: Args

    @common(to=("lost", "walk", "there"))
    def where_am_i(self, b: SoccerBehavior) -> Next:
        if not b.robot_pose.valid:
            return "lost"
        x, y, rotation = self.target(b)
        target_x, target_y = b.robot_pose.to_robot(x, y)
        turn = math.remainder(rotation - b.robot_pose.rotation, math.tau)
        return "there" if math.hypot(target_x, target_y) < b.parameters.arrived and abs(turn) < 0.15 else "walk"

    @state(initial=True)
    def walk(self, b: SoccerBehavior) -> None:
        """Walk to the pose; round a robot or a closed area in the way, facing the way meanwhile."""
        x, y, rotation = self.target(b)
        pose = b.robot_pose
        target_x, target_y = pose.to_robot(x, y)
        turn = math.remainder(rotation - pose.rotation, math.tau)
        zones = [(*pose.to_robot(cx, cy), radius) for cx, cy, radius in b.keep_out]
        way_x, way_y, detoured = b.avoid(target_x, target_y, zones)
        if detoured:  # face the way while walking round
            turn = math.atan2(way_y, way_x)
        b.walk_to(way_x, way_y, turn)

    @state(final=True)
    def there(self, b: SoccerBehavior) -> None:
        """Stand: the pose is reached."""
        self.target(b)
        b.stand()

    @state
    def lost(self, b: SoccerBehavior) -> None:
        """Turn on the spot while the robot does not know where it is (the head looks around)."""
        b.turn(LOST_TURN)

    def target(self, b: SoccerBehavior) -> tuple[float, float, float]:
        """The pose moved out of the closed areas (and drawn, on request)."""
        x, y = outside(self.args.x, self.args.y, b.keep_out)
        b.draw_target(x, y, self.args.rotation)
        return x, y, self.args.rotation


class Striker(Option["SoccerBehavior"]):
    """Get the ball to the opponent goal: kick it there (an own free kick: ahead and towards the middle),
    go by a teammate's ball without an own sighting, search by turning without any. While an opponent
    nearer the ball plays it, hold back (pushing is a foul); after ``hold_max_s`` challenge for it. While the
    own goalkeeper nearer the ball plays it in its penalty area, hold back too, on the field's side."""

    calls = (GoTo,)

    @common(to=("wait_outside", "kick", "hold_back", "challenge", "to_teammates_ball", "search"))
    def what_is_known(self, b: SoccerBehavior) -> Next:
        ball, p = b.ball_on_field(), b.parameters
        if b.keep_out and b.set_play_ball() is not None:
            return "wait_outside"
        if b.ball_model.valid:
            if self.state == "challenge" and self.time_in_state < p.challenge_s:
                return "challenge"
            if self.state == "hold_back" and self.time_in_state >= p.hold_max_s:
                return "challenge"
            return "hold_back" if b.contested(holding=self.state == "hold_back") or b.keeper_plays() else "kick"
        if ball is not None and b.robot_pose.valid:
            return "to_teammates_ball"
        return "search"

    @state(initial=True)
    def search(self, b: SoccerBehavior) -> None:
        """Nobody knows where the ball is: turn on the spot (the head searches), towards the side the ball was
        last seen on (``ball_search.SearchTurn``; a teammate's ball is gone to, not searched)."""
        b.turn(b.ball_search.direction(b.ball_model, b.robot_pose, None) * b.parameters.search_turn)

    @state
    def kick(self, b: SoccerBehavior) -> None:
        """Walk behind the ball on the kick's line and kick (``kicking.approach_and_kick``); far from the
        spot, facing the way (so that the robot sees what it walks into), round the robots in it; never
        backwards to a spot behind it (``BACKWARDS``): it faces that way too."""
        ball, p, out = b.ball_model, b.parameters, b.motion_request
        direction, kick, strength = b.kick_plan()  # a shot, or a pass by the pass rule (``passing.py``)
        approach_and_kick(ball, direction, kick, out, strength, b.obstacles)  # no keyframe kick with a robot close behind
        if out.motion is MotionType.walk_to and math.hypot(ball.x, ball.y) > p.near_ball:  # near it a duel is no push
            x, y, detoured = b.avoid(out.target_x, out.target_y)
            if detoured or math.hypot(x, y) > p.face_the_way:
                out.target_rotation = math.atan2(y, x)
            if detoured:  # on the way round, no walk kick (it would go where the detour faces)
                out.walk_kick = WalkKick.none
            out.target_x, out.target_y = x, y
        if out.motion is MotionType.walk_to and math.hypot(out.target_x, out.target_y) > FACE_BACK_WAY:
            way = math.atan2(out.target_y, out.target_x)
            if abs(math.remainder(way - out.target_rotation, math.tau)) > BACKWARDS:  # it would walk backwards, blind
                out.target_rotation, out.walk_kick = way, WalkKick.none

    @state
    def hold_back(self, b: SoccerBehavior) -> None:
        """An opponent nearer the ball plays it: wait ``hold_distance`` from the ball, between it and the own
        goal, facing it (round the robots on the way); while the own goalkeeper plays it, where the keeper can pass
        to (``hold_point``), facing the way there while it is farther than ``face_the_way`` (that way is mostly
        sideways, where the robot sees nothing: it walked into an opponent unseen)."""
        x, y, rotation = b.hold_point()
        if b.robot_pose.valid and math.hypot(x, y) > b.parameters.face_the_way and b.keeper_plays():
            rotation = math.atan2(y, x)
        if b.robot_pose.valid:
            fx, fy = b.robot_pose.to_field(x, y)
            self.call(GoTo, x=fx, y=fy, rotation=math.remainder(b.robot_pose.rotation + rotation, math.tau))
        else:
            way_x, way_y, _ = b.avoid(x, y)
            b.walk_to(way_x, way_y, rotation)

    @state
    def challenge(self, b: SoccerBehavior) -> None:
        """Held back for ``hold_max_s``: go for the ball as ``kick`` does, for ``challenge_s``."""
        self.kick(b)

    @state
    def to_teammates_ball(self, b: SoccerBehavior) -> None:
        """Walk to where a teammate sees the ball, facing the opponent goal."""
        bx, by = b.ball_on_field() or (0.0, 0.0)
        self.call(GoTo, x=bx, y=by, rotation=math.atan2(-by, pitch.LENGTH / 2 - bx))

    @state
    def wait_outside(self, b: SoccerBehavior) -> None:
        """The rules keep the team away from the ball (where it was last known, if nobody knows where it is
        now): stand between it and the own goal, just outside."""
        bx, by = b.set_play_ball() or (0.0, 0.0)
        dx, dy = OWN_GOAL_X - bx, -by
        distance = max(math.hypot(dx, dy), 1.0)
        reach = max((radius for cx, cy, radius in b.keep_out if math.hypot(bx - cx, by - cy) < radius), default=0.0)
        reach = max(reach, FREE_KICK_DISTANCE + b.parameters.keep_out_margin)
        x, y = bx + dx / distance * reach, by + dy / distance * reach
        self.call(GoTo, x=x, y=y, rotation=math.atan2(by - y, bx - x))


class Goalkeeper(Option["SoccerBehavior"]):
    """Stand between the ball and the goal's centre; clear a ball that comes near in the penalty area."""

    calls = (GoTo, Striker)

    @state(initial=True, to=("clear",))
    def guard(self, b: SoccerBehavior) -> Next:
        """On the goal line's front, shifted towards the ball's side."""
        if b.ball_model.valid and b.keeper_clears():
            return "clear"
        _, by = b.ball_on_field() or (0.0, 0.0)
        x, y = OWN_GOAL_X + 300.0, max(-500.0, min(500.0, 0.3 * by))
        self.call(GoTo, x=x, y=y, rotation=b.facing_ball(x, y))
        return None

    @state(to=("guard",))
    def clear(self, b: SoccerBehavior) -> Next:
        """The ball is near, in the own penalty area: play it away as the striker does."""
        if not (b.ball_model.valid and b.keeper_clears()):
            return "guard"
        self.call(Striker)
        return None


class Supporter(Option["SoccerBehavior"]):
    """Wait ahead of and beside the ball, open to a pass: the striker passes by the pass rule
    (``passing.py``) to a teammate nearer the opponent goal, and the receiver, then the nearest to the
    ball, becomes the striker."""

    calls = (GoTo,)

    @state(initial=True)
    def support(self, b: SoccerBehavior) -> None:
        """``supporter_offset`` ahead of and beside the ball (beside: towards the field's long axis, or the
        other side when an opponent stands within ``pass_open`` of that spot or ``lane_width`` of the ball's
        way to it and not of the other; the side chosen last is kept while open and its spot inside the
        touchlines, so the supporter does not cross in front of the ball to and fro), at least a metre in front
        of the own goal and ``SUPPORT_GOAL_GAP`` in front of the opponent goal line, ``SUPPORT_TOUCHLINE_GAP``
        inside the touchlines; facing the ball."""
        ball = b.ball_on_field() or (0.0, 0.0)
        ahead, beside = b.parameters.supporter_offset
        x = min(max(OWN_GOAL_X + 1000.0, ball[0] + ahead), pitch.LENGTH / 2 - SUPPORT_GOAL_GAP)
        inward = -math.copysign(1.0, ball[1]) if abs(ball[1]) > 100.0 else 1.0
        limit = pitch.WIDTH / 2 - SUPPORT_TOUCHLINE_GAP
        first = b.support_side if b.support_side and abs(ball[1] + b.support_side * beside) <= limit else inward
        spots = [(x, max(-limit, min(limit, ball[1] + side * beside))) for side in (first, -first)]
        pose, p = b.robot_pose, b.parameters
        opponents = [pose.to_field(o.x, o.y) for o in b.obstacles.obstacles if o.kind is ObstacleKind.robot] if pose.valid else []

        def open_to_pass(spot: tuple[float, float]) -> bool:
            return (all(math.dist(spot, o) >= p.pass_open for o in opponents)
                    and lane_clearance(ball, spot, opponents) >= p.lane_width)

        kept = open_to_pass(spots[0]) or not open_to_pass(spots[1])
        b.support_side = first if kept else -first
        x, y = spots[0] if kept else spots[1]
        self.call(GoTo, x=x, y=y, rotation=b.facing_ball(x, y))


class Defender(Option["SoccerBehavior"]):
    """Stand between the ball and the own goal (also a robot that has no role yet)."""

    calls = (GoTo,)

    @state(initial=True)
    def defend(self, b: SoccerBehavior) -> None:
        """A third of the way from the own goal to the ball, ``defender_spread`` to one side (even player
        numbers left, odd right: two defenders do not walk to the same place)."""
        bx, by = b.ball_on_field() or (0.0, 0.0)
        x, y = OWN_GOAL_X + 0.35 * (bx - OWN_GOAL_X), 0.35 * by + b.defender_side() * b.parameters.defender_spread
        self.call(GoTo, x=x, y=y, rotation=b.facing_ball(x, y))


ROLES: dict[Role, type[Option[SoccerBehavior]]] = {Role.striker: Striker, Role.goalkeeper: Goalkeeper, Role.supporter: Supporter,
                                                   Role.defender: Defender, Role.none: Defender}


class Play(Option["SoccerBehavior"]):
    """PLAYING: the role's play, within the rules of the set play going on."""

    @dataclass
    class Args:
        role: Role

    args: Args
    calls = (Striker, Goalkeeper, Supporter, Defender)

    @state(initial=True, to=("opponents_set_play", "own_free_kick"))
    def play(self, b: SoccerBehavior) -> Next:
        """No set play: the role plays freely."""
        if b.opponents_set_play():
            return "opponents_set_play"
        if b.own_free_kick():
            return "own_free_kick"
        self.call(ROLES[self.args.role])
        return None

    @state(to=("play", "set_play_over"))
    def opponents_set_play(self, b: SoccerBehavior) -> Next:
        """The opponents' free kick or penalty kick: keep 0.75 m (and ``keep_out_margin``) from the ball, or
        from where it was last known while nobody knows where it is."""
        if not b.opponents_set_play():
            return "play"
        if self.time_in_state >= FREE_KICK_S:
            return "set_play_over"
        for ball in b.set_play_balls():  # where it is, or where the rules put it (either side while unsure)
            b.keep_out.append((*ball, FREE_KICK_DISTANCE + b.parameters.keep_out_margin))
        self.call(ROLES[self.args.role])
        return None

    @state(to=("play",))
    def set_play_over(self, b: SoccerBehavior) -> Next:
        """30 s of the opponents' set play passed: it is over whatever the GameController still says."""
        if not b.opponents_set_play():
            return "play"
        self.call(ROLES[self.args.role])
        return None

    @state(to=("play",))
    def own_free_kick(self, b: SoccerBehavior) -> Next:
        """The own free kick is indirect: the ball is played ahead and towards the middle."""
        if not b.own_free_kick():
            return "play"
        b.indirect = True
        self.call(ROLES[self.args.role])
        return None


class ReadyPosition(Option["SoccerBehavior"]):
    """READY: walk to the role's kick-off position (``ready_*``), or the penalty kick's."""

    calls = (GoTo,)

    @common(to=("kick_off", "penalty_kick"))
    def which_set_play(self, b: SoccerBehavior) -> Next:
        return "penalty_kick" if b.game_state.set_play is SetPlay.penalty_kick else "kick_off"

    @state(initial=True)
    def kick_off(self, b: SoccerBehavior) -> None:
        """The role's place in the own half; the striker nearer the centre when its team kicks off. From the
        opponent half, over the halfway line first, beside the centre circle (``CROSS_BESIDE``)."""
        game, role, p = b.game_state, b.player_role.role, b.parameters
        kicking_off = role is Role.striker and game.kicking_team == game.team_number
        name = "striker_kicking_off" if kicking_off else role.name if role is not Role.none else "defender"
        x, y, rotation = getattr(p, f"ready_{name}")
        if name == "defender":  # two defenders: one on each side (even numbers where configured)
            y *= b.defender_side()
        pose = b.robot_pose
        if pose.valid and pose.x > -CROSSED:  # in the opponent half: over the halfway line first, beside the centre
            side = math.copysign(max(abs(pose.y), CROSS_BESIDE), pose.y if pose.y else y or 1.0)
            x, y, rotation = -2 * CROSSED, side, math.atan2(side - pose.y, -2 * CROSSED - pose.x)
        self.go([x, y, rotation])

    @state
    def penalty_kick(self, b: SoccerBehavior) -> None:
        """The kicker behind the penalty mark; the defending keeper on its goal line, the others out of the
        penalty area."""
        game, role, p = b.game_state, b.player_role.role, b.parameters
        ours = game.kicking_team == game.team_number
        if ours and role is Role.striker:
            self.go(p.ready_penalty_kicker)
        elif not ours and role is Role.goalkeeper:
            self.go(p.ready_penalty_keeper)
        else:
            x, y, rotation = getattr(p, f"ready_{role.name if role is not Role.none else 'defender'}")
            if not ours:  # outside the own penalty area
                x = max(x, OWN_GOAL_X + pitch.PENALTY_AREA_LENGTH + p.keep_out_margin)
            self.go([x, y, rotation])

    def go(self, pose: list[float]) -> None:
        self.call(GoTo, x=pose[0], y=pose[1], rotation=pose[2])


class ShootOut(Option["SoccerBehavior"]):
    """A penalty shoot-out in PLAYING: the kicking team's robot kicks at a goal corner once and then stands
    (the rules: the striker may not play the ball again once it clearly moved), the other keeps its goal
    line."""

    calls = (GoTo,)
    placed: Pose2D | None = None
    """the robot's odometry pose as the shot's PLAYING began: where the referee placed it (the rules: the
    striker on the edge of the penalty area, facing the ball and the goal)"""

    @common(to=("search", "shoot", "keep_line"))
    def whose_kick(self, b: SoccerBehavior) -> Next:
        if self.time_in_option <= 0.0 or self.placed is None:
            self.placed = b.odometry.as_pose2d()
        game = b.game_state
        if game.kicking_team != game.team_number:
            return "keep_line"
        if self.state in ("kicking", "settle", "kicked"):
            return None  # the shot is one touch
        return "shoot" if b.ball_model.valid else "search"

    @state(initial=True)
    def search(self, b: SoccerBehavior) -> None:
        """The kicker without a ball: turn on the spot."""
        b.turn(b.parameters.search_turn)

    @state(to=("kicking",))
    def shoot(self, b: SoccerBehavior) -> Next:
        """Kick at the goal's corner on the side away from the keeper's (``shootout_aim`` mm beside the centre).
        Where the goal is: by the pose, unless it is not valid or puts the goal over ``SHOT_POSE_TRUST`` away
        from where the placing puts it (straight ahead of where the robot stood, ``PENALTY_AREA_LENGTH`` away,
        followed by odometry): a mirrored pose would walk the robot round the ball and through it."""
        if b.motion_info.motion is MotionType.kick:
            return "kicking"
        ball, pose, p = b.ball_model, b.robot_pose, b.parameters
        aim = p.shootout_aim if not pose.valid or pose.y <= 0 else -p.shootout_aim
        now = b.odometry.as_pose2d()
        gx, gy = now.to_local(*(self.placed or now).to_global(pitch.PENALTY_AREA_LENGTH, aim))
        direction = math.atan2(gy - ball.y, gx - ball.x)
        if pose.valid:
            fx, fy = pose.to_robot(pitch.LENGTH / 2, aim)
            by_pose = math.atan2(fy - ball.y, fx - ball.x)
            direction = by_pose if abs(math.remainder(by_pose - direction, math.tau)) <= SHOT_POSE_TRUST else direction
        approach_and_kick(ball, direction, b.kick_tuning.apply(p), b.motion_request)
        return None

    @state(to=("settle",))
    def kicking(self, b: SoccerBehavior) -> Next:
        """The kick plays to its end (motion holds its request while busy)."""
        if not b.motion_info.busy and b.motion_info.motion is not MotionType.kick:
            return "settle"
        b.stand()
        return None

    @state(to=("shoot", "kicked"))
    def settle(self, b: SoccerBehavior) -> Next:
        """Stand ``SHOT_SETTLE_S`` after the kick; a ball then still at the feet (``SHOT_MISSED`` mm) did not go:
        the kick missed it, kick again. Else the shot is taken."""
        if self.time_in_state >= SHOT_SETTLE_S:
            ball = b.ball_model
            return "shoot" if ball.valid and math.hypot(ball.x, ball.y) < SHOT_MISSED else "kicked"
        b.stand()
        return None

    @state
    def kicked(self, b: SoccerBehavior) -> None:
        """The shot is taken: stand (the head follows the ball) until the referee ends it."""
        b.stand()

    @state
    def keep_line(self, b: SoccerBehavior) -> None:
        """On the goal line, across from the ball."""
        ball = b.ball_on_field()
        ball_y = ball[1] if ball is not None else 0.0
        x, _, rotation = b.parameters.ready_penalty_keeper
        self.call(GoTo, x=x, y=max(-pitch.GOAL_INNER_WIDTH / 2 + 200.0, min(pitch.GOAL_INNER_WIDTH / 2 - 200.0, ball_y)), rotation=rotation)


GAME_STATES = ("initial", "standby", "ready", "set", "playing", "opponents_kick_off", "penalized", "finished", "shoot_out_wait",
               "shoot_out")


class PlaySoccer(Option["SoccerBehavior"]):
    """The root: what the GameController's state asks for."""

    calls = (ReadyPosition, Play, ShootOut)

    @common(to=GAME_STATES)
    def follow_the_game_controller(self, b: SoccerBehavior) -> Next:
        game = b.game_state
        if game.game_phase is GamePhase.penalty_shoot:  # FINISHED there ends a shot, not the game: stand for the next
            return "penalized" if game.penalized else "shoot_out" if game.state is State.playing else "shoot_out_wait"
        if game.state is State.finished:
            return "finished"
        if game.penalized:
            return "penalized"
        if game.state in (State.initial, State.standby, State.set):
            return game.state.name
        if game.state is State.ready:
            return "ready"
        if self.state == "set" and game.set_play is SetPlay.none and game.kicking_team not in (game.team_number, 255):
            return "opponents_kick_off"  # PLAYING after SET: the opponents kick off
        return "opponents_kick_off" if self.state == "opponents_kick_off" else "playing"

    @state(initial=True)
    def initial(self, b: SoccerBehavior) -> None:
        """INITIAL: stand (the head looks around)."""
        b.stand()

    @state
    def standby(self, b: SoccerBehavior) -> None:
        """STANDBY: stand."""
        b.stand()

    @state
    def ready(self, b: SoccerBehavior) -> None:
        """READY: walk to the kick-off position."""
        self.call(ReadyPosition)

    @state
    def set(self, b: SoccerBehavior) -> None:
        """SET: stand."""
        b.stand()

    @state
    def playing(self, b: SoccerBehavior) -> None:
        """PLAYING: the role's play."""
        self.call(Play, role=b.player_role.role)

    @state(to=("playing",))
    def opponents_kick_off(self, b: SoccerBehavior) -> Next:
        """PLAYING after the opponents' kick-off: out of the centre circle until the ball moved or 10 s passed."""
        ball = b.ball_on_field()
        if self.time_in_state >= KICK_OFF_S or (ball is not None and math.hypot(*ball) > BALL_MOVED):
            return "playing"
        b.keep_out.append((0.0, 0.0, pitch.CENTER_CIRCLE_DIAMETER / 2 + b.parameters.keep_out_margin))
        self.call(Play, role=b.player_role.role)
        return None

    @state
    def penalized(self, b: SoccerBehavior) -> None:
        """Penalized: stand still (the head too) until the GameController unpenalizes."""
        b.stand()

    @state
    def finished(self, b: SoccerBehavior) -> None:
        """FINISHED: sit."""
        b.sit()

    @state
    def shoot_out_wait(self, b: SoccerBehavior) -> None:
        """A penalty shoot-out before a shot's PLAYING and after it (FINISHED): stand, to be placed for the next shot."""
        b.stand()

    @state
    def shoot_out(self, b: SoccerBehavior) -> None:
        """A penalty shoot-out in PLAYING."""
        self.call(ShootOut)


__all__ = ["Defender", "Goalkeeper", "GoTo", "Play", "PlaySoccer", "ReadyPosition", "ShootOut", "Striker", "Supporter"]
