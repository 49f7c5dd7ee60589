"""SoccerBehavior: plays the game as the GameController says, in the role the team agreed on."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from tafel.core import Module, bounded, provides, requires, uses
from tafel.debug import drawing, request
from tafel.modules.behavior.kicking import KickParameters, approach_and_kick, goal_direction
from tafel.representations import field as pitch
from tafel.representations.game import GameState, State
from tafel.representations.infrastructure import FrameInfo
from tafel.representations.modeling import BallModel, RobotPose
from tafel.representations.motion_control import MotionInfo, MotionRequest, MotionType, Odometry
from tafel.representations.team import PlayerRole, Role, TeamMates

DRAW = request("SoccerBehavior:draw_target", "where the player wants to be, on the field canvas")
OWN_GOAL_X = -pitch.LENGTH / 2


@requires(GameState, PlayerRole, BallModel, Odometry, MotionInfo, FrameInfo)
@uses(RobotPose, TeamMates)
@provides(MotionRequest)
class SoccerBehavior(Module):
    """What the robot does in each game state:

    - INITIAL, STANDBY, SET, and while penalized: stand (the head looks around meanwhile);
    - READY: walk to the kickoff position of its role (``ready_*``, field mm and rad, in the own half; the striker nearer the centre when its team kicks off);
    - PLAYING: the role's play. The striker kicks towards the opponent goal (``kicking``), searching
      by turning when no one knows where the ball is; the goalkeeper stands between the ball and the
      goal's centre and clears a ball that comes into its penalty area; the supporter waits behind
      and beside the ball; defenders stand between the ball and the own goal. Without an own sighting
      they go by a teammate's ball.
    - FINISHED: sit.
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
        arrived: float = bounded(10.0, 1000.0, 120.0)
        """mm from a position that counts as there (then the robot stands)"""
        team_ball_age: float = bounded(0.0, 30.0, 3.0)
        """s: a teammate's ball older than this is not used"""
        supporter_offset: list[float] = field(default_factory=lambda: [-1200.0, 900.0])
        """mm behind and beside the ball (beside: towards the field's centre line)"""
        keeper_clear_distance: float = bounded(0.0, 3000.0, 1200.0)
        """mm: a ball this near the goalkeeper, in its penalty area, is cleared"""

    def execute(self) -> None:
        game, out = self.game_state, self.motion_request
        if self.motion_info.busy:  # a kick or get-up plays to its end
            return
        out.motion = MotionType.stand
        if game.state is State.finished:
            out.motion = MotionType.sit
        elif game.penalized or game.state in (State.initial, State.standby, State.set):
            return
        elif game.state is State.ready:
            role = self.player_role.role
            kicking_off = role is Role.striker and game.kicking_team == game.team_number
            name = "striker_kicking_off" if kicking_off else role.name if role is not Role.none else "defender"
            self.go_to(*getattr(self.parameters, f"ready_{name}"))
        elif game.state is State.playing:
            self.play(self.player_role.role)

    def play(self, role: Role) -> None:
        ball, p, out, pose = self.ball_model, self.parameters, self.motion_request, self.robot_pose
        ball_on_field = ball.field_position(pose) if ball.valid and pose.valid else self.team_ball()
        if role is Role.striker or (role is Role.goalkeeper and ball.valid and self.keeper_clears(ball_on_field)):
            if ball.valid:
                approach_and_kick(ball, goal_direction(ball, pose, self.odometry), p, out)
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

    def go_to(self, x: float, y: float, rotation: float) -> None:
        """Walk to a field pose (mm, mm, rad); stand once there; look around while the pose is not known."""
        pose, out = self.robot_pose, self.motion_request
        if DRAW:
            drawing("field").robot_pose(x, y, rotation, color="orange")
        if not pose.valid:
            out.motion, out.walk_x, out.walk_y, out.walk_rotation = MotionType.walk, 0.0, 0.0, 0.3
            return
        target_x, target_y = pose.to_robot(x, y)
        turn = math.remainder(rotation - pose.rotation, math.tau)
        if math.hypot(target_x, target_y) < self.parameters.arrived and abs(turn) < 0.15:
            out.motion = MotionType.stand
            return
        out.motion, out.target_x, out.target_y, out.target_rotation = MotionType.walk_to, target_x, target_y, turn
