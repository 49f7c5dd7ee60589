"""SoccerBehavior: plays the game as the GameController says and the rules allow, in the role the team
agreed on, walking around the robots it knows of. The decisions are options (``options/soccer.py``,
root ``PlaySoccer``); this module runs them once a frame and holds what they share: the blackboard,
the parameters and the helpers below."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from tafel.core import Module, bounded, fields_of, provides, requires, uses
from tafel.debug import Canvas, DebugRequest
from tafel.modules.behavior.kicking import KickParameters, goal_direction, kick_tuning
from tafel.modules.behavior.options import OptionRunner
from tafel.modules.behavior.options.soccer import FREE_KICKS, OWN_GOAL_X, PlaySoccer
from tafel.modules.behavior.paths import Disc
from tafel.representations import field as pitch
from tafel.representations.behavior import ActivationGraph, OptionGraph
from tafel.representations.game import GameState, SetPlay
from tafel.representations.infrastructure import FrameInfo
from tafel.representations.modeling import BallModel, RobotPose
from tafel.representations.motion_control import MotionInfo, MotionRequest, MotionType, Odometry
from tafel.representations.obstacles import ROBOT_RADIUS, Obstacles
from tafel.representations.team import PlayerRole, TeamMates

OPPONENT_PENALTY_MARK_X = pitch.LENGTH / 2 - pitch.PENALTY_MARK_DISTANCE


@requires(GameState, PlayerRole, BallModel, Odometry, MotionInfo, FrameInfo)
@uses(RobotPose, TeamMates, Obstacles)
@provides(MotionRequest, ActivationGraph, OptionGraph)
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
      keeps the goal line; substitutes (penalized) stand still, and so does everybody between the shots
      (FINISHED there ends a shot: the referee places the robots for the next).
    - FINISHED: sit.

    It walks around the robots in ``Obstacles`` (and around the areas the rules keep it out of) by
    ``paths.waypoint``: pushing is a foul.

    Each decision is an option's state (``options/soccer.py``); ``ActivationGraph`` says every frame
    which options are active, in which state and for how long, ``OptionGraph`` what they all are.
    """

    game_state: GameState
    player_role: PlayerRole
    ball_model: BallModel
    odometry: Odometry
    motion_info: MotionInfo
    frame_info: FrameInfo
    robot_pose: RobotPose
    team_mates: TeamMates
    obstacles: Obstacles
    motion_request: MotionRequest
    activation_graph: ActivationGraph
    option_graph: OptionGraph

    show_target = DebugRequest("where the player wants to be, on the field canvas", name="SoccerBehavior:draw_target")
    kick_tuning = kick_tuning()

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

    parameters: Parameters

    def __init__(self) -> None:
        self.options = OptionRunner(PlaySoccer)
        self.keep_out: list[Disc] = []
        """field discs (mm) the rules keep the team out of this frame: the set plays' options add them"""
        self.indirect = False
        """this frame's kick is an own free kick's: indirect, never straight at the goal"""

    def execute(self) -> None:
        out = self.motion_request
        if not self.option_graph.root:  # the static graph, for the views: written once
            graph = self.options.graph()
            self.option_graph.root, self.option_graph.options = graph.root, graph.options
        busy = {info.name: getattr(out, info.name) for info in fields_of(MotionRequest)} if self.motion_info.busy else None
        self.keep_out, self.indirect = [], False
        out.motion = MotionType.stand
        self.options.run(self, self.frame_info.time_s, self.activation_graph)
        if busy is not None:  # a kick or get-up plays to its end: the options went on, the request stays
            for name, value in busy.items():
                setattr(out, name, value)

    # ------------------------------------------------------------------------ what the options do
    def stand(self) -> None:
        self.motion_request.motion = MotionType.stand

    def sit(self) -> None:
        self.motion_request.motion = MotionType.sit

    def turn(self, speed: float) -> None:
        """Turn on the spot at ``speed`` rad/s."""
        out = self.motion_request
        out.motion, out.walk_x, out.walk_y, out.walk_rotation = MotionType.walk, 0.0, 0.0, speed

    def walk_to(self, x: float, y: float, rotation: float) -> None:
        """Walk to a pose in the robot frame (mm, mm, rad)."""
        out = self.motion_request
        out.motion, out.target_x, out.target_y, out.target_rotation = MotionType.walk_to, x, y, rotation

    def draw_target(self, x: float, y: float, rotation: float) -> None:
        if self.show_target:
            self.show_target.canvas(Canvas.FIELD).robot_pose(x, y, rotation, color="orange")

    # ------------------------------------------------------------------------- what they ask about
    def opponents_set_play(self) -> bool:
        """Whether an opponents' free kick or penalty kick is on (``Play`` ends it after 30 s)."""
        game = self.game_state
        return game.set_play in (*FREE_KICKS, SetPlay.penalty_kick) and game.kicking_team != game.team_number

    def own_free_kick(self) -> bool:
        game = self.game_state
        return game.set_play in FREE_KICKS and game.kicking_team == game.team_number

    def ball_on_field(self) -> tuple[float, float] | None:
        """The ball in field mm: the own sighting, else a teammate's; None when nobody knows."""
        ball, pose = self.ball_model, self.robot_pose
        return ball.field_position(pose) if ball.valid and pose.valid else self.team_ball()

    def facing_ball(self, x: float, y: float) -> float:
        """rad (field) from (x, y) towards the ball (the centre spot when nobody knows where it is)."""
        bx, by = self.ball_on_field() or (0.0, 0.0)
        return math.atan2(by - y, bx - x)

    def indirect_direction(self) -> float:
        """rad in the robot frame for an own free kick: ahead and towards the middle, not at the goal."""
        pose, ball = self.robot_pose, self.ball_model
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

    def keeper_clears(self) -> bool:
        """Whether the ball is in the own penalty area and near enough for the goalkeeper to clear it."""
        ball, ball_on_field = self.ball_model, self.ball_on_field()
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
