"""SoccerBehavior: plays the game as the GameController says and the rules allow, in the role the team
agreed on, walking around the robots it knows of. The decisions are options (``options/soccer.py``,
root ``PlaySoccer``); this module runs them once a frame and holds what they share: the blackboard,
the parameters and the helpers below."""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

from tafel.core import Module, bounded, fields_of, provides, requires, uses
from tafel.debug import Canvas, DebugRequest
from tafel.modules.behavior.ball_search import SearchTurn
from tafel.modules.behavior.kicking import KickParameters, goal_direction, kick_tuning
from tafel.modules.behavior.options import OptionRunner
from tafel.modules.behavior.options.soccer import FREE_KICKS, OWN_GOAL_X, SUPPORT_TOUCHLINE_GAP, PlaySoccer
from tafel.modules.behavior.passing import PassParameters, best_shot, choose_pass, lane_clearance, pass_kick
from tafel.modules.behavior.paths import Disc, clear, detour, free_direction, outside
from tafel.representations import field as pitch
from tafel.representations.behavior import ActivationGraph, OptionGraph
from tafel.representations.game import GameState, SetPlay, State
from tafel.representations.infrastructure import FrameInfo
from tafel.representations.modeling import BallModel, RobotPose
from tafel.representations.motion_control import MotionInfo, MotionRequest, MotionType, Odometry, WalkKick
from tafel.representations.obstacles import ROBOT_RADIUS, ObstacleKind, Obstacles, RobotsPercept, same_robots
from tafel.representations.team import PlayerRole, Role, TeamMates

OPPONENT_PENALTY_MARK_X = pitch.LENGTH / 2 - pitch.PENALTY_MARK_DISTANCE
KEEPER_AREA_MARGIN = 150.0  # mm inside its penalty area's lines a goalkeeper is sure to be in it (the pose's error)
#: rad beside the heading beyond which the robot sees nothing (robots are seen within 100 degrees); mm a walk's target
#: lies that way at most (with the walk's target_gain, 1.5/s: no faster than 70 mm/s, below the rules' pushing) when it
#: is nearer than BLIND_TURN mm; farther, the robot is to face its way (the walk turns to it first, nearly in place:
#: ``WalkingEngine``'s turn_in_place_beyond)
BLIND, BLIND_STEP, BLIND_TURN = math.radians(100.0), 45.0, 400.0
POST_SEEN = 300.0  # mm round a goal post within which ObstacleModeler takes what is seen for the post (its post_radius)
KICK_HELD_BACK = 30.0  # mm a walk's target may be held back from a robot (``keep_from_pushing``) and the walk kick still be asked for


#: mm from the field's centre line a ball that went out over a goal line counts as on one side: nearer, the rules'
#: corner of either side may hold it (both are kept away from)
SIDE_UNSURE = 500.0


def placed_ball(set_play: SetPlay, last: tuple[float, float] | None) -> list[tuple[float, float]]:
    """Where the rules put the ball at the opponents' ``set_play`` (field mm, the own goal at -x), the ball last
    known at ``last`` (where it went out): a goal kick on the corner of their goal area, a corner kick in the own
    field corner, each on the side it went out (both corners while that is unsure), a kick-in on the touchline beside
    where it went out, a penalty kick on the own penalty mark, a pushing free kick where the ball is. Empty when
    that cannot be told (no ball known)."""
    if set_play is SetPlay.penalty_kick:
        return [(-OPPONENT_PENALTY_MARK_X, 0.0)]
    if last is None:
        return []
    x, y = last
    sides = [math.copysign(1.0, y)] if abs(y) > SIDE_UNSURE else [1.0, -1.0]
    if set_play is SetPlay.goal_kick:
        return [(pitch.LENGTH / 2 - pitch.GOAL_AREA_LENGTH, side * pitch.GOAL_AREA_WIDTH / 2) for side in sides]
    if set_play is SetPlay.corner_kick:
        return [(-pitch.LENGTH / 2, side * pitch.WIDTH / 2) for side in sides]
    if set_play is SetPlay.kick_in:
        return [(max(-pitch.LENGTH / 2, min(pitch.LENGTH / 2, x)), math.copysign(pitch.WIDTH / 2, y))]
    return [last]


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
        """mm beyond the field's lines a walk may lead at most (the torso 0.3 m beyond one has left the field)"""
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
        self.note_set_play()
        self.last_ball = self.ball_on_field() or self.last_ball
        if self.ball_model.valid:
            self.ball_search.found()
        out.motion, out.walk_kick = MotionType.stand, WalkKick.none  # each frame's request starts afresh
        self.options.run(self, self.frame_info.time_s, self.activation_graph)
        self.stay_on_field()
        self.keep_from_pushing()
        if busy is not None:  # a kick or get-up plays to its end: the options went on, the request stays
            for name, value in busy.items():
                setattr(out, name, value)

    def stay_on_field(self) -> None:
        """A walk's target beyond the lines by more than ``field_margin`` comes back to it: leaving the field
        is a foul (the referee calls it 0.3 m beyond a line). When the way back runs into a robot's disc
        (the way round it led beyond the line), the free direction nearest it that leads no further beyond
        the lines than the robot is; the robot stands if there is none: pushing is a foul too."""
        out, pose, margin = self.motion_request, self.robot_pose, self.parameters.field_margin
        if out.motion is not MotionType.walk_to or not pose.valid:
            return
        x, y = pose.to_field(out.target_x, out.target_y)
        limit_x, limit_y = pitch.LENGTH / 2 + margin, pitch.WIDTH / 2 + margin
        inside = max(-limit_x, min(limit_x, x)), max(-limit_y, min(limit_y, y))
        if inside == (x, y):
            return
        target = pose.to_robot(*inside)
        robots = self.robot_discs(self.parameters.obstacle_margin)
        if not clear(*target, robots, 0.0):
            way_x, way_y, _ = free_direction(*target, robots, 0.0)
            fx, fy = pose.to_field(way_x, way_y)
            if (way_x, way_y) == (0.0, 0.0) or abs(fx) > max(limit_x, abs(pose.x)) or abs(fy) > max(limit_y, abs(pose.y)):
                out.motion, out.walk_kick = MotionType.stand, WalkKick.none
                return
            target = way_x, way_y
        out.target_x, out.target_y = target

    def keep_from_pushing(self) -> None:
        """The rules' pushing is walking into a touching opponent (its torso approaching faster than 80 mm/s):
        a walk's target is held back along the line to every robot (not a teammate) so that the way towards it
        ends ``push_distance`` from its centre, as near as the robot may come. Sideways to it the walk goes
        on; the walk slows as it nears its target, so it comes to rest there rather than at contact. One
        already nearer steps back a little, straight away from it. Robots seen at a goal post count too
        (``ObstacleModeler`` takes them for the post: a keeper by its post was walked into). A walk backwards,
        ``BLIND`` of the heading where nothing is seen, goes no faster than the rules' pushing (``BLIND_STEP``).
        The rules spare the goalkeeper in its own
        penalty area (the GameController's goalkeeper, ``KEEPER_AREA_MARGIN`` inside the area's lines by the
        pose): it plays the ball there whoever stands at it."""
        out, pose, team = self.motion_request, self.robot_pose, self.game_state.own_team()
        if out.motion is not MotionType.walk_to:
            return
        if (team is not None and team.goalkeeper == self.game_state.player_number and pose.valid
                and pose.x < OWN_GOAL_X + pitch.PENALTY_AREA_LENGTH - KEEPER_AREA_MARGIN
                and abs(pose.y) < pitch.PENALTY_AREA_WIDTH / 2 - KEEPER_AREA_MARGIN):
            return
        x, y = out.target_x, out.target_y
        robots = [(o.x, o.y) for o in self.obstacles.obstacles if o.kind is ObstacleKind.robot]
        if pose.valid:  # what is seen at a goal post: the post, or a keeper standing by it
            robots += [(r.x, r.y) for r in self.robots_percept.robots if any(
                math.dist(pose.to_field(r.x, r.y), (sx * pitch.LENGTH / 2, sy * (pitch.GOAL_INNER_WIDTH + pitch.GOAL_POST_DIAMETER) / 2)) < POST_SEEN
                for sx in (-1, 1) for sy in (-1, 1))]
        for _ in range(3):  # held back from one, the target may lead further towards another: again
            for rx, ry in robots:
                distance = math.hypot(rx, ry)
                if distance < 1.0:
                    continue
                ux, uy = rx / distance, ry / distance
                towards, limit = x * ux + y * uy, distance - self.parameters.push_distance
                if towards > limit:
                    x, y = x - (towards - limit) * ux, y - (towards - limit) * uy
        length, way = math.hypot(x, y), math.atan2(y, x)
        if abs(way) > BLIND and length > BLIND_STEP and self.game_state.state is State.playing:  # backwards, blind
            if length > BLIND_TURN:  # far: turn (the walk turns first) and walk there facing the way
                out.target_rotation = way
            else:  # near: slowly
                x, y = x * BLIND_STEP / length, y * BLIND_STEP / length
        if math.hypot(x - out.target_x, y - out.target_y) > KICK_HELD_BACK:  # the kick's spot is out of reach: no kick
            out.walk_kick = WalkKick.none
        out.target_x, out.target_y = x, y

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

    def note_set_play(self) -> None:
        """An opponents' set play that begins: when, and where the rules put the ball (``placed_ball``), from where
        it was last known (before this frame: where it went out)."""
        game = self.game_state
        now = (game.set_play, game.kicking_team) if self.opponents_set_play() else None
        if now != self.set_play:
            self.set_play, self.set_play_s = now, self.frame_info.time_s
            self.set_play_spots = placed_ball(game.set_play, self.last_ball) if now is not None else []

    def set_play_balls(self) -> list[tuple[float, float]]:
        """Where the ball of the opponents' set play is (field mm), to keep away from: the own sighting or a
        teammate's, if made since the set play began; else where the rules put it (``set_play_spots``: a ball that
        went out is put back by the referee, often beside the robot that chased it there, which may not see it
        then, and its model still shows it where it went out); else where it was last known."""
        ball, since = self.ball_model, self.frame_info.time_s - self.set_play_s
        if self.set_play is None:
            known = self.ball_on_field()
            return [known] if known is not None else []
        if ball.valid and ball.time_since_seen < since and self.robot_pose.valid:
            return [ball.field_position(self.robot_pose)]
        heard = [m for m in self.team_mates.mates if m.message.ball_seen and m.message.pose_valid and 0.0 <= m.message.ball_age]
        heard = [m for m in heard if m.age + m.message.ball_age < min(since, self.parameters.team_ball_age)]
        if heard:
            best = min(heard, key=lambda m: m.age + m.message.ball_age).message
            return [(best.ball_x, best.ball_y)]
        if self.set_play_spots:
            return list(self.set_play_spots)
        return [self.last_ball] if self.last_ball is not None else []

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

    def kick_plan(self) -> tuple[float, KickParameters, WalkKick]:
        """The kick this frame (``passing``): the direction (rad, robot frame), the kick's parameters (tuned live)
        and the walk kick's strength. A shot aims through the goal mouth's most open lane; a pass (by the pass
        rule) goes to the point ahead of the teammate, by the walk kick its distance asks for (beyond it the
        keyframe kick). The choice is kept ``pass_decide_s``; an own free kick is indirect; without a pose,
        the goal's way by odometry."""
        ball, pose, p = self.ball_model, self.robot_pose, self.parameters
        tuned = self.kick_tuning.apply(p)
        if self.indirect:
            return self.indirect_direction(), tuned, WalkKick.long
        if not pose.valid:
            return goal_direction(ball, pose, self.odometry), tuned, WalkKick.long
        bx, by = ball.field_position(pose)
        now = self.frame_info.time_s
        if self.aim is None or now - self.aim_s >= p.pass_decide_s or now < self.aim_s:
            mates = [(m.message.x, m.message.y) for m in self.team_mates.fresh(p.pass_mate_age)
                     if m.message.pose_valid and not (m.message.fallen or m.message.penalized)]
            opponents = self.seen_opponents()
            target = choose_pass((bx, by), mates, opponents, p)
            self.aim, self.aim_is_pass, self.aim_s = target or best_shot((bx, by), opponents, p)[0], target is not None, now
        ax, ay = pose.to_robot(*self.aim)
        direction = math.atan2(ay - ball.y, ax - ball.x)
        if not self.aim_is_pass:
            return direction, tuned, WalkKick.long
        strength = pass_kick(math.hypot(ax - ball.x, ay - ball.y), p)
        if strength is WalkKick.none:  # farther than the walk kicks go: the keyframe kick
            return direction, replace(tuned, walk_kick=False), WalkKick.long
        return direction, replace(tuned, walk_kick=True), strength

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

    def defender_side(self) -> float:
        """+1 for even player numbers, -1 for odd ones: the side a defender stands on (+1: as configured,
        left of the line to the own goal in PLAYING)."""
        return -1.0 if self.game_state.player_number % 2 else 1.0

    def robot_discs(self, margin: float = 0.0) -> list[Disc]:
        """The robots known to be near (robot frame), as discs this robot's centre keeps out of (grown by
        ``margin`` mm)."""
        return [(o.x, o.y, o.radius + ROBOT_RADIUS + margin) for o in self.obstacles.obstacles]

    def avoid(self, x: float, y: float, zones: list[Disc] | None = None) -> tuple[float, float, bool]:
        """Where to walk first on the way to (x, y) (robot frame mm) without walking into a robot (kept
        ``obstacle_margin`` away) or into ``zones`` (robot frame discs the rules close), and whether that is
        a detour. A target on a robot moves out to the edge of its disc: the robot stops short of it."""
        robots, closed = self.robot_discs(self.parameters.obstacle_margin), []
        for cx, cy, radius in zones or []:
            if math.hypot(cx, cy) >= radius:
                closed.append((cx, cy, radius))
            elif cx * x + cy * y > 0.0:  # within a closed area and the way leads further in: straight out first
                out_x, out_y = outside(0.0, 0.0, [(cx, cy, radius)], 1.0)
                return out_x, out_y, True
        x, y = outside(x, y, robots, 1.0)
        now = self.frame_info.time_s
        prefer = self.detour_side if now - self.detour_s <= self.parameters.detour_memory_s else 0
        way_x, way_y, side = detour(x, y, [*closed, *robots], 0.0, prefer)
        if side:
            self.detour_side, self.detour_s = side, now
        return way_x, way_y, (way_x, way_y) != (x, y)

    def contested(self, holding: bool) -> bool:
        """Whether an opponent contests the ball: a robot not of the team within ``contest_distance`` of
        the ball and nearer to it than this robot (by ``contest_margin``, unless ``holding`` back already)."""
        ball, p = self.ball_model, self.parameters
        if not ball.valid:
            return False
        rivals = [math.hypot(o.x - ball.x, o.y - ball.y) for o in self.obstacles.obstacles if o.kind is ObstacleKind.robot]
        nearest = min(rivals, default=math.inf)
        return nearest < p.contest_distance and nearest < math.hypot(ball.x, ball.y) - (0.0 if holding else p.contest_margin)

    def keeper_plays(self) -> bool:
        """Whether the own goalkeeper plays the ball in its penalty area: the ball there, and a teammate in the
        goalkeeper role (heard within ``pass_mate_age``) nearer to it than this robot, which is not the goalkeeper.
        Two of a team at the ball push each other: the keeper clearing pushed the striker over the goal line."""
        ball, pose = self.ball_model, self.robot_pose
        if not (ball.valid and pose.valid) or self.player_role.role is Role.goalkeeper:
            return False
        bx, by = ball.field_position(pose)
        if bx > OWN_GOAL_X + pitch.PENALTY_AREA_LENGTH or abs(by) > pitch.PENALTY_AREA_WIDTH / 2:
            return False
        mine = math.hypot(ball.x, ball.y)
        return any(m.message.role is Role.goalkeeper and m.message.pose_valid and not (m.message.fallen or m.message.penalized)
                   and math.hypot(m.message.x - bx, m.message.y - by) < mine for m in self.team_mates.fresh(self.parameters.pass_mate_age))

    def hold_point(self) -> tuple[float, float, float]:
        """Where the striker waits while an opponent plays the ball: ``hold_distance`` from the ball towards
        the own goal's centre (towards this robot without a pose), facing the ball; while the own goalkeeper
        plays it (``keeper_plays``), at ``keeper_pass_spot`` instead, out of its way and open to its pass;
        robot frame mm, mm, rad."""
        ball, pose = self.ball_model, self.robot_pose
        if pose.valid and self.keeper_plays():
            x, y = pose.to_robot(*self.keeper_pass_spot())
            return x, y, math.atan2(ball.y - y, ball.x - x)
        gx, gy = pose.to_robot(OWN_GOAL_X, 0.0) if pose.valid else (0.0, 0.0)
        dx, dy = gx - ball.x, gy - ball.y
        distance = math.hypot(dx, dy)
        if distance < 1.0:
            dx, dy, distance = -ball.x, -ball.y, max(math.hypot(ball.x, ball.y), 1.0)
        reach = min(self.parameters.hold_distance, distance)
        x, y = ball.x + dx / distance * reach, ball.y + dy / distance * reach
        return x, y, math.atan2(ball.y - y, ball.x - x)

    def keeper_pass_spot(self) -> tuple[float, float]:
        """Where the striker waits while its goalkeeper plays the ball (field mm; needs a valid pose):
        ``keeper_pass_offset`` ahead of and beside the ball, beside towards the field's long axis, or the other
        side when an opponent stands within ``pass_open`` of that spot or ``lane_width`` of the ball's way to it
        and not of the other; the side chosen last is kept while open; ``SUPPORT_TOUCHLINE_GAP`` inside the
        touchlines. So the keeper's clearance can be a pass by the pass rule (``passing.py``)."""
        pose, p = self.robot_pose, self.parameters
        bx, by = self.ball_model.field_position(pose)
        ahead, beside = p.keeper_pass_offset
        limit = pitch.WIDTH / 2 - SUPPORT_TOUCHLINE_GAP
        inward = -math.copysign(1.0, by) if abs(by) > 100.0 else 1.0
        first = self.keeper_pass_side if self.keeper_pass_side and abs(by + self.keeper_pass_side * beside) <= limit else inward
        spots = [(bx + ahead, max(-limit, min(limit, by + side * beside))) for side in (first, -first)]
        opponents = self.seen_opponents()  # the keeper seen at the ball marks nothing

        def open_to_pass(spot: tuple[float, float]) -> bool:
            return all(math.dist(spot, o) >= p.pass_open for o in opponents) and lane_clearance((bx, by), spot, opponents) >= p.lane_width

        kept = open_to_pass(spots[0]) or not open_to_pass(spots[1])
        self.keeper_pass_side = first if kept else -first
        return spots[0] if kept else spots[1]

    def seen_opponents(self) -> list[tuple[float, float]]:
        """The robots seen (field mm; needs a valid pose) but those that are teammates: the robot seen nearest where a
        teammate said it was (within ``pass_mate_seen``) is that teammate, walked on since."""
        pose, p = self.robot_pose, self.parameters
        seen = [pose.to_field(o.x, o.y) for o in self.obstacles.obstacles if o.kind is ObstacleKind.robot]
        mates_seen = same_robots([(m.message.x, m.message.y) for m in self.team_mates.fresh(p.pass_mate_age)], seen, p.pass_mate_seen)
        return [robot for k, robot in enumerate(seen) if k not in mates_seen]
