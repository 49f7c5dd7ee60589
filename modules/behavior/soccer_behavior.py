"""SoccerBehavior: plays the game as the GameController says and the rules allow, in the role the team
agreed on, walking around the robots it knows of. The decisions are options (``options/soccer.py``,
root ``PlaySoccer``); this module runs them once a frame and holds what they share: the blackboard,
the parameters and the helpers below."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from tafel.core import Module, bounded, fields_of, provides, requires, uses
from tafel.debug import Canvas, DebugRequest
from tafel.modules.behavior.ball_search import SearchTurn
from tafel.modules.behavior.fair_walk import avoid, keep_from_pushing, stay_on_field
from tafel.modules.behavior.holding_back import contested, hold_point, keeper_plays
from tafel.modules.behavior.kick_choice import kick_plan
from tafel.modules.behavior.kicking import KickParameters, kick_tuning
from tafel.modules.behavior.options import OptionRunner
from tafel.modules.behavior.options.soccer import FREE_KICKS, OWN_GOAL_X, PlaySoccer
from tafel.modules.behavior.passing import PassParameters
from tafel.modules.behavior.paths import Disc
from tafel.modules.behavior.set_play_ball import OPPONENT_PENALTY_MARK_X, note_set_play, set_play_balls, team_ball
from tafel.representations import field as pitch
from tafel.representations.behavior import ActivationGraph, OptionGraph
from tafel.representations.game import GameState, SetPlay
from tafel.representations.infrastructure import FrameInfo
from tafel.representations.modeling import BallModel, RobotPose
from tafel.representations.motion_control import MotionInfo, MotionRequest, MotionType, Odometry, WalkKick
from tafel.representations.obstacles import Obstacles, RobotsPercept
from tafel.representations.team import PlayerRole, TeamMates


@requires(GameState, PlayerRole, BallModel, Odometry, MotionInfo, FrameInfo)
@uses(RobotPose, TeamMates, Obstacles, RobotsPercept)
@provides(MotionRequest, ActivationGraph, OptionGraph)
class SoccerBehavior(Module):
    """What the robot does in each game state:

    - INITIAL, STANDBY, SET, and while penalized: stand (the head looks around meanwhile; penalized, it
      holds still);
    - READY: walk to the kickoff position of its role (``ready_*``, field mm and rad, in the own half;
      the striker nearer the centre when its team kicks off). At a penalty kick: the defending
      goalkeeper on its goal line, everybody else outside that penalty area; the kicking team's
      striker behind the penalty mark (``ready_penalty_kicker``);
    - PLAYING: the role's play. The striker kicks through the goal mouth's most open lane (``kicking``), or
      passes to a teammate better placed to score by the pass rule of ``passing.py`` (``kick_plan``), searching
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
    ``paths.detour``, keeping ``obstacle_margin`` between footprints and stopping short of a robot that
    stands where it wants to go: pushing is a foul. When an opponent is nearer the ball (``contested``),
    the striker holds back ``hold_distance`` from the ball, between it and the own goal, as B-Human's
    do; after ``hold_max_s`` it goes for the ball anyway for ``challenge_s`` (a robot that stands by
    the ball must not stall the game).

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
    robots_percept: RobotsPercept
    motion_request: MotionRequest
    activation_graph: ActivationGraph
    option_graph: OptionGraph

    show_target = DebugRequest("where the player wants to be, on the field canvas", name="SoccerBehavior:draw_target")
    kick_tuning = kick_tuning()

    @dataclass
    class Parameters(KickParameters, PassParameters):
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
        supporter_offset: list[float] = field(default_factory=lambda: [1400.0, 1400.0])
        """mm ahead of (towards the opponent goal; negative: behind) and beside the ball (beside: towards the
        field's long axis), where the supporter waits for a pass: 45 degrees off the ball's way to the goal,
        past an opponent waiting there (at 34 degrees, 1.5 m ahead and 1 m beside, the lane was blocked)"""
        keeper_clear_distance: float = bounded(0.0, 3000.0, 1200.0)
        """mm: a ball this near the goalkeeper, in its penalty area, is cleared"""
        keep_out_margin: float = bounded(0.0, 1000.0, 300.0)
        """mm kept beyond the rules' distances (the centre circle, 0.75 m from a free kick's ball)"""
        indirect_target: list[float] = field(default_factory=lambda: [1500.0, 0.5])
        """an own free kick goes this far ahead of the ball (mm, at most to the penalty area's front) and
        this share of the way to the field's long axis: never straight at the goal"""
        obstacle_margin: float = bounded(0.0, 1000.0, 250.0)
        """mm kept between this robot's and another robot's footprints on the way"""
        near_ball: float = bounded(0.0, 2000.0, 400.0)
        """mm: within this of the ball the striker goes straight for it (a duel for the ball is no push)"""
        shootout_aim: float = bounded(0.0, 700.0, 450.0)
        """mm beside the goal's centre the shoot-out kick aims (the side away from the keeper)"""
        face_the_way: float = bounded(0.0, 5000.0, 700.0)
        """mm: the striker walks to a spot behind the ball farther than this facing the way, not the kick"""
        contest_distance: float = bounded(0.0, 3000.0, 1000.0)
        """mm: an opponent this near the ball and nearer to it than this robot contests it"""
        contest_margin: float = bounded(0.0, 1000.0, 50.0)
        """mm an opponent must be nearer the ball to make the striker hold back (it goes again once the
        opponent is no nearer: two robots at about the same distance do not both wait)"""
        hold_distance: float = bounded(300.0, 2000.0, 700.0)
        """mm from the ball the striker waits while an opponent plays it"""
        keeper_pass_offset: list[float] = field(default_factory=lambda: [1200.0, 1200.0])
        """mm ahead of (towards the opponent goal) and beside the ball (beside: towards the field's long axis, or the
        other side when an opponent marks that spot or its lane) where the striker waits while its own goalkeeper
        plays the ball (``keeper_plays``): open to the keeper's pass, within the pass rule's reach and gain (at
        0.7 m straight ahead it was too near, and behind the opponent holding back 0.7 m before the ball)"""
        hold_max_s: float = bounded(0.0, 60.0, 8.0)
        """s the striker holds back at most; then it challenges for the ball"""
        challenge_s: float = bounded(0.0, 60.0, 5.0)
        """s the striker goes for the ball after holding back, contested or not"""
        defender_spread: float = bounded(0.0, 2000.0, 400.0)
        """mm a defender stands beside the line from the ball to the own goal (even numbers left, odd right)"""
        field_margin: float = bounded(0.0, 300.0, 150.0)
        """mm beyond the field's lines a walk may lead at most (leaving the carpet, 0.7 m beyond, is a foul)"""
        detour_memory_s: float = bounded(0.0, 10.0, 1.5)
        """s a side chosen round an obstacle is kept for one dead ahead (no zigzag)"""
        pass_decide_s: float = bounded(0.0, 10.0, 1.0)
        """s a choice between a pass and a shot (and where to) is kept before it is made again: the approach
        does not waver between two kick poses"""
        pass_mate_age: float = bounded(0.0, 10.0, 2.5)
        """s: a teammate whose last message is older is not passed to"""
        pass_mate_seen: float = bounded(0.0, 3000.0, 800.0)
        """mm: the robot seen nearest where a teammate last said it was, if this near, is that teammate (it walked
        since; the obstacles count it as a teammate only within 400 mm), not an opponent marking it, for the pass rule"""
        push_distance: float = bounded(330.0, 1000.0, 420.0)
        """mm between this robot's centre and another robot's up to which a walk may approach it (the referee
        calls contact at 330 mm): a walk's target is held back that far along the line to every robot near"""

    parameters: Parameters

    def __init__(self) -> None:
        self.options = OptionRunner(PlaySoccer)
        self.keep_out: list[Disc] = []
        """field discs (mm) the rules keep the team out of this frame: the set plays' options add them"""
        self.indirect = False
        """this frame's kick is an own free kick's: indirect, never straight at the goal"""
        self.detour_side, self.detour_s = 0, -math.inf
        """the side last chosen round an obstacle, and when (s)"""
        self.aim: tuple[float, float] | None = None
        self.aim_is_pass, self.aim_s = False, -math.inf
        """where the ball is played (field mm: a pass's target or the shot's point), whether it is a pass, and when chosen (s)"""
        self.last_ball: tuple[float, float] | None = None
        """field mm: where the ball was last known (own sighting or a teammate's)"""
        self.ball_search = SearchTurn()
        """which way a search for the ball turns: towards the side it was last seen on"""
        self.support_side = 0.0
        """the side of the ball the supporter waits on (+1: +y, -1: -y, 0: none yet), kept while open to a pass"""
        self.keeper_pass_side = 0.0
        """the side of the ball the striker waits on while its goalkeeper plays the ball (as ``support_side``)"""
        self.set_play: tuple[SetPlay, int] | None = None
        self.set_play_s = -math.inf
        self.set_play_spots: list[tuple[float, float]] = []
        """the opponents' set play going on (set play, kicking team), when this robot heard of it (s), and where the
        rules put its ball (field mm; ``placed_ball``), from where it was last known before"""

    def execute(self) -> None:
        out = self.motion_request
        if not self.option_graph.root:  # the static graph, for the views: written once
            graph = self.options.graph()
            self.option_graph.root, self.option_graph.options = graph.root, graph.options
        busy = {info.name: getattr(out, info.name) for info in fields_of(MotionRequest)} if self.motion_info.busy else None
        self.keep_out, self.indirect = [], False
        note_set_play(self)
        self.last_ball = self.ball_on_field() or self.last_ball
        if self.ball_model.valid:
            self.ball_search.found()
        out.motion, out.walk_kick = MotionType.stand, WalkKick.none  # each frame's request starts afresh
        self.options.run(self, self.frame_info.time_s, self.activation_graph)
        stay_on_field(out, self.robot_pose, self.obstacles, self.parameters)
        keep_from_pushing(out, self.robot_pose, self.game_state, self.obstacles, self.robots_percept, self.parameters)
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
        return ball.field_position(pose) if ball.valid and pose.valid else team_ball(self.team_mates, self.parameters.team_ball_age)

    def set_play_balls(self) -> list[tuple[float, float]]:
        """Where the ball of the opponents' set play is (field mm; ``set_play_ball.set_play_balls``)."""
        return set_play_balls(self)

    def set_play_ball(self) -> tuple[float, float] | None:
        """The ball to keep away from (field mm): where it is known; at the opponents' set play ``set_play_balls``,
        the one nearest this robot (the rules may put it on either side)."""
        balls = self.set_play_balls()
        if len(balls) > 1 and self.robot_pose.valid:
            pose = self.robot_pose
            return min(balls, key=lambda b: math.hypot(b[0] - pose.x, b[1] - pose.y))
        return balls[0] if balls else None

    def facing_ball(self, x: float, y: float) -> float:
        """rad (field) from (x, y) towards the ball (the centre spot when nobody knows where it is)."""
        bx, by = self.ball_on_field() or (0.0, 0.0)
        return math.atan2(by - y, bx - x)

    def kick_plan(self) -> tuple[float, KickParameters, WalkKick]:
        """The kick this frame, a shot or a pass, with the kick's parameters tuned live (``kick_choice.kick_plan``)."""
        return kick_plan(self, self.parameters, self.kick_tuning.apply(self.parameters))

    def keeper_clears(self) -> bool:
        """Whether the ball is in the own penalty area and near enough for the goalkeeper to clear it."""
        ball, ball_on_field = self.ball_model, self.ball_on_field()
        in_area = ball_on_field is not None and ball_on_field[0] < OWN_GOAL_X + pitch.PENALTY_AREA_LENGTH and abs(ball_on_field[1]) < pitch.PENALTY_AREA_WIDTH / 2
        return in_area and math.hypot(ball.x, ball.y) < self.parameters.keeper_clear_distance

    def defender_side(self) -> float:
        """+1 for even player numbers, -1 for odd ones: the side a defender stands on (+1: as configured,
        left of the line to the own goal in PLAYING)."""
        return -1.0 if self.game_state.player_number % 2 else 1.0

    def avoid(self, x: float, y: float, zones: list[Disc] | None = None) -> tuple[float, float, bool]:
        """Where to walk first on the way to (x, y) (robot frame mm) round robots and ``zones`` (``fair_walk.avoid``)."""
        return avoid(self, x, y, zones)

    def contested(self, holding: bool) -> bool:
        """Whether an opponent contests the ball (``holding_back.contested``)."""
        return contested(self, holding)

    def keeper_plays(self) -> bool:
        """Whether the own goalkeeper plays the ball in its penalty area (``holding_back.keeper_plays``)."""
        return keeper_plays(self)

    def hold_point(self) -> tuple[float, float, float]:
        """Where the striker waits while another plays the ball (robot frame; ``holding_back.hold_point``)."""
        return hold_point(self)
