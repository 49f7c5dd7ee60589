"""The motion system against simulator ground truth, in MuJoCo and PyBullet in one run.

For each engine: walking speed at the largest request (forward, sideways, turning, 10 s each), falls
and odometry error over simulated minutes of random walk requests (a new one every 2 s, within the
walk's limits), the mean kick distance of 10 kicks, get-up successes from the front and the back
(10 tries each), and the real-time factor while walking with both cameras rendered.

    python benchmarks/walking.py [--minutes 10] [--kicks 10] [--getups 10] [--engines mujoco,pybullet]

Prints one JSON line. Targets (MuJoCo, this 2-core machine): forward >= 200 mm/s, sideways >= 100 mm/s,
turning >= 0.8 rad/s, 0 falls in 10 minutes, odometry error <= 10 %, kick >= 3 m, get-up >= 9/10 each,
real-time factor >= 1.0 with cameras.
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

from tafel.representations.motion_control import FallState, Foot, MotionRequest, MotionType, Odometry  # noqa: E402
from tests.support.simulation import Simulation  # noqa: E402


class Driven:
    """A simulation whose motion context gets ``request`` every frame (as ``motion:*`` would set it)."""

    def __init__(self, engine: str, cameras: bool = False, seed: int = 0) -> None:
        self.sim = Simulation(engine, cameras="on" if cameras else "off", ball="4000,2800", seed=str(seed))
        self.request = MotionRequest(motion=MotionType.stand)
        self.motion = self.sim.blackboard("motion")
        self.sim.runtime.runners["motion"].manager.before_frame.append(lambda: self.motion.set(self.request))
        self.turned = 0.0
        self.last_heading = self.sim.platform.robot_pose()[2]
        self.lying = False
        self.falls = 0
        self.sim.run(2.0, self.watch)

    def watch(self, sim: Simulation) -> None:
        heading = sim.platform.robot_pose()[2]
        self.turned += math.remainder(heading - self.last_heading, math.tau)
        self.last_heading = heading
        lying = sim.platform.posture() != "upright"
        if lying and not self.lying:
            self.falls += 1
        self.lying = lying

    def run(self, seconds: float) -> None:
        self.sim.run(seconds, self.watch)

    def close(self) -> None:
        self.sim.close()


def speeds(engine: str) -> dict[str, float]:
    """Ground-truth speed over 10 s at the largest request in each direction (from a standstill)."""
    result = {}
    for name, request in (("forward_mm_s", (1000.0, 0.0, 0.0)), ("sideways_mm_s", (0.0, 1000.0, 0.0)), ("turn_rad_s", (0.0, 0.0, 10.0))):
        driven = Driven(engine)
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
    driven = Driven(engine)
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
        driven = Driven(engine, seed=i)
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


def getups(engine: str, tries: int) -> dict[str, str]:
    result = {}
    for side in ("front", "back"):
        success = 0
        for attempt in range(tries):
            driven = Driven(engine, seed=attempt)
            x, y, heading = driven.sim.platform.robot_pose()
            driven.sim.platform.move_robot(x, y, heading, side)
            up = False
            for _ in range(15):
                driven.run(1.0)
                if driven.sim.platform.posture() == "upright" and driven.sim.platform.torso_height() > 280 \
                        and driven.motion[FallState].upright:
                    up = True
                    break
            success += up
            driven.close()
        result[f"getup_{side}"] = f"{success}/{tries}"
    return result


def realtime_with_cameras(engine: str, seconds: float = 10.0) -> float:
    driven = Driven(engine, cameras=True)
    driven.request = MotionRequest(motion=MotionType.walk, walk_x=200.0, walk_rotation=0.2)
    start = time.perf_counter()
    driven.run(seconds)
    wall = time.perf_counter() - start
    driven.close()
    return round(seconds / wall, 2)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--minutes", type=float, default=10.0, help="simulated minutes of random walking per engine")
    parser.add_argument("--kicks", type=int, default=10)
    parser.add_argument("--getups", type=int, default=10, help="tries from the front and from the back")
    parser.add_argument("--engines", default="mujoco,pybullet")
    args = parser.parse_args()
    report: dict[str, object] = {"benchmark": "walking"}
    for engine in args.engines.split(","):
        started = time.perf_counter()
        figures: dict[str, object] = {}
        figures.update(speeds(engine))
        figures.update(random_walk(engine, args.minutes))
        figures.update(kicks(engine, args.kicks))
        figures.update(getups(engine, args.getups))
        figures["realtime_factor_walking_with_cameras"] = realtime_with_cameras(engine)
        figures["benchmark_wall_s"] = round(time.perf_counter() - started, 1)
        report[engine] = figures
    report["targets_mujoco"] = {"forward_mm_s": 200, "sideways_mm_s": 100, "turn_rad_s": 0.8, "falls": 0,
                                "odometry_error_percent": 10, "kick_mean_m": 3.0, "getup": "9/10",
                                "realtime_factor_walking_with_cameras": 1.0}
    print(json.dumps(report))


if __name__ == "__main__":
    main()
