"""SoccerBehavior: plays the game as the GameController says and the rules allow, in the role the team
agreed on, walking around the robots it knows of."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from tafel.core import Module, bounded, provides, requires, uses
from tafel.debug import drawing, request
from tafel.modules.behavior.kicking import KickParameters, approach_and_kick, goal_direction
from tafel.modules.behavior.paths import Disc, outside, waypoint
from tafel.representations import field as pitch
from tafel.representations.game import GamePhase, GameState, SetPlay, State
from tafel.representations.infrastructure import FrameInfo
from tafel.representations.modeling import BallModel, RobotPose
from tafel.representations.motion_control import MotionInfo, MotionRequest, MotionType, Odometry
from tafel.representations.obstacles import ROBOT_RADIUS, Obstacles
from tafel.representations.team import PlayerRole, Role, TeamMates

DRAW = request("SoccerBehavior:draw_target", "where the player wants to be, on the field canvas")
OWN_GOAL_X = -pitch.LENGTH / 2
OPPONENT_PENALTY_MARK_X = pitch.LENGTH / 2 - pitch.PENALTY_MARK_DISTANCE
#: the rules' set plays with a free kick: the other team keeps FREE_KICK_DISTANCE from the ball
FREE_KICKS = (SetPlay.goal_kick, SetPlay.pushing_free_kick, SetPlay.corner_kick, SetPlay.kick_in)
FREE_KICK_DISTANCE = 750.0  # mm, the rules
FREE_KICK_S = 30.0  # s: then the set play is over, touched or not (the GameController says so too)
KICK_OFF_S = 10.0  # s of PLAYING the defending team stays out of the centre circle, unless the ball moved
BALL_MOVED = 200.0  # mm from the centre spot: the kick-off ball has moved


@requires(GameState, PlayerRole, BallModel, Odometry, MotionInfo, FrameInfo)
@uses(RobotPose, TeamMates, Obstacles)
@provides(MotionRequest)
class SoccerBehavior(Module):
    """What the robot does in each game state:

    - INITIAL, STANDBY, SET, and while penalized: stand (the head looks around meanwhile; penalized, it
      holds still);
    - READY: walk to the kickoff position of its role (``ready_*``, field mm and rad, in the own half;
      the striker nearer the centre when its team kicks off). At a penalty kick: the defending
      goalkeeper on its goal line, everybody else outside that penalty area; the kicking team's
      striker behind the penalty mark (``ready_penalty_kicker``);
    - PLAYING: the role's play. The striker kicks towards the opponent goal (``kicking``), searching
      by turning when no one knows where the ball is; the goalkeeper stands between the ball and the
      goal's centre and clears a ball that comes into its penalty area; the supporter waits behind
      and beside the ball; defenders stand between the ball and the own goal. Without an own sighting
      they go by a teammate's ball.
    - The rules' set plays in PLAYING: at the opponents' kick-off nobody enters the centre circle until
      the ball moved or 10 s passed; at the opponents' free kick (goal kick, corner kick, kick-in,
      pushing free kick) and penalty kick nobody comes nearer the ball than 0.75 m (plus
      ``keep_out_margin``) until the set play ends; the own free kicks are indirect, so the striker
      plays the ball to ``indirect_target`` (ahead and towards the middle), not at the goal.
    - Penalty shoot-out: the kicking team's robot kicks at a corner of the goal; the defending team's
      keeps the goal line.
    - FINISHED: sit.

    It walks around the robots in ``Obstacles`` (and around the areas the rules keep it out of) by
    ``paths.waypoint``: pushing is a foul.
    """

    @dataclass
    class Parameters(KickParameters):
        search_turn: float = bounded(0.0, 2.0, 0.6)
        """rad/s while nobody knows where the ball is"""
        ready_goalkeeper: list[float] = field(default_factory=lambda: [-4200.0, 0.0, 0.0])
        """field mm, mm, rad: where each role goes in READY"""
        ready_striker: list[float] = field(default_factory=lambda: [-1000.0, 0.0, 0.0])
        ready_striker_kicking_off: list[float] = field(default_factory=lambda: [-300.0, 0.0, 0.0])
        ready_supporter: list[float] = field(default_factory=lambda: [-1500.0, -1300.0, 0.0])
        ready_defender: list[float] = field(default_factory=lambda: [-2800.0, 1000.0, 0.0])
        ready_penalty_kicker: list[float] = field(default_factory=lambda: [OPPONENT_PENALTY_MARK_X - 500.0, 0.0, 0.0])
        """field mm, mm, rad: the kicking team's striker at a penalty kick"""
        ready_penalty_keeper: list[float] = field(default_factory=lambda: [OWN_GOAL_X + 100.0, 0.0, 0.0])
        """field mm, mm, rad: the defending goalkeeper at a penalty kick and in a shoot-out: on its goal line"""
        arrived: float = bounded(10.0, 1000.0, 120.0)
        """mm from a position that counts as there (then the robot stands)"""
        team_ball_age: float = bounded(0.0, 30.0, 3.0)
        """s: a teammate's ball older than this is not used"""
        supporter_offset: list[float] = field(default_factory=lambda: [-1200.0, 900.0])
        """mm behind and beside the ball (beside: towards the field's centre line)"""
        keeper_clear_distance: float = bounded(0.0, 3000.0, 1200.0)
        """mm: a ball this near the goalkeeper, in its penalty area, is cleared"""
        keep_out_margin: float = bounded(0.0, 1000.0, 300.0)
        """mm kept beyond the rules' distances (the centre circle, 0.75 m from a free kick's ball)"""
        indirect_target: list[float] = field(default_factory=lambda: [1500.0, 0.5])
        """an own free kick goes this far ahead of the ball (mm, at most to the penalty area's front) and
        this share of the way to the field's long axis: never straight at the goal"""
        obstacle_margin: float = bounded(0.0, 1000.0, 150.0)
        """mm kept between this robot's and another robot's footprints on the way"""
        near_ball: float = bounded(0.0, 2000.0, 400.0)
        """mm: within this of the ball the striker goes straight for it (a duel for the ball is no push)"""
        shootout_aim: float = bounded(0.0, 700.0, 450.0)
        """mm beside the goal's centre the shoot-out kick aims (the side away from the keeper)"""

    def __init__(self) -> None:
        self.last_state = State.initial
        self.playing_since = 0.0  # s: when PLAYING began
        self.kick_off_against = False  # this PLAYING began with the opponents' kick-off
        self.set_play_since = 0.0  # s: when the current set play began
        self.last_set_play = SetPlay.none
        self.kick_off_ball_moved = False

    def execute(self) -> None:
        game, out, now = self.game_state, self.motion_request, self.frame_info.time_s
        self.follow_game(game, now)
        if self.motion_info.busy:  # a kick or get-up plays to its end
            return
        out.motion = MotionType.stand
        if game.state is State.finished:
            out.motion = MotionType.sit
        elif game.penalized or game.state in (State.initial, State.standby, State.set):
            return
        elif game.game_phase is GamePhase.penalty_shoot:
            if game.state is State.playing:
                self.shoot_out(game)
        elif game.state is State.ready:
            self.go_to(*self.ready_position(game))
        elif game.state is State.playing:
            self.play(self.player_role.role)

    # ---------------------------------------------------------------------------- the rules' clock
    def follow_game(self, game: GameState, now: float) -> None:
        """Note when PLAYING and set plays began, and whether a kick-off of the opponents is on."""
        opponents_kick = game.kicking_team not in (game.team_number, 255)
        if game.state is State.playing and self.last_state is not State.playing:
            self.playing_since = now
            self.kick_off_against = self.last_state is State.set and game.set_play is SetPlay.none and opponents_kick
            self.kick_off_ball_moved = False
        if game.set_play is not self.last_set_play:
            self.set_play_since = now
        self.last_state, self.last_set_play = game.state, game.set_play

    def kick_off_wait(self) -> bool:
        """Whether the opponents' kick-off still keeps this team out of the centre circle."""
        if not self.kick_off_against or self.frame_info.time_s - self.playing_since >= KICK_OFF_S:
            return False
        ball = self.ball_on_field()
        if ball is not None and math.hypot(*ball) > BALL_MOVED:
            self.kick_off_ball_moved = True
        return not self.kick_off_ball_moved

    def opponents_set_play(self) -> bool:
        """Whether an opponents' free kick or penalty kick is on: keep the distance from the ball."""
        game = self.game_state
        return (game.set_play in (*FREE_KICKS, SetPlay.penalty_kick) and game.kicking_team != game.team_number
                and self.frame_info.time_s - self.set_play_since < FREE_KICK_S)

    def own_free_kick(self) -> bool:
        game = self.game_state
        return game.set_play in FREE_KICKS and game.kicking_team == game.team_number

    def keep_out(self) -> list[Disc]:
        """The field's discs this team must stay out of now (field mm)."""
        discs: list[Disc] = []
        margin = self.parameters.keep_out_margin
        if self.kick_off_wait():
            discs.append((0.0, 0.0, pitch.CENTER_CIRCLE_DIAMETER / 2 + margin))
        ball = self.ball_on_field()
        if self.opponents_set_play() and ball is not None:
            discs.append((*ball, FREE_KICK_DISTANCE + margin))
        return discs

    # --------------------------------------------------------------------------------- positions
    def ready_position(self, game: GameState) -> list[float]:
        p, role = self.parameters, self.player_role.role
        if game.set_play is SetPlay.penalty_kick:
            if game.kicking_team == game.team_number:
                if role is Role.striker:
                    return p.ready_penalty_kicker
            elif role is Role.goalkeeper:
                return p.ready_penalty_keeper
            x, y, rotation = getattr(p, f"ready_{role.name if role is not Role.none else 'defender'}")
            if game.kicking_team != game.team_number:  # outside the own penalty area
                x = max(x, OWN_GOAL_X + pitch.PENALTY_AREA_LENGTH + p.keep_out_margin)
            return [x, y, rotation]
        kicking_off = role is Role.striker and game.kicking_team == game.team_number
        name = "striker_kicking_off" if kicking_off else role.name if role is not Role.none else "defender"
        return getattr(p, f"ready_{name}")

    def ball_on_field(self) -> tuple[float, float] | None:
        ball, pose = self.ball_model, self.robot_pose
        return ball.field_position(pose) if ball.valid and pose.valid else self.team_ball()

    # -------------------------------------------------------------------------------------- play
    def play(self, role: Role) -> None:
        ball, p, out, pose = self.ball_model, self.parameters, self.motion_request, self.robot_pose
        ball_on_field = self.ball_on_field()
        keep_out = self.keep_out()
        if role is Role.striker or (role is Role.goalkeeper and ball.valid and self.keeper_clears(ball_on_field)):
            if keep_out and ball_on_field is not None:
                self.wait_for_ball(ball_on_field, keep_out)
            elif ball.valid:
                direction = self.indirect_direction(ball) if self.own_free_kick() else goal_direction(ball, pose, self.odometry)
                approach_and_kick(ball, direction, p, out)
                if out.motion is MotionType.walk_to and math.hypot(ball.x, ball.y) > p.near_ball:
                    out.target_x, out.target_y = waypoint(out.target_x, out.target_y, self.robot_discs(), p.obstacle_margin)
            elif ball_on_field is not None and pose.valid:
                self.go_to(*ball_on_field, math.atan2(-ball_on_field[1], pitch.LENGTH / 2 - ball_on_field[0]))
            else:
                out.motion, out.walk_x, out.walk_y, out.walk_rotation = MotionType.walk, 0.0, 0.0, p.search_turn
            return
        bx, by = ball_on_field if ball_on_field is not None else (0.0, 0.0)
        if role is Role.goalkeeper:
            x, y = OWN_GOAL_X + 300.0, max(-500.0, min(500.0, 0.3 * by))
        elif role is Role.supporter:
            back, beside = p.supporter_offset
            x, y = max(OWN_GOAL_X + 1000.0, bx + back), by - math.copysign(beside, by) if abs(by) > 100.0 else by + beside
        else:  # defender, or no role yet: between the ball and the own goal
            x, y = OWN_GOAL_X + 0.35 * (bx - OWN_GOAL_X), 0.35 * by
        self.go_to(x, y, math.atan2(by - y, bx - x))

    def wait_for_ball(self, ball: tuple[float, float], keep_out: list[Disc]) -> None:
        """While the rules keep the team away: stand between the ball and the own goal, just outside."""
        bx, by = ball
        dx, dy = OWN_GOAL_X - bx, -by
        distance = max(math.hypot(dx, dy), 1.0)
        reach = max((radius for cx, cy, radius in keep_out if math.hypot(bx - cx, by - cy) < radius), default=0.0)
        reach = max(reach, FREE_KICK_DISTANCE + self.parameters.keep_out_margin)
        x, y = bx + dx / distance * reach, by + dy / distance * reach
        self.go_to(x, y, math.atan2(by - y, bx - x))

    def indirect_direction(self, ball: BallModel) -> float:
        """rad in the robot frame for an own free kick: ahead and towards the middle, not at the goal."""
        pose = self.robot_pose
        if not pose.valid:
            return goal_direction(ball, pose, self.odometry) + 0.6  # beside the goal rather than at it
        bx, by = ball.field_position(pose)
        ahead, inward = self.parameters.indirect_target
        tx = min(bx + ahead, pitch.LENGTH / 2 - pitch.PENALTY_AREA_LENGTH)  # near the goal line: back into the field
        tx = bx - 300.0 if abs(tx - bx) < 300.0 else tx
        ty = by * (1.0 - inward)
        beside, to_line = pitch.GOAL_INNER_WIDTH / 2 + 500.0, max(pitch.LENGTH / 2 - bx, 1.0)
        if tx > bx and abs(by + (ty - by) * to_line / (tx - bx)) < beside:  # it would cross the goal line in the goal
            ty = by + (math.copysign(beside, by if by else 1.0) - by) * (tx - bx) / to_line  # aim beside it instead
        rx, ry = pose.to_robot(tx, ty)
        return math.atan2(ry - ball.y, rx - ball.x)

    def shoot_out(self, game: GameState) -> None:
        """The penalty shoot-out: kick at a goal corner, or keep the goal line."""
        ball, pose, p, out = self.ball_model, self.robot_pose, self.parameters, self.motion_request
        if game.kicking_team == game.team_number:
            if not ball.valid:
                out.motion, out.walk_x, out.walk_y, out.walk_rotation = MotionType.walk, 0.0, 0.0, p.search_turn
                return
            if pose.valid:
                gx, gy = pose.to_robot(pitch.LENGTH / 2, p.shootout_aim if pose.y <= 0 else -p.shootout_aim)
                direction = math.atan2(gy - ball.y, gx - ball.x)
            else:
                direction = goal_direction(ball, pose, self.odometry)
            approach_and_kick(ball, direction, p, out)
            return
        ball_y = self.ball_on_field()[1] if self.ball_on_field() is not None else 0.0
        x, _, rotation = p.ready_penalty_keeper
        self.go_to(x, max(-pitch.GOAL_INNER_WIDTH / 2 + 200.0, min(pitch.GOAL_INNER_WIDTH / 2 - 200.0, ball_y)), rotation)

    def keeper_clears(self, ball_on_field: tuple[float, float] | None) -> bool:
        ball = self.ball_model
        in_area = ball_on_field is not None and ball_on_field[0] < OWN_GOAL_X + pitch.PENALTY_AREA_LENGTH and abs(ball_on_field[1]) < pitch.PENALTY_AREA_WIDTH / 2
        return in_area and math.hypot(ball.x, ball.y) < self.parameters.keeper_clear_distance

    def team_ball(self) -> tuple[float, float] | None:
        """The freshest ball a teammate with a valid pose saw (field mm), if recent enough."""
        heard = [m for m in self.team_mates.mates if m.message.ball_seen and m.message.pose_valid and 0.0 <= m.message.ball_age]
        heard = [m for m in heard if m.age + m.message.ball_age <= self.parameters.team_ball_age]
        if not heard:
            return None
        best = min(heard, key=lambda m: m.age + m.message.ball_age).message
        return best.ball_x, best.ball_y

    def robot_discs(self) -> list[Disc]:
        """The robots known to be near (robot frame), as discs this robot's centre keeps out of."""
        return [(o.x, o.y, o.radius + ROBOT_RADIUS) for o in self.obstacles.obstacles]

    def go_to(self, x: float, y: float, rotation: float) -> None:
        """Walk to a field pose (mm, mm, rad), out of the areas the rules keep the team from and around
        the robots in the way; stand once there; look around while the pose is not known."""
        pose, out, p = self.robot_pose, self.motion_request, self.parameters
        if not pose.valid:
            out.motion, out.walk_x, out.walk_y, out.walk_rotation = MotionType.walk, 0.0, 0.0, 0.3
            return
        keep_out = self.keep_out() if self.game_state.state is State.playing else []
        x, y = outside(x, y, keep_out)
        if DRAW:
            drawing("field").robot_pose(x, y, rotation, color="orange")
        target_x, target_y = pose.to_robot(x, y)
        turn = math.remainder(rotation - pose.rotation, math.tau)
        if math.hypot(target_x, target_y) < p.arrived and abs(turn) < 0.15:
            out.motion = MotionType.stand
            return
        zones = [(*pose.to_robot(cx, cy), radius) for cx, cy, radius in keep_out]
        way_x, way_y = waypoint(target_x, target_y, [*zones, *self.robot_discs()], p.obstacle_margin)
        if (way_x, way_y) != (target_x, target_y):  # a detour: face the way while walking round
            turn = math.atan2(way_y, way_x)
        out.motion, out.target_x, out.target_y, out.target_rotation = MotionType.walk_to, way_x, way_y, turn
