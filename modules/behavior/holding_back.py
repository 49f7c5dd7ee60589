"""When and where SoccerBehavior's striker holds back from the ball: an opponent nearer plays it (``contested``;
pushing is a foul), or the own goalkeeper plays it in its penalty area (``keeper_plays``); ``hold_point`` is where it
waits then, ``keeper_pass_spot`` where the keeper can pass to it."""

from __future__ import annotations

import math
from typing import Protocol

from tafel.modules.behavior.kick_choice import SightParameters, seen_opponents
from tafel.modules.behavior.options.soccer import OWN_GOAL_X, SUPPORT_TOUCHLINE_GAP
from tafel.modules.behavior.passing import lane_clearance
from tafel.representations import field as pitch
from tafel.representations.modeling import BallModel, RobotPose
from tafel.representations.obstacles import ObstacleKind, Obstacles
from tafel.representations.team import PlayerRole, Role, TeamMates


class HoldParameters(SightParameters, Protocol):
    """What these functions read of SoccerBehavior.Parameters."""

    contest_distance: float
    contest_margin: float
    hold_distance: float
    keeper_pass_offset: list[float]
    lane_width: float
    pass_open: float


class Holder(Protocol):
    """What these functions read of SoccerBehavior, and the side it waits on for the keeper's pass (kept there)."""

    ball_model: BallModel
    robot_pose: RobotPose
    player_role: PlayerRole
    team_mates: TeamMates
    obstacles: Obstacles
    keeper_pass_side: float

    @property
    def parameters(self) -> HoldParameters: ...


def contested(b: Holder, holding: bool) -> bool:
    """Whether an opponent contests the ball: a robot not of the team within ``contest_distance`` of
    the ball and nearer to it than this robot (by ``contest_margin``, unless ``holding`` back already)."""
    ball, p = b.ball_model, b.parameters
    if not ball.valid:
        return False
    rivals = [math.hypot(o.x - ball.x, o.y - ball.y) for o in b.obstacles.obstacles if o.kind is ObstacleKind.robot]
    nearest = min(rivals, default=math.inf)
    return nearest < p.contest_distance and nearest < math.hypot(ball.x, ball.y) - (0.0 if holding else p.contest_margin)


def keeper_plays(b: Holder) -> bool:
    """Whether the own goalkeeper plays the ball in its penalty area: the ball there, and a teammate in the
    goalkeeper role (heard within ``pass_mate_age``) nearer to it than this robot, which is not the goalkeeper.
    Two of a team at the ball push each other: the keeper clearing pushed the striker over the goal line."""
    ball, pose = b.ball_model, b.robot_pose
    if not (ball.valid and pose.valid) or b.player_role.role is Role.goalkeeper:
        return False
    bx, by = ball.field_position(pose)
    if bx > OWN_GOAL_X + pitch.PENALTY_AREA_LENGTH or abs(by) > pitch.PENALTY_AREA_WIDTH / 2:
        return False
    mine = math.hypot(ball.x, ball.y)
    return any(m.message.role is Role.goalkeeper and m.message.pose_valid and not (m.message.fallen or m.message.penalized)
               and math.hypot(m.message.x - bx, m.message.y - by) < mine for m in b.team_mates.fresh(b.parameters.pass_mate_age))


def hold_point(b: Holder) -> tuple[float, float, float]:
    """Where the striker waits while an opponent plays the ball: ``hold_distance`` from the ball towards
    the own goal's centre (towards this robot without a pose), facing the ball; while the own goalkeeper
    plays it (``keeper_plays``), at ``keeper_pass_spot`` instead, out of its way and open to its pass;
    robot frame mm, mm, rad."""
    ball, pose = b.ball_model, b.robot_pose
    if pose.valid and keeper_plays(b):
        x, y = pose.to_robot(*keeper_pass_spot(b))
        return x, y, math.atan2(ball.y - y, ball.x - x)
    gx, gy = pose.to_robot(OWN_GOAL_X, 0.0) if pose.valid else (0.0, 0.0)
    dx, dy = gx - ball.x, gy - ball.y
    distance = math.hypot(dx, dy)
    if distance < 1.0:
        dx, dy, distance = -ball.x, -ball.y, max(math.hypot(ball.x, ball.y), 1.0)
    reach = min(b.parameters.hold_distance, distance)
    x, y = ball.x + dx / distance * reach, ball.y + dy / distance * reach
    return x, y, math.atan2(ball.y - y, ball.x - x)


def keeper_pass_spot(b: Holder) -> tuple[float, float]:
    """Where the striker waits while its goalkeeper plays the ball (field mm; needs a valid pose):
    ``keeper_pass_offset`` ahead of and beside the ball, beside towards the field's long axis, or the other
    side when an opponent stands within ``pass_open`` of that spot or ``lane_width`` of the ball's way to it
    and not of the other; the side chosen last is kept while open; ``SUPPORT_TOUCHLINE_GAP`` inside the
    touchlines. So the keeper's clearance can be a pass by the pass rule (``passing.py``)."""
    pose, p = b.robot_pose, b.parameters
    bx, by = b.ball_model.field_position(pose)
    ahead, beside = p.keeper_pass_offset
    limit = pitch.WIDTH / 2 - SUPPORT_TOUCHLINE_GAP
    inward = -math.copysign(1.0, by) if abs(by) > 100.0 else 1.0
    first = b.keeper_pass_side if b.keeper_pass_side and abs(by + b.keeper_pass_side * beside) <= limit else inward
    spots = [(bx + ahead, max(-limit, min(limit, by + side * beside))) for side in (first, -first)]
    opponents = seen_opponents(b)  # the keeper seen at the ball marks nothing

    def open_to_pass(spot: tuple[float, float]) -> bool:
        return all(math.dist(spot, o) >= p.pass_open for o in opponents) and lane_clearance((bx, by), spot, opponents) >= p.lane_width

    kept = open_to_pass(spots[0]) or not open_to_pass(spots[1])
    b.keeper_pass_side = first if kept else -first
    return spots[0] if kept else spots[1]
