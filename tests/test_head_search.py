"""LookAtBallBehavior's search while the own pose is unsure: where a teammate's ball would be from either
twin, through the mocked blackboard."""

from __future__ import annotations

import math

from tafel.core.testing import ModuleHarness
from tafel.modules.behavior.look_at_ball_behavior import LookAtBallBehavior
from tafel.representations.behavior import HeadMotionRequest
from tafel.representations.infrastructure import FrameInfo
from tafel.representations.modeling import BallModel, RobotPose
from tafel.representations.team import TeamMate, TeamMates, TeamMessage

FRAME_NS = 33_333_333


def requests(pose: RobotPose, team_ball: tuple[float, float] | None, seconds: float) -> list[tuple[float, float]]:
    """(yaw, pitch) requested each frame for ``seconds`` with no ball of its own."""
    mates = []
    if team_ball is not None:
        said = TeamMessage(team=1, player=3, sent_ms=0, pose_valid=True, ball_seen=True, ball_x=team_ball[0], ball_y=team_ball[1], ball_age=0.2)
        mates = [TeamMate(message=said, age=0.3)]
    harness = ModuleHarness(LookAtBallBehavior, BallModel(valid=False), pose, TeamMates(mates=mates))
    out = []
    for i in range(1, int(seconds * 30) + 1):
        harness.set(FrameInfo(frame_number=i, time_ns=i * FRAME_NS))
        request = harness.execute()[HeadMotionRequest]
        out.append((request.yaw, request.pitch))
    return out


def test_an_unsure_robot_looks_where_the_teams_ball_would_be_from_either_twin() -> None:
    """Gathered on a pose it cannot tell from its twin, the head looks first where the teammate's ball lies
    seen from the estimate, then where it lies seen from the twin (both within reach), not a sweep."""
    pose = RobotPose(valid=False, lost=True, x=1000.0, y=-500.0, rotation=2.0, deviation=120.0)
    ball = (-500.0, 1000.0)
    p = LookAtBallBehavior.Parameters()
    seen = requests(pose, ball, 2 * p.candidate_dwell)
    estimate = math.atan2(*reversed(pose.to_robot(*ball)))
    twin = math.atan2(*reversed(pose.to_robot(-ball[0], -ball[1])))
    dwell = int(p.candidate_dwell * 30)
    assert abs(seen[dwell // 2][0] - estimate) < 1e-6 and abs(seen[dwell + dwell // 2][0] - twin) < 1e-6
    distance = math.hypot(*pose.to_robot(*ball))
    assert seen[dwell // 2][1] == math.atan2(p.camera_height, distance) - p.camera_tilt


def test_without_a_teams_ball_or_gathered_particles_it_sweeps() -> None:
    """No teammate's ball, or particles spread all over: the sweep, as wide as the head reaches when unsure."""
    p = LookAtBallBehavior.Parameters()
    spread = RobotPose(valid=False, lost=True, x=1000.0, y=-500.0, rotation=2.0, deviation=2000.0)
    for pose, ball in [(spread, (-500.0, 1000.0)), (RobotPose(valid=False, deviation=100.0), None)]:
        yaws = [yaw for yaw, _ in requests(pose, ball, 6.0)]
        assert max(yaws) > p.search_amplitude + 0.5 and min(yaws) < -p.search_amplitude - 0.5
    sure = [yaw for yaw, _ in requests(RobotPose(valid=True, deviation=100.0), (-500.0, 1000.0), 6.0)]
    assert max(map(abs, sure)) <= p.search_amplitude + 1e-9


def test_a_ball_found_by_searching_is_looked_at_before_the_next_glance() -> None:
    """Found after a search, the ball stays in view for a glance interval (an unsure robot decides its
    side by it) rather than being looked away from at once because a glance was due."""
    p = LookAtBallBehavior.Parameters()
    harness = ModuleHarness(LookAtBallBehavior, BallModel(valid=False), RobotPose(valid=False, lost=True), TeamMates(mates=[]))
    frame = 0
    for _ in range(4 * 30):  # 4 s of searching: a glance is long due
        frame += 1
        harness.set(FrameInfo(frame_number=frame, time_ns=frame * FRAME_NS))
        harness.execute()
    harness.set(BallModel(valid=True, seen=True, x=2000.0, y=500.0))
    yaws = []
    for _ in range(int(p.glance_interval_lost * 30) - 2):
        frame += 1
        harness.set(FrameInfo(frame_number=frame, time_ns=frame * FRAME_NS))
        yaws.append(harness.execute()[HeadMotionRequest].yaw)
    assert all(abs(yaw - math.atan2(500.0, 2000.0)) < 1e-9 for yaw in yaws)


def test_each_place_is_looked_at_for_a_dwell_once_the_head_can_be_there() -> None:
    """The two places lie on either side: the nearer to the head first, and each for ``candidate_dwell`` s
    after the time the head needs to get there at ``track_speed`` (a dwell counted from the request ended
    before the head had arrived: the ball behind the shoulder was never in view)."""
    p = LookAtBallBehavior.Parameters()
    pose = RobotPose(valid=False, lost=True, x=0.0, y=0.0, rotation=0.0, deviation=120.0)
    ball = (2000.0 * math.cos(1.9), 2000.0 * math.sin(1.9))  # from the estimate 1.9 rad left, from the twin 1.24 right
    yaws = [yaw for yaw, _ in requests(pose, ball, 4.0)]
    left, right = 1.9, 1.9 - math.pi
    runs: list[tuple[float, int]] = []  # (yaw, frames in a row)
    for yaw in yaws:
        if runs and abs(runs[-1][0] - yaw) < 1e-6:
            runs[-1] = (yaw, runs[-1][1] + 1)
        else:
            runs.append((yaw, 1))
    assert abs(runs[0][0] - right) < 1e-6 and abs(runs[1][0] - left) < 1e-6  # the nearer to the head (at 0) first
    assert runs[0][1] >= (abs(right) / p.track_speed + p.candidate_dwell) * 30 - 1
    assert runs[1][1] >= ((left - right) / p.track_speed + p.candidate_dwell) * 30 - 1


def test_a_place_that_comes_within_reach_during_the_round_is_looked_at_before_the_sweep() -> None:
    """The body turns while the head looks: the place from the estimate, out of reach at first, comes within
    reach while the head looks at the twin's; it is looked at next, not left for the sweep (it was, when the
    round was fixed at its start)."""
    p = LookAtBallBehavior.Parameters()
    ball = (2000.0 * math.cos(2.6), 2000.0 * math.sin(2.6))  # from the estimate 2.6 rad left (beyond reach), from the twin 0.54 right
    said = TeamMessage(team=1, player=3, sent_ms=0, pose_valid=True, ball_seen=True, ball_x=ball[0], ball_y=ball[1], ball_age=0.2)
    harness = ModuleHarness(LookAtBallBehavior, BallModel(valid=False), TeamMates(mates=[TeamMate(message=said, age=0.3)]))
    looks: list[tuple[float, float, float]] = []  # (requested yaw, the estimate's place, the twin's place), rad
    for i in range(1, 91):  # 3 s, the body turning left at 0.6 rad/s
        pose = RobotPose(valid=False, lost=True, x=0.0, y=0.0, rotation=0.02 * i, deviation=120.0)
        harness.set(FrameInfo(frame_number=i, time_ns=i * FRAME_NS), pose)
        yaw = harness.execute()[HeadMotionRequest].yaw
        looks.append((yaw, math.atan2(*reversed(pose.to_robot(*ball))), math.atan2(*reversed(pose.to_robot(-ball[0], -ball[1])))))
    assert abs(looks[0][0] - looks[0][2]) < 1e-6 and abs(looks[0][1]) > p.candidate_reach  # the twin's first: the other is out of reach
    twin_done = next(i for i, (yaw, _, twin) in enumerate(looks) if abs(yaw - twin) > 1e-6)
    assert all(abs(yaw - estimate) < 1e-6 for yaw, estimate, _ in looks[twin_done:twin_done + int(p.candidate_dwell * 30)])
