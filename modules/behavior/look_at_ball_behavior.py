"""LookAtBallBehavior: look at the ball while it is seen, glancing round now and then for the
localization; sweep the head to find it when it is not (first where a teammate's ball would be, while
the own pose is unsure); hold the head still while penalized."""

from __future__ import annotations

import math
from dataclasses import dataclass

from tafel.core import Module, provides, requires, uses
from tafel.representations.behavior import HOLD_SPEED, HeadMotionRequest
from tafel.representations.game import GameState
from tafel.representations.infrastructure import FrameInfo
from tafel.representations.modeling import BallModel, RobotPose
from tafel.representations.team import TeamMates

HEAD_YAW_LIMIT = 2.0857  # rad: the farthest the head turns to either side (requests beyond go there)


def sweep(start: float, direction: float, distance: float, amplitude: float) -> float:
    """Where a point moving ``distance`` from ``start`` in ``direction`` (+1/-1) is, bouncing at ±amplitude."""
    if amplitude <= 0:
        return 0.0
    position = start + direction * distance + amplitude  # unfold into [0, 4A) and fold back
    period = 4 * amplitude
    phase = position % period
    return (phase if phase <= 2 * amplitude else period - phase) - amplitude


@requires(BallModel, FrameInfo)
@uses(RobotPose, GameState, TeamMates)
@provides(HeadMotionRequest)
class LookAtBallBehavior(Module):
    """Points the head at the ball model's position while the ball is being seen. Once it has not been
    seen for ``lost_after`` (it rolled away, or was moved), the head sweeps left and right, starting
    towards the other side, where the ball most likely went out of view.

    A ball alone shows little of the field, so every ``glance_interval`` s (more often while the pose is
    not valid) the head glances left and right for lines and goals, unless the ball is close and the pose
    valid: then the striker needs it in view, and the ball model follows the robot's steps meanwhile anyway.

    While the pose is not valid (a robot carried elsewhere: the field cannot tell it from its twin, only
    the team's ball can) and the particles have gathered, the search looks first where a teammate's ball
    would be from the estimate and from its twin, those within the head's reach, the one nearer the head
    first, each for ``candidate_dwell`` s once the head can have got there (at ``track_speed``: from one
    side to the other takes over a second, and a dwell counted from the request ended before the head
    arrived), then sweeps; the sweep reaches ``search_amplitude_lost`` then, to show the field round the robot.

    While penalized the head holds still where it is (``max_speed`` 0): the rules allow a penalized
    robot no motion at all until the GameController unpenalizes it. Then it looks for the ball anew."""

    ball_model: BallModel
    frame_info: FrameInfo
    robot_pose: RobotPose
    game_state: GameState
    team_mates: TeamMates
    head_motion_request: HeadMotionRequest

    @dataclass
    class Parameters:
        camera_height: float = 480.0
        """mm, height of the top camera above the ground when standing"""
        camera_tilt: float = math.radians(1.2)
        """rad, downward tilt of the top camera relative to the head"""
        lost_after: float = 0.5
        """s without seeing the ball before searching"""
        search_amplitude: float = 1.2
        """rad, largest head yaw while searching"""
        search_pitch: float = 0.3
        """rad, head pitch while searching"""
        track_speed: float = 3.0
        """rad/s, head speed while tracking"""
        search_speed: float = 1.5
        """rad/s, head speed while searching"""

        glance_interval: float = 5.0
        """s between glances while the pose is valid"""
        glance_interval_lost: float = 1.5
        """s between glances while it is not"""
        glance_duration: float = 1.6
        """s of one glance: left, right, back"""
        glance_amplitude: float = 1.0
        """rad of head yaw a glance reaches to either side"""
        glance_min_ball_distance: float = 900.0
        """mm: nearer balls are never looked away from while the pose is valid (an unsure robot glances anyway:
        next to the ball it would kick it the wrong way)"""

        search_amplitude_lost: float = 2.0
        """rad, largest head yaw while searching with the pose not valid"""
        candidate_dwell: float = 0.8
        """s the head looks where a teammate's ball would be from one twin while the pose is not valid (the
        candidate places: below)"""
        candidate_deviation: float = 400.0
        """mm: candidate places are looked at once the particles have gathered this close (RobotPose.deviation)"""
        candidate_range: float = 5000.0
        """mm: candidate places this near are looked at"""
        candidate_reach: float = 2.4
        """rad: candidate places this far to either side are looked at (the head turns to 2.09, the top camera sees 0.5 beyond)"""
        candidate_jump: float = 500.0
        """mm (a radian counting 1000 mm): the estimate moved this far in a frame, the candidate places are looked at anew"""
        team_ball_age: float = 3.0
        """s: a teammate's ball reported this recently gives candidate places"""

    parameters: Parameters

    def __init__(self) -> None:
        self.search_start: tuple[float, float, float] | None = None  # (time s, yaw rad, direction)
        self.last_glance = 0.0  # s when the last glance started
        self.current: int | None = None  # the candidate place (0: from the estimate, 1: from the twin) looked at now
        self.step_ends = 0.0  # s when the look at it ends
        self.done: set[int] = set()  # the candidate places looked at in this round: the sweep after it lasts a dwell for each
        self.sweep_until: float | None = None  # s until which the search sweeps between two rounds of candidates
        self.last_pose: tuple[float, float, float] | None = None  # the pose of the last frame: did it jump?
        self.searching = False  # whether the last frame searched: a ball found is looked at a while before a glance

    def execute(self) -> None:
        p, ball, request = self.parameters, self.ball_model, self.head_motion_request
        now = self.frame_info.time_s
        if self.game_state.penalized:
            request.max_speed, self.search_start = HOLD_SPEED, None
            return
        if ball.valid and ball.time_since_seen <= p.lost_after:
            self.search_start, self.current, self.done, self.sweep_until = None, None, set(), None
            if self.searching:  # just found: the next glance only after an interval (an unsure pose needs the ball)
                self.searching, self.last_glance = False, now - p.glance_duration
            if self.glance(now, math.hypot(ball.x, ball.y)):
                return
            distance = max(math.hypot(ball.x, ball.y), 1.0)
            request.yaw = math.atan2(ball.y, ball.x)
            request.pitch = math.atan2(p.camera_height, distance) - p.camera_tilt
            request.max_speed = p.track_speed
            return
        self.searching = True
        if self.look_at_candidates(now):
            return
        amplitude = p.search_amplitude if self.robot_pose.valid else p.search_amplitude_lost
        if self.search_start is None:
            yaw = max(-amplitude, min(amplitude, request.yaw))
            self.search_start = (now, yaw, -1.0 if yaw > 0 else 1.0)
        started, yaw, direction = self.search_start
        request.yaw = sweep(yaw, direction, (now - started) * p.search_speed, amplitude)
        request.pitch = p.search_pitch
        request.max_speed = p.search_speed * 1.5  # the request itself moves at search speed; keep up with it

    def candidates(self) -> dict[int, tuple[float, float]]:
        """Where a teammate's ball would be (robot frame, mm) from the estimate (0) and from its twin (1), those
        within the head's reach; none while the pose is valid or the particles are spread."""
        p, pose = self.parameters, self.robot_pose
        if pose.valid or pose.deviation > p.candidate_deviation:
            return {}
        team = self.team_mates.freshest_ball(p.team_ball_age)
        if team is None:
            return {}
        # seen from the twin (turned by 180 degrees about the centre spot), a point lies where its mirror
        # image lies seen from the estimate
        places = {0: pose.to_robot(team.x, team.y), 1: pose.to_robot(-team.x, -team.y)}
        return {place: (x, y) for place, (x, y) in places.items()
                if abs(math.atan2(y, x)) <= p.candidate_reach and 0.0 < math.hypot(x, y) <= p.candidate_range}

    def look_at_candidates(self, now: float) -> bool:
        """Look in turn where the teammate's ball would be from either twin (the one nearer the head first),
        ``candidate_dwell`` s each once the head can be there, then sweep for as long before looking again;
        whether the head is doing so. A place that comes within reach during the round (the estimate moved) is
        looked at in it too; an estimate that jumps (the particles found another place) starts a new round."""
        p, request, pose = self.parameters, self.head_motion_request, self.robot_pose
        places = self.candidates()
        jumped = self.last_pose is not None and (math.hypot(pose.x - self.last_pose[0], pose.y - self.last_pose[1])
                                                 + 1000.0 * abs(math.remainder(pose.rotation - self.last_pose[2], math.tau))) > p.candidate_jump
        self.last_pose = (pose.x, pose.y, pose.rotation)
        if not places or jumped:
            self.current, self.done, self.sweep_until = None, set(), None
            if not places:
                return False
        if self.sweep_until is not None:
            if now < self.sweep_until:
                return False  # the sweep's turn: the ball may lie elsewhere, and the field round helps the particles
            self.sweep_until, self.done = None, set()
        head = max(-HEAD_YAW_LIMIT, min(HEAD_YAW_LIMIT, request.yaw))  # where the head is (about: it follows the request)
        if self.current is not None and (self.current not in places or now >= self.step_ends):
            self.done.add(self.current)  # looked there (or it went out of reach)
            self.current = None
        if self.current is None:
            pending = [place for place in places if place not in self.done]
            if not pending:
                self.sweep_until = now + max(1, len(self.done)) * p.candidate_dwell
                return False
            self.current = min(pending, key=lambda place: abs(math.atan2(places[place][1], places[place][0]) - head))
            target = math.atan2(places[self.current][1], places[self.current][0])
            travel = abs(max(-HEAD_YAW_LIMIT, min(HEAD_YAW_LIMIT, target)) - head) / p.track_speed  # the head's way there, then the dwell
            self.step_ends = now + travel + p.candidate_dwell
        x, y = places[self.current]
        request.yaw = math.atan2(y, x)
        request.pitch = math.atan2(p.camera_height, math.hypot(x, y)) - p.camera_tilt
        request.max_speed = p.track_speed
        self.search_start = None  # the sweep starts from where the head looked
        return True

    def glance(self, now: float, ball_distance: float) -> bool:
        """Glance round if it is time (or go on with a glance begun); whether the head is glancing."""
        p, request = self.parameters, self.head_motion_request
        interval = p.glance_interval if self.robot_pose.valid else p.glance_interval_lost
        near = ball_distance < p.glance_min_ball_distance and self.robot_pose.valid  # unsure, it must see the field
        if now - self.last_glance >= p.glance_duration + interval and not near:
            self.last_glance = now
        elapsed = now - self.last_glance
        if elapsed >= p.glance_duration or self.last_glance == 0.0:
            return False
        request.yaw = p.glance_amplitude * math.sin(2 * math.pi * elapsed / p.glance_duration)
        request.pitch = p.search_pitch
        request.max_speed = p.search_speed * 2.0
        return True
