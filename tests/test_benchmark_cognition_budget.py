"""benchmarks/cognition_budget.py's figures: each cognition frame's wall time and its thread's CPU time."""

from __future__ import annotations

import math
from pathlib import Path
from types import ModuleType

import cv2
import numpy as np
import pytest

from tafel.platforms.images import standing_camera
from tests.support.benchmarks import load_benchmark


def benchmark() -> ModuleType:
    return load_benchmark("cognition_budget")


@pytest.mark.slow
def test_each_frame_has_its_wall_time_and_its_cpu_time(tmp_path: Path) -> None:
    """A painted field (carpet below, hall above) seen by both cameras: the default cognition runs each frame once, and
    each frame has a wall time and the cognition thread's CPU time (what a loaded machine disturbs least); each pair,
    run again ``repeats`` times, its least CPU time (cpu_best_ms); and the page faults per frame."""
    budget = benchmark()
    pairs = []
    for shade in (0, 30):
        shots = []
        for camera, (width, height) in (("top", (640, 480)), ("bottom", (320, 240))):
            image = np.empty((height, width, 3), np.uint8)
            image[:] = (40, 140 + shade, 50)
            image[: height // 3] = (120, 110, 100)
            cv2.circle(image, (width // 2, 2 * height // 3), height // 20, (240, 240, 240), -1)
            shots.append(budget.Shot(image, standing_camera(camera), math.radians(56.3), math.radians(43.7)))
        pairs.append((shots[0], shots[1]))
    source = tmp_path / "top.png"
    cv2.imwrite(str(source), pairs[0][0].image)
    whole, cpu, modules, best, faults = budget.cognition(source, pairs, 3, repeats=2)
    assert len(whole) == len(cpu) == 3
    assert all(seconds > 0.0 for seconds in whole + cpu)
    assert "SPLBallDetector" in modules and len(modules["SPLBallDetector"]) == 3
    assert len(best) == len(pairs) and all(0.0 < seconds < math.inf for seconds in best)  # each pair's least CPU time
    assert faults >= 0.0
