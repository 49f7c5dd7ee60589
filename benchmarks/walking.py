"""The motion system against simulator ground truth, in MuJoCo and PyBullet in one run.

For each engine: walking speed at the largest request (forward, sideways, turning, 10 s each), falls
and odometry error over simulated minutes of random walk requests (a new one every 2 s, within the
walk's limits), ``push_survived_n``: walking forward at 150 mm/s, 0.1 s pushes on the torso from the
front, back, left and right at increasing force (20 N up, 2 to 2.6 s apart) until the robot falls, the
median over 5 seeds of the largest survived (0: the first, 20 N, threw it over; the push acts at the
torso's centre of mass in both engines, on robots of 5.40 kg in MuJoCo and 5.36 kg in PyBullet: 60 N
for 0.1 s is 1.1 m/s, a capture point about 190 mm beyond the body, farther than a leg reaches in one
step); the mean kick distance of 10 kicks, get-up successes from
the front and the back (10 seeds each; a success stands and is still upright 2 s later) with the median
and mean seconds from being laid down to standing, and the real-time factor while walking with both
cameras rendered. Only the get-ups: ``--parts getups``.

    python benchmarks/walking.py [--minutes 10] [--kicks 10] [--getups 10] [--push-seeds 5]
                                 [--engines mujoco,pybullet] [--parts speeds,random_walk,pushes,...]
                                 [--set parameters.WalkingEngine.foot_lift=25 ...]

``--set`` changes configuration values as ``tafel run --set`` does, for trying a parameter against
ground truth before it goes into ``config/``; the JSON line names what was set.

Prints one JSON line. Targets (MuJoCo, this 2-core machine): forward >= 200 mm/s, sideways >= 100 mm/s,
turning >= 0.8 rad/s, 0 falls in 10 minutes, odometry error <= 10 %, kick >= 3 m, get-up 10/10 each within
6 s (both engines), real-time factor >= 1.0 with cameras.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import sys
import time
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(REPO))
os.environ.setdefault("MUJOCO_GL", "egl")

from tafel.core.framework.errors import TafelError  # noqa: E402
from tafel.representations.motion_control import Foot, MotionRequest, MotionType, Odometry  # noqa: E402
from tests.support.driven import PUSH_FROM, Driven  # noqa: E402
from tests.support.getting_up import get_up, seeded_walk_s  # noqa: E402


def speeds(engine: str) -> dict[str, float]:
    """Ground-truth speed over 10 s at the largest request in each direction (from a standstill)."""
    result = {}
    for name, request in (("forward_mm_s", (1000.0, 0.0, 0.0)), ("sideways_mm_s", (0.0, 1000.0, 0.0)), ("turn_rad_s", (0.0, 0.0, 10.0))):
        driven = Driven(engine, overrides=OVERRIDES)
        x0, y0, heading = driven.sim.platform.robot_pose()
        turned0 = driven.turned
        driven.request = MotionRequest(motion=MotionType.walk, walk_x=request[0], walk_y=request[1], walk_rotation=request[2])
        driven.run(10.0)
        x1, y1, _ = driven.sim.platform.robot_pose()
        dx, dy = x1 - x0, y1 - y0
        along = {"forward_mm_s": math.cos(heading) * dx + math.sin(heading) * dy,
                 "sideways_mm_s": -math.sin(heading) * dx + math.cos(heading) * dy}
        result[name] = round((driven.turned - turned0) / 10.0 if name == "turn_rad_s" else along[name] / 10.0, 3)
        driven.close()
    return result


def random_walk(engine: str, minutes: float, seed: int = 1) -> dict[str, float]:
    """Falls and odometry error over random walk requests, a new one every 2 s."""
    rng = np.random.default_rng(seed)
    driven = Driven(engine, overrides=OVERRIDES)
    walked = error = 0.0
    for _ in range(int(minutes * 30)):
        x0, y0, h0 = driven.sim.platform.robot_pose()
        odometry = driven.motion[Odometry]
        o0 = (odometry.x, odometry.y, odometry.rotation)
        share = rng.uniform(0.0, 1.0)  # within the ellipsoid of the walk's limits
        direction = rng.normal(size=3)
        direction /= np.linalg.norm(direction)
        vx, vy, vr = share * direction * np.array([300.0, 130.0, 1.1])
        driven.request = MotionRequest(motion=MotionType.walk, walk_x=vx if vx >= 0 else vx / 2, walk_y=vy, walk_rotation=vr)
        driven.run(2.0)
        x1, y1, _ = driven.sim.platform.robot_pose()
        odometry = driven.motion[Odometry]
        # both motions in the frame the robot had at the start of the segment
        c, s = math.cos(-h0), math.sin(-h0)
        truth = np.array([c * (x1 - x0) - s * (y1 - y0), s * (x1 - x0) + c * (y1 - y0)])
        c, s = math.cos(-o0[2]), math.sin(-o0[2])
        ox, oy = odometry.x - o0[0], odometry.y - o0[1]
        measured = np.array([c * ox - s * oy, s * ox + c * oy])
        walked += float(np.linalg.norm(truth))
        error += float(np.linalg.norm(measured - truth))
        if driven.lying:
            driven.sim.platform.move_robot(*driven.sim.platform.robot_pose()[:2])  # stand it up again and go on
            driven.run(1.0)
    driven.close()
    return {"falls": driven.falls, "odometry_error_percent": round(100.0 * error / max(walked, 1.0), 2),
            "distance_walked_m": round(walked / 1000.0, 1)}


def kicks(engine: str, count: int) -> dict[str, float]:
    """Each kick with its own sensor-noise seed, the ball placed up to 15 mm off the ideal spot."""
    rng = np.random.default_rng(7)
    distances = []
    falls = 0
    for i in range(count):
        driven = Driven(engine, overrides=OVERRIDES, seed=i)
        x, y, heading = driven.sim.platform.robot_pose()
        foot = Foot.left if i % 2 == 0 else Foot.right
        side = 50.0 if foot is Foot.left else -50.0
        ahead, aside = 185.0 + rng.uniform(-15, 15), side + rng.uniform(-15, 15)
        c, s = math.cos(heading), math.sin(heading)
        ball = (x + ahead * c - aside * s, y + ahead * s + aside * c)
        driven.sim.platform.move_ball(*ball)
        driven.request = MotionRequest(motion=MotionType.kick, kick_foot=foot)
        driven.run(8.0)
        bx, by = driven.sim.platform.ball_position()
        distances.append(math.hypot(bx - ball[0], by - ball[1]))
        falls += driven.falls
        driven.close()
    return {"kick_mean_m": round(float(np.mean(distances)) / 1000.0, 2), "kick_min_m": round(min(distances) / 1000.0, 2),
            "kick_falls": falls}


def getups(engine: str, tries: int) -> dict[str, object]:
    """Successes within 15 s from lying on the front and on the back (standing, and still upright 2 s
    later; each seed laid down after walking its own 0 to 1 s, ``tests.support.getting_up``), the median
    and mean time (s, of the successes) from being laid down to standing, and how many stood up but fell
    again within the 2 s."""
    result: dict[str, object] = {}
    for side in ("front", "back"):
        times, fell_again = [], 0
        for seed in range(tries):
            attempt = get_up(engine, side, seed, seeded_walk_s(seed), overrides=OVERRIDES)
            if attempt.succeeded and attempt.up_s is not None:
                times.append(attempt.up_s)
            fell_again += attempt.up_s is not None and not attempt.stayed_up
        result[f"getup_{side}"] = f"{len(times)}/{tries}"
        result[f"getup_{side}_s"] = round(float(np.median(times)), 2) if times else None
        result[f"getup_{side}_mean_s"] = round(float(np.mean(times)), 2) if times else None
        result[f"getup_{side}_fell_again"] = fell_again
    return result


PUSH_FORCES = (20.0, 30.0, 40.0, 50.0, 60.0, 70.0, 80.0, 90.0, 100.0, 120.0)  # N, each for 0.1 s


def largest_push_survived(engine: str, side: str, seed: int, forces: tuple[float, ...] = PUSH_FORCES) -> float:
    """Walking forward at 150 mm/s, pushed from ``side`` for 0.1 s at each force in turn (2 to 2.6 s apart,
    seeded, so that the pushes meet the step at different phases) until the robot falls (ground truth):
    the largest force survived (0 when the first one throws it over)."""
    rng = np.random.default_rng(seed)
    driven = Driven(engine, overrides=OVERRIDES, seed=seed, start="-3500,0,0")
    driven.request = MotionRequest(motion=MotionType.walk, walk_x=150.0)
    driven.run(2.0)
    survived = 0.0
    for force in forces:
        driven.run(float(rng.uniform(0.0, 0.6)))
        driven.push_from(side, force)
        driven.run(2.0)
        if driven.falls:
            break
        survived = force
    driven.close()
    return survived


def pushes(engine: str, seeds: int) -> dict[str, dict[str, float]]:
    """``push_survived_n``: for each side, the median over ``seeds`` seeds of the largest push survived."""
    return {"push_survived_n": {side: float(np.median([largest_push_survived(engine, side, seed) for seed in range(seeds)]))
                                for side in PUSH_FROM}}


def realtime_with_cameras(engine: str, seconds: float = 10.0) -> float:
    driven = Driven(engine, overrides=OVERRIDES, cameras=True)
    driven.request = MotionRequest(motion=MotionType.walk, walk_x=200.0, walk_rotation=0.2)
    start = time.perf_counter()
    driven.run(seconds)
    wall = time.perf_counter() - start
    driven.close()
    return round(seconds / wall, 2)


#: ``--set`` values every simulation of this run gets (configuration overrides, KEY=VALUE)
OVERRIDES: list[str] = []

PARTS = ("speeds", "random_walk", "pushes", "kicks", "getups", "realtime")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--minutes", type=float, default=10.0, help="simulated minutes of random walking per engine")
    parser.add_argument("--kicks", type=int, default=10)
    parser.add_argument("--getups", type=int, default=10, help="tries from the front and from the back")
    parser.add_argument("--push-seeds", type=int, default=5, help="seeds of the pushes from each side")
    parser.add_argument("--engines", default="mujoco,pybullet")
    parser.add_argument("--parts", default=",".join(PARTS), help=f"which measurements, of {','.join(PARTS)}")
    parser.add_argument("--set", dest="overrides", action="append", default=[], metavar="KEY=VALUE",
                        help="override a configuration value, e.g. parameters.WalkingEngine.foot_lift=25 (repeatable)")
    args = parser.parse_args()
    OVERRIDES[:] = args.overrides
    try:  # a wrong key or value is said before minutes of simulation, as tafel run says it
        Driven(args.engines.split(",")[0], overrides=OVERRIDES).close()
    except TafelError as error:
        parser.error(f"--set: {error}")
    parts = args.parts.split(",")
    unknown = sorted(set(parts) - set(PARTS))
    if unknown:
        parser.error(f"--parts: unknown {', '.join(unknown)}; choose from {','.join(PARTS)}")
    report: dict[str, object] = {"benchmark": "walking", "overrides": args.overrides}
    for engine in args.engines.split(","):
        started = time.perf_counter()
        figures: dict[str, object] = {}
        if "speeds" in parts:
            figures.update(speeds(engine))
        if "random_walk" in parts:
            figures.update(random_walk(engine, args.minutes))
        if "pushes" in parts:
            figures.update(pushes(engine, args.push_seeds))
        if "kicks" in parts:
            figures.update(kicks(engine, args.kicks))
        if "getups" in parts:
            figures.update(getups(engine, args.getups))
        if "realtime" in parts:
            figures["realtime_factor_walking_with_cameras"] = realtime_with_cameras(engine)
        figures["benchmark_wall_s"] = round(time.perf_counter() - started, 1)
        report[engine] = figures
    report["targets_mujoco"] = {"forward_mm_s": 200, "sideways_mm_s": 100, "turn_rad_s": 0.8, "falls": 0,
                                "odometry_error_percent": 10, "kick_mean_m": 3.0, "getup": "10/10", "getup_s": 6.0,
                                "realtime_factor_walking_with_cameras": 1.0}
    print(json.dumps(report))


if __name__ == "__main__":
    main()
