"""A robot that walks to the ball and kicks it with the behaviour's own kicking (``kicking.approach_and_kick``),
the ball as ground truth gives it: for the walk-kick tests and ``benchmarks/kicks.py``."""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

from tafel.modules.behavior.kicking import KickParameters, approach_and_kick
from tafel.representations.geometry import Pose2D
from tafel.representations.modeling import BallModel
from tafel.representations.motion_control import MotionRequest, MotionType, WalkKick
from tests.support.driven import Driven


@dataclass
class KickTrial:
    """What ground truth says of one kick."""

    distance_mm: float  # the ball's travel
    direction_error_deg: float  # its direction against the wanted one (field frame)
    approach_to_moving_s: float  # from the start of the approach (1 m off) to the ball moving
    request_to_moving_s: float  # from the first frame the kick was asked for to the ball moving
    arrival_to_moving_s: float  # from the robot at its kicking pose (within 40 mm; the keyframe kick: asked for) to the ball moving
    falls: int


def kick_trial(engine: str, seed: int, direction_deg: float, strength: WalkKick = WalkKick.long, walk_kick: bool = True,
               start_behind: float = 600.0) -> KickTrial:
    """The robot at the field's centre facing +x, the ball ``start_behind`` mm ahead (a little aside by the
    seed); it approaches and kicks towards ``direction_deg`` (field frame) and the ball rolls out (8 s)."""
    driven = Driven(engine, seed=seed)
    x, y, heading = driven.sim.platform.robot_pose()
    aside = 60.0 * math.sin(seed * 1.7)
    ball0 = (x + start_behind * math.cos(heading) - aside * math.sin(heading), y + start_behind * math.sin(heading) + aside * math.cos(heading))
    driven.sim.platform.move_ball(*ball0)
    wanted = math.radians(direction_deg)
    p = replace(KickParameters(), walk_kick=walk_kick)
    t = 0.0
    asked_at = arrived_at = moved_at = None
    request = MotionRequest()  # kept from frame to frame, as the blackboard keeps the behaviour's
    while t < 15.0 and (moved_at is None or t < moved_at + 6.0):
        if moved_at is None:
            rx, ry, rh = driven.sim.platform.robot_pose()
            bx, by = driven.sim.platform.ball_position()
            ball_x, ball_y = Pose2D(rx, ry, rh).to_local(bx, by)
            ball = BallModel(valid=True, x=ball_x, y=ball_y)
            approach_and_kick(ball, math.remainder(wanted - rh, math.tau), p, request, strength)
            driven.request = replace(request)
            if asked_at is None and (request.walk_kick is not WalkKick.none or request.motion is MotionType.kick):
                asked_at = t
            there = request.motion is MotionType.kick or (request.walk_kick is not WalkKick.none and math.hypot(request.target_x, request.target_y) < 40.0)
            if arrived_at is None and there:
                arrived_at = t
            if math.hypot(bx - ball0[0], by - ball0[1]) > 30.0:
                moved_at = t
                if request.motion is not MotionType.kick:  # the keyframe kick plays on as asked, then stands
                    driven.request = MotionRequest(motion=MotionType.walk)
        driven.run(0.03)
        t += 0.03
    bx, by = driven.sim.platform.ball_position()
    driven.close()
    travel = math.hypot(bx - ball0[0], by - ball0[1])
    error = math.degrees(math.remainder(math.atan2(by - ball0[1], bx - ball0[0]) - wanted, math.tau))
    def since(start: float | None) -> float:
        return moved_at - start if moved_at is not None and start is not None else math.inf

    return KickTrial(travel, error, moved_at if moved_at is not None else math.inf, since(asked_at), since(arrived_at), driven.falls)
