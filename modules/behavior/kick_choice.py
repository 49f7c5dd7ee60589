"""SoccerBehavior's kick plan (``kick_plan``): a shot or a pass by the pass rule (``passing.py``), the way an own free
kick goes, never straight at the goal (``indirect_direction``), and which robots seen are opponents (``seen_opponents``)."""

from __future__ import annotations

import math
from dataclasses import replace
from typing import Protocol

from tafel.modules.behavior.kicking import KickParameters, goal_direction
from tafel.modules.behavior.passing import PassParameters, best_shot, choose_pass, pass_kick
from tafel.representations import field as pitch
from tafel.representations.infrastructure import FrameInfo
from tafel.representations.modeling import BallModel, RobotPose
from tafel.representations.motion_control import Odometry, WalkKick
from tafel.representations.obstacles import ObstacleKind, Obstacles, same_robots
from tafel.representations.team import TeamMates


class SightParameters(Protocol):
    """What ``seen_opponents`` reads of SoccerBehavior.Parameters."""

    pass_mate_age: float
    pass_mate_seen: float


class Sighted(Protocol):
    """What ``seen_opponents`` reads of SoccerBehavior."""

    robot_pose: RobotPose
    obstacles: Obstacles
    team_mates: TeamMates

    @property
    def parameters(self) -> SightParameters: ...


class KickPlanParameters(SightParameters, Protocol):
    """What ``kick_plan`` reads of SoccerBehavior.Parameters beside the pass rule's and the kick's."""

    indirect_target: list[float]
    pass_decide_s: float


class Kicker(Sighted, Protocol):
    """What ``kick_plan`` reads of SoccerBehavior, and the choice it keeps there (``aim``, ``aim_is_pass``, ``aim_s``)."""

    ball_model: BallModel
    odometry: Odometry
    frame_info: FrameInfo
    indirect: bool
    aim: tuple[float, float] | None
    aim_is_pass: bool
    aim_s: float

    @property
    def parameters(self) -> KickPlanParameters: ...


def seen_opponents(b: Sighted) -> list[tuple[float, float]]:
    """The robots seen (field mm; needs a valid pose) but those that are teammates: the robot seen nearest where a
    teammate said it was (within ``pass_mate_seen``) is that teammate, walked on since."""
    pose, p = b.robot_pose, b.parameters
    seen = [pose.to_field(o.x, o.y) for o in b.obstacles.obstacles if o.kind is ObstacleKind.robot]
    mates_seen = same_robots([(m.message.x, m.message.y) for m in b.team_mates.fresh(p.pass_mate_age)], seen, p.pass_mate_seen)
    return [robot for k, robot in enumerate(seen) if k not in mates_seen]


def indirect_direction(ball: BallModel, pose: RobotPose, odometry: Odometry, indirect_target: list[float]) -> float:
    """rad in the robot frame for an own free kick: ahead and towards the middle, not at the goal."""
    if not pose.valid:
        return goal_direction(ball, pose, odometry) + 0.6  # beside the goal rather than at it
    bx, by = ball.field_position(pose)
    ahead, inward = indirect_target
    tx = min(bx + ahead, pitch.LENGTH / 2 - pitch.PENALTY_AREA_LENGTH)  # near the goal line: back into the field
    tx = bx - 300.0 if abs(tx - bx) < 300.0 else tx
    ty = by * (1.0 - inward)
    beside, to_line = pitch.GOAL_INNER_WIDTH / 2 + 500.0, max(pitch.LENGTH / 2 - bx, 1.0)
    if tx > bx and abs(by + (ty - by) * to_line / (tx - bx)) < beside:  # it would cross the goal line in the goal
        ty = by + (math.copysign(beside, by if by else 1.0) - by) * (tx - bx) / to_line  # aim beside it instead
    rx, ry = pose.to_robot(tx, ty)
    return math.atan2(ry - ball.y, rx - ball.x)


def kick_plan(b: Kicker, p: PassParameters, tuned: KickParameters) -> tuple[float, KickParameters, WalkKick]:
    """The kick this frame: the direction (rad, robot frame), the kick's parameters (``tuned``: tuned live) and the
    walk kick's strength. A shot aims through the goal mouth's most open lane; a pass (by the pass rule, ``p``) goes
    to the point ahead of the teammate, by the walk kick its distance asks for (beyond it the keyframe kick). The
    choice is kept ``pass_decide_s``; an own free kick is indirect; without a pose, the goal's way by odometry."""
    ball, pose, q = b.ball_model, b.robot_pose, b.parameters
    if b.indirect:
        return indirect_direction(ball, pose, b.odometry, q.indirect_target), tuned, WalkKick.long
    if not pose.valid:
        return goal_direction(ball, pose, b.odometry), tuned, WalkKick.long
    bx, by = ball.field_position(pose)
    now = b.frame_info.time_s
    if b.aim is None or now - b.aim_s >= q.pass_decide_s or now < b.aim_s:
        mates = [(m.message.x, m.message.y) for m in b.team_mates.fresh(q.pass_mate_age)
                 if m.message.pose_valid and not (m.message.fallen or m.message.penalized)]
        opponents = seen_opponents(b)
        target = choose_pass((bx, by), mates, opponents, p)
        b.aim, b.aim_is_pass, b.aim_s = target or best_shot((bx, by), opponents, p)[0], target is not None, now
    ax, ay = pose.to_robot(*b.aim)
    direction = math.atan2(ay - ball.y, ax - ball.x)
    if not b.aim_is_pass:
        return direction, tuned, WalkKick.long
    strength = pass_kick(math.hypot(ax - ball.x, ay - ball.y), p)
    if strength is WalkKick.none:  # farther than the walk kicks go: the keyframe kick
        return direction, replace(tuned, walk_kick=False), WalkKick.long
    return direction, replace(tuned, walk_kick=True), strength
