"""The approach to a kick walks round the ball when the robot stands past it (``kicking.round_the_ball``):
straight on, it pushed the ball back towards its own goal (issue 36: a keeper out of its goal dribbled the
ball 1.5 m back in a 2v2)."""

from __future__ import annotations

import math
from dataclasses import replace

import pytest

from tafel.modules.behavior.kicking import KickParameters, approach_and_kick
from tafel.representations.geometry import Pose2D
from tafel.representations.modeling import BallModel
from tafel.representations.motion_control import MotionRequest, MotionType, WalkKick


def walk_to_kick(start: tuple[float, float, float], walk_kick: bool, strength: WalkKick) -> tuple[float, bool]:
    """A point robot from ``start`` (field mm, mm, rad) steps 20 mm a frame towards the approach's walk target
    (turning at most 0.05 rad a frame) to kick the ball at the origin towards +x. Returns how near (mm) its
    centre came to the ball's and whether it got to kick."""
    p = replace(KickParameters(), walk_kick=walk_kick)
    x, y, heading = start
    out, nearest = MotionRequest(), math.inf
    for _ in range(400):
        ball_x, ball_y = Pose2D(x, y, heading).to_local(0.0, 0.0)
        nearest = min(nearest, math.hypot(ball_x, ball_y))
        approach_and_kick(BallModel(valid=True, x=ball_x, y=ball_y), math.remainder(-heading, math.tau), p, out, strength)
        if out.walk_kick is not WalkKick.none or out.motion is MotionType.kick:
            return nearest, True
        distance = math.hypot(out.target_x, out.target_y)
        step = min(distance, 20.0) / distance if distance > 0.0 else 0.0
        x, y = Pose2D(x, y, heading).to_global(out.target_x * step, out.target_y * step)
        heading += max(-0.05, min(0.05, out.target_rotation))
    return nearest, False


@pytest.mark.parametrize("start", [(300.0, 0.0, math.pi), (200.0, 50.0, math.pi), (1000.0, 100.0, math.pi), (500.0, -400.0, 2.5)])
@pytest.mark.parametrize("walk_kick, strength", [(True, WalkKick.long), (True, WalkKick.short), (False, WalkKick.long)])
def test_a_robot_past_the_ball_walks_round_it_to_kick(start: tuple[float, float, float], walk_kick: bool, strength: WalkKick) -> None:
    nearest, kicked = walk_to_kick(start, walk_kick, strength)
    assert kicked and nearest > 110.0  # straight on, the centre passed 6 to 116 mm from the ball's: through it


def test_a_robot_behind_the_ball_walks_straight_to_its_spot() -> None:
    p = replace(KickParameters(), walk_kick=True)
    out = MotionRequest()
    approach_and_kick(BallModel(valid=True, x=600.0, y=100.0), 0.3, p, out, WalkKick.long)
    spot = Pose2D(600.0, 100.0, 0.3).to_global(-p.walk_kick_distance, 0.0)
    assert math.hypot(out.target_x - spot[0], out.target_y - spot[1]) <= p.foot_offset + 1.0  # the spot, beside by the foot
