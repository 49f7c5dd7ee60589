"""ObstacleModeler: the robots near this one, from what it sees and what its teammates say."""

from __future__ import annotations

import math
from dataclasses import dataclass

from tafel.core import Module, bounded, provides, requires, uses
from tafel.representations.field import GOAL_INNER_WIDTH, GOAL_POST_DIAMETER, LENGTH
from tafel.representations.infrastructure import FrameInfo
from tafel.representations.modeling import RobotPose
from tafel.representations.motion_control import Odometry
from tafel.representations.obstacles import ROBOT_RADIUS, Obstacle, ObstacleKind, Obstacles, RobotsPercept, same_robots
from tafel.representations.sonar import SonarPercept
from tafel.representations.team import TeamMates

#: the goal posts' centres on the field (mm)
GOAL_POSTS = [(sx * LENGTH / 2, sy * (GOAL_INNER_WIDTH + GOAL_POST_DIAMETER) / 2) for sx in (-1, 1) for sy in (-1, 1)]


def bearing(x: float, y: float) -> float:
    """rad from the heading to (x, y) (robot frame mm)."""
    return math.atan2(y, x)


@requires(FrameInfo)
@uses(RobotsPercept, SonarPercept, TeamMates, RobotPose, Odometry)
@provides(Obstacles)
class ObstacleModeler(Module):
    """Keeps the robots seen (``RobotsPercept``: in the images or, in ``--cameras off`` matches, from
    ground truth) and heard (``SonarPercept``'s echoes) for ``memory_s`` s, on the field while the pose is
    valid (so that they stay put while this robot turns and walks); one remembered beyond ``view_angle`` of
    the heading (beside or behind, where it cannot be seen again) for ``unseen_memory_s`` s, so that a robot
    walking backwards or sideways still keeps clear of it, and then, until ``faint_memory_s``, as ``faint``: it
    may have gone, so it blocks no way, but it may still stand there, so it is not walked into fast (5v5 seed 1,
    625.9 s: an opponent forgotten 2 s before, beside the robot, was pushed). It adds every teammate that said
    where it is within ``mate_timeout`` s and is not penalized (a penalized robot is off the field).
    A teammate's radius grows with the age of its message (``mate_spread`` mm/s: it may have walked
    meanwhile); the seen robot nearest a teammate, if within ``same_robot`` mm, is that teammate (another one
    beside it, say an opponent in a duel with it, stays a robot; a teammate said to be beyond ``view_angle`` is
    only a robot remembered there, never one seen this frame), and one seen
    again within two robot radii of where it was remembered replaces that memory. Something seen within
    ``post_radius`` mm of a goal post (where the pose puts them) is that post, not a robot. While the
    pose is not valid, seen robots are remembered as long where ``Odometry`` puts them (no teammates then)."""

    frame_info: FrameInfo
    robots_percept: RobotsPercept
    sonar_percept: SonarPercept
    team_mates: TeamMates
    robot_pose: RobotPose
    odometry: Odometry
    obstacles: Obstacles

    @dataclass
    class Parameters:
        memory_s: float = bounded(0.0, 10.0, 2.0)
        """s a seen robot is remembered after it was last seen (robots out of view while this one walks
        sideways or backwards are still walked round)"""
        view_angle: float = bounded(0.0, math.pi, 1.75)
        """rad either side of the heading within which robots are seen (``tafel match --cameras off``: 100
        degrees); one remembered beyond it is not looked for"""
        unseen_memory_s: float = bounded(0.0, 30.0, 5.0)
        """s a robot remembered beyond ``view_angle`` is kept after it was last seen"""
        faint_memory_s: float = bounded(0.0, 60.0, 15.0)
        """s a robot remembered beyond ``view_angle`` is kept as ``faint`` after it was last seen"""
        mate_timeout: float = bounded(0.0, 30.0, 6.0)
        """s after a teammate's message that its position is still used"""
        mate_spread: float = bounded(0.0, 500.0, 60.0)
        """mm/s the uncertainty of a teammate's position grows with the age of its message"""
        same_robot: float = bounded(0.0, 2000.0, 400.0)
        """mm: the seen robot nearest a teammate, if this near, is the teammate"""
        max_distance: float = bounded(500.0, 15000.0, 4000.0)
        """mm: obstacles farther away are left out"""
        post_radius: float = bounded(0.0, 1000.0, 300.0)
        """mm round a goal post within which what is seen is the post"""

    parameters: Parameters

    def __init__(self) -> None:
        self.seen: list[tuple[float, float, float]] = []  # field mm, mm, and when (s)
        self.unplaced: list[tuple[float, float, float]] = []  # while the pose is not valid: odometry's frame (mm), and when (s)

    def execute(self) -> None:
        p, pose, now, out = self.parameters, self.robot_pose, self.frame_info.time_s, self.obstacles
        obstacles: list[Obstacle] = []
        faint: list[Obstacle] = []
        seen = [(r.x, r.y) for r in self.robots_percept.robots] + [(e.x, e.y) for e in self.sonar_percept.echoes]
        if pose.valid:
            fresh = [(*pose.to_field(x, y), now) for x, y in seen]
            fresh = [(x, y, t) for x, y, t in fresh if all(math.hypot(x - px, y - py) > p.post_radius for px, py in GOAL_POSTS)]
            kept = [(x, y, t) for x, y, t in self.seen
                    if now - t <= self.memory(*pose.to_robot(x, y)) and all(math.hypot(x - fx, y - fy) > 2 * ROBOT_RADIUS for fx, fy, _ in fresh)]
            self.seen = fresh + kept  # a robot seen again replaces its memory
            mates = [m for m in self.team_mates.fresh(p.mate_timeout) if m.message.pose_valid and not m.message.penalized]
            for mate in mates:
                x, y = pose.to_robot(mate.message.x, mate.message.y)
                obstacles.append(Obstacle(x, y, ROBOT_RADIUS + p.mate_spread * mate.age, ObstacleKind.teammate, mate.age))
            claimed = self.claimed([(m.message.x, m.message.y) for m in mates], now)
            for k, (fx, fy, when) in enumerate(self.seen):
                if k in claimed:
                    continue
                x, y = pose.to_robot(fx, fy)
                self.remembered(x, y, now - when, obstacles, faint)
        else:  # without a pose: remembered where odometry puts them (robots seen now and then while it walks)
            self.seen = []
            odometry = self.odometry.as_pose2d()
            fresh = [(*odometry.to_global(x, y), now) for x, y in seen]
            kept = [(x, y, t) for x, y, t in self.unplaced
                    if now - t <= self.memory(*odometry.to_local(x, y)) and all(math.hypot(x - fx, y - fy) > 2 * ROBOT_RADIUS for fx, fy, _ in fresh)]
            self.unplaced = fresh + kept
            for ox, oy, when in self.unplaced:
                self.remembered(*odometry.to_local(ox, oy), now - when, obstacles, faint)
        if pose.valid:
            self.unplaced = []
        out.obstacles, out.faint = self.nearest_first(obstacles), self.nearest_first(faint)
        out.clearance = max(0.0, min((math.hypot(o.x, o.y) - o.radius for o in out.obstacles), default=0.0))

    def nearest_first(self, found: list[Obstacle]) -> list[Obstacle]:
        """``found`` within ``max_distance``, nearest first."""
        near = (o for o in found if math.hypot(o.x, o.y) <= self.parameters.max_distance)
        return sorted(near, key=lambda o: math.hypot(o.x, o.y))

    def claimed(self, places: list[tuple[float, float]], now: float) -> set[int]:
        """Which of ``self.seen`` are the teammates said to be at ``places`` (field mm; ``same_robots``). A teammate
        said to be beyond ``view_angle`` (where this robot sees nothing) may be a robot remembered there, never one
        seen this frame: that one is in view, and the teammate is not (5v5: an opponent seen beside the robot,
        within ``same_robot`` of a teammate behind it, was taken for the teammate and not kept from)."""
        p, pose = self.parameters, self.robot_pose
        seen = [(fx, fy) for fx, fy, _ in self.seen]
        in_view = [place for place in places if abs(bearing(*pose.to_robot(*place))) <= p.view_angle]
        claimed = same_robots(in_view, seen, p.same_robot)
        remembered = [k for k, (_, _, when) in enumerate(self.seen) if when < now and k not in claimed]
        beyond = [place for place in places if place not in in_view]
        return claimed | {remembered[j] for j in same_robots(beyond, [seen[k] for k in remembered], p.same_robot)}

    def memory(self, x: float, y: float) -> float:
        """s a robot remembered at (x, y) (robot frame mm) is kept: beyond ``view_angle``, where it is not looked
        for, as an obstacle for longer and then as ``faint``."""
        p = self.parameters
        return p.memory_s if abs(bearing(x, y)) <= p.view_angle else max(p.memory_s, p.unseen_memory_s, p.faint_memory_s)

    def obstacle_memory(self, x: float, y: float) -> float:
        """s a robot remembered at (x, y) (robot frame mm) stays an obstacle (then faint, or forgotten)."""
        p = self.parameters
        return p.memory_s if abs(bearing(x, y)) <= p.view_angle else max(p.memory_s, p.unseen_memory_s)

    def remembered(self, x: float, y: float, age: float, obstacles: list[Obstacle], faint: list[Obstacle]) -> None:
        """A robot seen ``age`` s ago, now at (x, y) (robot frame mm): to ``obstacles``, or to ``faint`` once older
        than ``obstacle_memory``."""
        (obstacles if age <= self.obstacle_memory(x, y) else faint).append(Obstacle(x, y, ROBOT_RADIUS, ObstacleKind.robot, age))
