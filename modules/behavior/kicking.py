"""How a field player gets the ball to where it wants it: walk behind it on the kick's line, then kick.

With ``walk_kick`` (``Striker``'s default) the kick comes out of the walk: the robot walks to where the ball lies
``walk_kick_distance`` ahead of the kicking foot along the kick direction, turned only as far as the
walk kick cannot turn the ball itself (``walk_kick_max_angle`` either side), and asks for the kick while
it walks; the kicking foot is the one on the side the ball goes (the foot swings outwards, never across
the other), or for a straight kick the one on the ball's side. Without it: the keyframe kick, standing, unless
a robot stands near beside or behind the kicker (``kick_clearance``): the keyframe kick shifts the torso over the
standing foot, into a robot it does not see (5v5: pushing); then the walk kick, which leads away from it.

Shared by the behaviours that kick (``Striker``, ``SoccerBehavior``); not a module.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields

from tafel.core import bounded
from tafel.debug import ModifyParameters
from tafel.modules.behavior.passing import segment_distance
from tafel.representations import field
from tafel.representations.geometry import Pose2D
from tafel.representations.modeling import BallModel, RobotPose
from tafel.representations.motion_control import Foot, MotionRequest, MotionType, Odometry, WalkKick
from tafel.representations.obstacles import Obstacles


@dataclass
class KickParameters:
    behind: float = bounded(100.0, 500.0, 190.0)
    """mm from the ball to the robot's centre when kicking"""
    foot_offset: float = bounded(0.0, 120.0, 50.0)
    """mm sideways from the robot's centre to the kicking foot's centre"""
    kick_tolerance_x: float = bounded(10.0, 200.0, 45.0)
    """mm the ball may lie nearer or farther than ``behind`` for a kick"""
    kick_tolerance_y: float = bounded(5.0, 100.0, 30.0)
    """mm the ball may lie beside the kicking foot for a kick"""
    kick_tolerance_angle: float = bounded(0.02, 1.0, 0.2)
    """rad the robot may face away from the kick direction for a kick"""
    walk_kick: bool = False
    """kick out of the walk (``MotionRequest.walk_kick``; the ``Striker``'s default); false: the keyframe kick from standing"""
    walk_kick_distance: float = bounded(120.0, 300.0, 150.0)
    """mm from the kicking foot's place beside the robot to the ball's centre, along the kick direction"""
    walk_kick_turned_farther: float = bounded(0.0, 150.0, 40.0)
    """mm farther the ball lies for a kick turned 90 degrees (times the sine): clear of the walking foot's corner"""
    walk_kick_ask_within: float = bounded(20.0, 600.0, 250.0)
    """mm from the kicking pose within which the walk kick is asked for: the walk kicks once it is there"""
    walk_kick_max_angle: float = bounded(0.0, 0.8, 0.8)
    """rad either side the walk kick sends the ball without the robot turning to it"""
    walk_kick_long_max_angle: float = bounded(0.0, 0.8, 0.1)
    """rad either side the long walk kick turns the ball (it is a straight kick: the robot faces its direction)"""
    walk_kick_keep_foot: float = bounded(0.0, 100.0, 40.0)
    """mm either side of the middle within which a straight walk kick keeps the foot it chose"""
    walk_kick_straight: float = bounded(0.0, 0.5, 0.15)
    """rad within which a kick is straight: the foot on the ball's side kicks"""
    round_ball_clearance: float = bounded(0.0, 600.0, 250.0)
    """mm: a robot past the ball on the kick's line whose straight way to the kick's spot passes nearer the
    ball's centre than this walks round the ball (straight on, it would push the ball back, towards its own goal)"""
    round_ball_beside: float = bounded(150.0, 800.0, 300.0)
    """mm beside the ball's centre the way round the ball leads"""
    kick_clearance: float = bounded(0.0, 1000.0, 450.0)
    """mm from the robot's centre within which a robot beside or behind (beyond ``kick_ahead``) allows no keyframe
    kick, only the walk kick: the keyframe kick shifts the torso over the standing foot, and the referee calls
    contact at 330 mm (5v5: an opponent 340 mm behind the kicker, unseen, was pushed)"""
    kick_ahead: float = bounded(0.0, 3.2, 0.6)
    """rad either side of the heading within which a robot is ahead of the kicker, the ball between (no push)"""


#: the kick's parameters tried live: modify values Kick:NAME, declared by the modules that kick
KICK_TUNED = tuple(item.name for item in fields(KickParameters) if item.type in ("float", float))


def kick_tuning() -> ModifyParameters:
    """The declaration of the kick's modify values, for a module that kicks: ``kick_tuning = kick_tuning()``."""
    return ModifyParameters(KICK_TUNED, "the kick, tried live: modify:set Kick:NAME", prefix="Kick")


def goal_direction(ball: BallModel, pose: RobotPose, odometry: Odometry) -> float:
    """rad in the robot frame from the ball to the opponent goal's centre; without a valid pose, the way
    the robot faced at the start (by odometry), which in the default scene is that goal as well."""
    if not pose.valid:
        return math.remainder(-odometry.rotation, math.tau)
    goal_x, goal_y = pose.to_robot(field.LENGTH / 2 + field.GOAL_DEPTH / 2, 0.0)
    return math.atan2(goal_y - ball.y, goal_x - ball.x)


def crowded(obstacles: Obstacles | None, p: KickParameters) -> bool:
    """Whether a robot (a teammate too: its place is only what it said, and an opponent near it may be taken for
    it) stands within ``kick_clearance`` mm of the robot's centre beside or behind it (beyond ``kick_ahead`` of
    the heading), where a keyframe kick's sway would walk into it."""
    if obstacles is None:
        return False
    return any(math.hypot(o.x, o.y) < p.kick_clearance and abs(math.atan2(o.y, o.x)) > p.kick_ahead for o in obstacles.obstacles)


def approach_and_kick(ball: BallModel, kick_direction: float, p: KickParameters, out: MotionRequest,
                      strength: WalkKick = WalkKick.long, obstacles: Obstacles | None = None) -> tuple[float, float, float]:
    """Fill ``out``: kick towards ``kick_direction`` (rad, robot frame) when the ball lies right in front
    of the kicking foot, else walk to the point ``behind`` mm behind the ball on the kick's line, the
    kicking foot in line with the ball. Returns that point and direction (mm, mm, rad; robot frame).
    With ``p.walk_kick``, or while a robot of ``obstacles`` stands near beside or behind (``crowded``): the walk
    kick of ``strength`` (``walk_kick_approach``).

    The caller passes ``p`` with its modify values ``Kick:NAME`` applied (``kick_tuning``), so a value pinned
    by a debug client is tried live."""
    out.walk_kick = WalkKick.none
    if p.walk_kick or crowded(obstacles, p):
        return walk_kick_approach(ball, kick_direction, p, out, strength)
    foot = Foot.left if ball.y >= 0 else Foot.right
    side = p.foot_offset if foot is Foot.left else -p.foot_offset
    # behind the ball on the kick's line, shifted so that the kicking foot (not the centre) meets it
    target_x, target_y = Pose2D(ball.x, ball.y, kick_direction).to_global(-p.behind, -side)
    # the ball as the kicking foot sees it, in the kick's frame
    along, across = Pose2D(0.0, 0.0, kick_direction).to_local(ball.x, ball.y)
    across -= side
    if abs(along - p.behind) < p.kick_tolerance_x and abs(across) < p.kick_tolerance_y and abs(kick_direction) < p.kick_tolerance_angle:
        out.motion, out.kick_foot, out.kick_direction = MotionType.kick, foot, kick_direction
    else:
        target_x, target_y = round_the_ball(ball, kick_direction, target_x, target_y, p)
        out.motion = MotionType.walk_to
        out.target_x, out.target_y, out.target_rotation = target_x, target_y, kick_direction
    return target_x, target_y, kick_direction


#: mm past the ball (along the kick's line, from the ball's centre) from which a robot may have to walk round it
ROUND_PAST = 50.0


def round_the_ball(ball: BallModel, kick_direction: float, target_x: float, target_y: float, p: KickParameters) -> tuple[float, float]:
    """Where to walk on the way to the kick's spot ``target`` (robot frame mm): the spot itself, unless the robot
    stands more than ``ROUND_PAST`` past the ball along the kick's line (``kick_direction``, rad) and the straight
    way to the spot passes within ``round_ball_clearance`` of the ball; then round the ball on the robot's side,
    ``round_ball_beside`` from it: first out sideways (no farther past the ball than that), then back to beside
    the spot, from where the spot is reached sideways."""
    ux, uy = math.cos(kick_direction), math.sin(kick_direction)
    along, across = -(ball.x * ux + ball.y * uy), ball.x * uy - ball.y * ux  # the robot from the ball, in the kick's frame
    if along <= ROUND_PAST or segment_distance((target_x, target_y), (ball.x, ball.y)) >= p.round_ball_clearance:
        return target_x, target_y
    side = 1.0 if across >= 0.0 else -1.0
    beside = side * p.round_ball_beside
    if abs(across) < 0.8 * p.round_ball_beside:  # in front of the ball: out sideways first
        way_along = min(along, p.round_ball_beside)
    else:  # beside it: back to beside the spot
        way_along = (target_x - ball.x) * ux + (target_y - ball.y) * uy
    return ball.x + way_along * ux - beside * uy, ball.y + way_along * uy + beside * ux


def walk_kick_approach(ball: BallModel, kick_direction: float, p: KickParameters, out: MotionRequest,
                       strength: WalkKick) -> tuple[float, float, float]:
    """Walk to where the ball lies ``walk_kick_distance`` ahead of the kicking foot along the kick line,
    facing ``kick_direction`` turned back by what the walk kick turns itself; ask for the walk kick once
    near it (``walk_kick_ask_within``): the walk kicks when it gets there. Returns the pose walked to (mm,
    mm, rad; robot frame)."""
    limit = 0.0 if strength is WalkKick.long else p.walk_kick_max_angle  # the long kick: the robot faces its direction
    angle = min(limit, max(-limit, kick_direction))  # what the kick turns
    heading = kick_direction - angle  # what the robot turns
    if abs(angle) > p.walk_kick_straight:
        foot = Foot.left if angle > 0 else Foot.right
    elif abs(ball.y) > p.walk_kick_keep_foot:
        foot = Foot.left if ball.y >= 0 else Foot.right
    else:
        foot = out.kick_foot  # near the middle: the foot of the last frame, as the torso sways the ball across
    side = p.foot_offset if foot is Foot.left else -p.foot_offset
    # the ball in the frame the robot has at the kick: ahead of the kicking foot along the kick's line
    distance = p.walk_kick_distance + p.walk_kick_turned_farther * abs(math.sin(angle))  # clear of the walking foot
    spot_x, spot_y = distance * math.cos(angle), side + distance * math.sin(angle)
    target_x, target_y = Pose2D(ball.x, ball.y, heading).to_global(-spot_x, -spot_y)
    along, across = Pose2D(0.0, side, angle).to_local(ball.x, ball.y)
    out.motion = MotionType.walk_to
    out.kick_foot = foot  # kept for the next frame's choice near the middle
    way_x, way_y = round_the_ball(ball, kick_direction, target_x, target_y, p)
    out.target_x, out.target_y, out.target_rotation = way_x, way_y, heading
    if (way_x, way_y) != (target_x, target_y):  # past the ball: round it first, no kick
        return way_x, way_y, heading
    if math.hypot(along - distance, across) < p.walk_kick_ask_within and abs(heading) < p.kick_tolerance_angle:
        # the long kick corrects what the robot is still turned away, up to walk_kick_long_max_angle
        residual = min(p.walk_kick_long_max_angle, max(-p.walk_kick_long_max_angle, heading))
        out.walk_kick, out.kick_direction = strength, angle + (residual if strength is WalkKick.long else 0.0)
    return target_x, target_y, heading
