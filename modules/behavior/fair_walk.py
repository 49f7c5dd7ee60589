"""What keeps SoccerBehavior's walks within the rules: round the robots and the closed areas on the way (``avoid``),
and, after the options chose a walk, on the field (``stay_on_field``) and off the robots it would push
(``keep_from_pushing``). Robot frame, mm."""

from __future__ import annotations

import math
from typing import Protocol

from tafel.modules.behavior.options.soccer import OWN_GOAL_X
from tafel.modules.behavior.paths import Disc, clear, detour, free_direction, outside
from tafel.representations import field as pitch
from tafel.representations.game import GameState, State
from tafel.representations.infrastructure import FrameInfo
from tafel.representations.modeling import RobotPose
from tafel.representations.motion_control import MotionRequest, MotionType, WalkKick
from tafel.representations.obstacles import ROBOT_RADIUS, ObstacleKind, Obstacles, RobotsPercept

KEEPER_AREA_MARGIN = 150.0  # mm inside its penalty area's lines a goalkeeper is sure to be in it (the pose's error)
#: rad beside the heading beyond which the robot sees nothing (robots are seen within 100 degrees); mm a walk's target
#: lies that way at most (with the walk's target_gain, 1.5/s: no faster than 70 mm/s, below the rules' pushing) when it
#: is nearer than BLIND_TURN mm; farther, the robot is to face its way (the walk turns to it first, nearly in place:
#: ``WalkingEngine``'s turn_in_place_beyond)
BLIND, BLIND_STEP, BLIND_TURN = math.radians(100.0), 45.0, 400.0
#: mm (centre to centre) within which a faint robot (``Obstacles.faint``: remembered behind, may have gone) is walked
#: towards no faster than BLIND_STEP allows (below the rules' pushing); beyond, the walk has room to slow down to it
FAINT_NEAR = 700.0
#: mm beyond ``push_distance`` within which a robot seen is walked towards no faster than BLIND_STEP allows: where it is
#: seen may be 100 mm off, and the walk needs room to slow down; so a touch the error lets happen is no push
SLOW_NEAR = 250.0
POST_SEEN = 300.0  # mm round a goal post within which ObstacleModeler takes what is seen for the post (its post_radius)
KICK_HELD_BACK = 30.0  # mm a walk's target may be held back from a robot (``keep_from_pushing``) and the walk kick still be asked for


class WalkParameters(Protocol):
    """What these functions read of SoccerBehavior.Parameters."""

    detour_memory_s: float
    field_margin: float
    obstacle_margin: float
    push_distance: float


class Walker(Protocol):
    """What ``avoid`` reads of SoccerBehavior, and the side it last chose round an obstacle (kept there)."""

    frame_info: FrameInfo
    obstacles: Obstacles
    detour_side: int
    detour_s: float

    @property
    def parameters(self) -> WalkParameters: ...


def robot_discs(obstacles: Obstacles, margin: float = 0.0) -> list[Disc]:
    """The robots known to be near (robot frame), as discs this robot's centre keeps out of (grown by
    ``margin`` mm)."""
    return [(o.x, o.y, o.radius + ROBOT_RADIUS + margin) for o in obstacles.obstacles]


def avoid(b: Walker, x: float, y: float, zones: list[Disc] | None = None) -> tuple[float, float, bool]:
    """Where to walk first on the way to (x, y) (robot frame mm) without walking into a robot (kept
    ``obstacle_margin`` away) or into ``zones`` (robot frame discs the rules close), and whether that is
    a detour. A target on a robot moves out to the edge of its disc: the robot stops short of it."""
    robots, closed = robot_discs(b.obstacles, b.parameters.obstacle_margin), []
    for cx, cy, radius in zones or []:
        if math.hypot(cx, cy) >= radius:
            closed.append((cx, cy, radius))
        elif cx * x + cy * y > 0.0:  # within a closed area and the way leads further in: straight out first
            out_x, out_y = outside(0.0, 0.0, [(cx, cy, radius)], 1.0)
            return out_x, out_y, True
    x, y = outside(x, y, robots, 1.0)
    now = b.frame_info.time_s
    prefer = b.detour_side if now - b.detour_s <= b.parameters.detour_memory_s else 0
    way_x, way_y, side = detour(x, y, [*closed, *robots], 0.0, prefer)
    if side:
        b.detour_side, b.detour_s = side, now
    return way_x, way_y, (way_x, way_y) != (x, y)


def stay_on_field(out: MotionRequest, pose: RobotPose, obstacles: Obstacles, p: WalkParameters) -> None:
    """A walk's target beyond the lines by more than ``field_margin`` comes back to it: leaving the field
    is a foul (off the carpet, 0.7 m beyond a line; a real referee judges by eye). When the way back runs into a robot's disc
    (the way round it led beyond the line), the free direction nearest it that leads no further beyond
    the lines than the robot is; the robot stands if there is none: pushing is a foul too."""
    margin = p.field_margin
    if out.motion is not MotionType.walk_to or not pose.valid:
        return
    x, y = pose.to_field(out.target_x, out.target_y)
    limit_x, limit_y = pitch.LENGTH / 2 + margin, pitch.WIDTH / 2 + margin
    inside = max(-limit_x, min(limit_x, x)), max(-limit_y, min(limit_y, y))
    if inside == (x, y):
        return
    target = pose.to_robot(*inside)
    robots = robot_discs(obstacles, p.obstacle_margin)
    if not clear(*target, robots, 0.0):
        way_x, way_y, _ = free_direction(*target, robots, 0.0)
        fx, fy = pose.to_field(way_x, way_y)
        if (way_x, way_y) == (0.0, 0.0) or abs(fx) > max(limit_x, abs(pose.x)) or abs(fy) > max(limit_y, abs(pose.y)):
            out.motion, out.walk_kick = MotionType.stand, WalkKick.none
            return
        target = way_x, way_y
    out.target_x, out.target_y = target


def keep_from_pushing(out: MotionRequest, pose: RobotPose, game: GameState, obstacles: Obstacles, percept: RobotsPercept,
                      p: WalkParameters) -> None:
    """The rules' pushing is walking into a touching opponent (its torso approaching faster than 80 mm/s):
    a walk's target is held back along the line to every robot (not a teammate) so that the way towards it
    ends ``push_distance`` from its centre, as near as the robot may come. Sideways to it the walk goes
    on; within ``SLOW_NEAR`` beyond that it goes towards the robot no faster than ``BLIND_STEP`` allows (the
    robot may be nearer than seen), so it comes to rest there slowly rather than at contact. One
    already nearer steps back a little, straight away from it. A faint robot (``Obstacles.faint``, remembered behind
    the robot for longer than it is walked round) may have gone: the walk is not held back from it, but goes
    towards it, within ``FAINT_NEAR``, no faster than ``BLIND_STEP`` allows. Robots seen at a goal post count too
    (``ObstacleModeler`` takes them for the post: a keeper by its post was walked into). A walk backwards,
    ``BLIND`` of the heading where nothing is seen, goes no faster than the rules' pushing (``BLIND_STEP``).
    The rules spare the goalkeeper in its own
    penalty area (the GameController's goalkeeper, ``KEEPER_AREA_MARGIN`` inside the area's lines by the
    pose): it plays the ball there whoever stands at it."""
    team = game.own_team()
    if out.motion is not MotionType.walk_to:
        return
    if (team is not None and team.goalkeeper == game.player_number and pose.valid
            and pose.x < OWN_GOAL_X + pitch.PENALTY_AREA_LENGTH - KEEPER_AREA_MARGIN
            and abs(pose.y) < pitch.PENALTY_AREA_WIDTH / 2 - KEEPER_AREA_MARGIN):
        return
    x, y = out.target_x, out.target_y
    robots = [(o.x, o.y) for o in obstacles.obstacles if o.kind is ObstacleKind.robot]
    if pose.valid:  # what is seen at a goal post: the post, or a keeper standing by it
        robots += [(r.x, r.y) for r in percept.robots if any(
            math.dist(pose.to_field(r.x, r.y), (sx * pitch.LENGTH / 2, sy * (pitch.GOAL_INNER_WIDTH + pitch.GOAL_POST_DIAMETER) / 2)) < POST_SEEN
            for sx in (-1, 1) for sy in (-1, 1))]
    limits = [(rx, ry, min(room, BLIND_STEP) if room < SLOW_NEAR else room) for rx, ry in robots for room in [math.hypot(rx, ry) - p.push_distance]]
    limits += [(o.x, o.y, BLIND_STEP) for o in obstacles.faint if math.hypot(o.x, o.y) < FAINT_NEAR]
    for _ in range(3):  # held back from one, the target may lead further towards another: again
        for rx, ry, limit in limits:
            distance = math.hypot(rx, ry)
            if distance < 1.0:
                continue
            ux, uy = rx / distance, ry / distance
            towards = x * ux + y * uy
            if towards > limit:
                x, y = x - (towards - limit) * ux, y - (towards - limit) * uy
    length, way = math.hypot(x, y), math.atan2(y, x)
    if abs(way) > BLIND and length > BLIND_STEP and game.state is State.playing:  # backwards, blind
        if length > BLIND_TURN:  # far: turn (the walk turns first) and walk there facing the way
            out.target_rotation = way
        else:  # near: slowly
            x, y = x * BLIND_STEP / length, y * BLIND_STEP / length
    if math.hypot(x - out.target_x, y - out.target_y) > KICK_HELD_BACK:  # the kick's spot is out of reach: no kick
        out.walk_kick = WalkKick.none
    out.target_x, out.target_y = x, y
