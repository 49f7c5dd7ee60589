"""Camera latency: the ball's ground position while the head sweeps, with time-aligned and with newest
camera matrices, side by side.

MuJoCo renders each image 40 ms before cognition gets it (``--camera-latency-ms 40``), as on the NAO,
while the head turns across the ball at 2.5 rad/s. Every ball percept taken while the head moves at
least half that fast is compared with the ground truth; the error is the distance between percept and
truth as a share of the true distance. Three seeds of sensor noise each. Prints one JSON line.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from tests.support.head_sweep import summary, sweep_errors  # noqa: E402


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--latency-ms", type=float, default=40.0)
    parser.add_argument("--speed", type=float, default=2.5, help="head speed, rad/s")
    parser.add_argument("--seconds", type=float, default=6.0, help="simulated seconds of sweeping per seed")
    parser.add_argument("--seeds", type=int, default=3)
    args = parser.parse_args()
    result: dict[str, object] = {"benchmark": "camera_latency", "engine": "mujoco", "latency_ms": args.latency_ms,
                                 "head_speed_rad_s": args.speed, "seeds": args.seeds}
    for name, aligned in (("aligned", True), ("newest", False)):
        errors: list[float] = []
        for seed in range(args.seeds):
            errors += sweep_errors("mujoco", args.latency_ms, aligned, seconds=args.seconds, speed=args.speed, seed=seed)
        stats = summary(errors)
        result[name] = {"percepts": stats["percepts"], "mean_error_pct": round(100 * stats["mean"], 2),
                        "p95_error_pct": round(100 * stats["p95"], 2), "max_error_pct": round(100 * stats["max"], 2)}
    print(json.dumps(result))


if __name__ == "__main__":
    main()
