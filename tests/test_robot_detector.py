"""RobotDetector: robots in drawn scenes through the mocked blackboard, and in a MuJoCo render of a match's world."""

from __future__ import annotations

import math
import os
from types import ModuleType

import cv2
import numpy as np
import pytest

from tafel.core.testing import ModuleHarness
from tafel.modules.perception.image_geometry import ImageProjection
from tafel.modules.perception.robot_detector import RobotDetector
from tafel.representations.motion import CameraMatrix, CameraMatrixBuffer
from tafel.representations.obstacles import RobotsPercept
from tafel.representations.perception import CameraImageBottom, CameraImageTop, FieldBoundary, FieldColor, SegmentedImage
from tests.support.benchmarks import load_benchmark

WIDTH, HEIGHT = 640, 480
FOV = (math.radians(56.3), math.radians(43.7))
GREEN, WHITE, GREY = (40, 140, 40), (235, 235, 235), (110, 110, 110)


def camera(pitch: float = 0.35, height: float = 480.0) -> CameraMatrix:
    """A camera ``height`` mm above the robot's origin, looking ahead and ``pitch`` rad down."""
    forward = [math.cos(pitch), 0.0, -math.sin(pitch)]
    up = [math.sin(pitch), 0.0, math.cos(pitch)]
    return CameraMatrix(np.column_stack([forward, [0.0, 1.0, 0.0], up]), np.array([0.0, 0.0, height]), True)


class Scene:
    """A drawn top camera image: carpet up to ``field_end`` mm ahead, the hall above it, and things in it."""

    def __init__(self, field_end: float = 5000.0) -> None:
        self.matrix = camera()
        self.projection = ImageProjection(self.matrix, WIDTH, HEIGHT, *FOV)
        self.image = np.zeros((HEIGHT, WIDTH, 3), np.uint8)
        self.image[:] = GREY
        self.polygon([(field_end, -8000.0, 0.0), (field_end, 8000.0, 0.0), (100.0, 8000.0, 0.0), (100.0, -8000.0, 0.0)], GREEN)
        carpet = (self.image == np.array(GREEN, np.uint8)).all(axis=2)
        self.boundary = np.where(carpet.any(axis=0), np.argmax(carpet, axis=0), HEIGHT).astype(np.float32)  # where the carpet ends

    def pixels(self, points: list[tuple[float, float, float]]) -> np.ndarray:
        found, front = self.projection.to_image(np.array(points, float))
        assert front.all()
        return found

    def polygon(self, points: list[tuple[float, float, float]], colour: tuple[int, int, int]) -> None:
        cv2.fillConvexPoly(self.image, cv2.convexHull(np.round(self.pixels(points)).astype(np.int32)), colour)

    def robot(self, x: float, y: float, width: float = 220.0, height: float = 560.0) -> None:
        """A robot standing at (x, y): a box ``width`` mm wide and deep, white with grey joints."""
        half = width / 2
        corners = [(x + dx, y + dy, z) for dx in (-half, half) for dy in (-half, half) for z in (0.0, height)]
        self.polygon(corners, WHITE)
        self.polygon([(x - half, y - half, 250.0), (x - half, y + half, 250.0), (x - half, y + half, 300.0), (x - half, y - half, 300.0)], GREY)

    def line(self, x: float) -> None:
        """A field line across the view, ``x`` mm ahead (50 mm wide)."""
        self.polygon([(x, -3000.0, 0.0), (x, 3000.0, 0.0), (x + 50.0, 3000.0, 0.0), (x + 50.0, -3000.0, 0.0)], WHITE)

    def ball(self, x: float, y: float) -> None:
        centre = self.pixels([(x, y, 50.0)])[0]
        radius = self.projection.fx * 50.0 / math.hypot(x, y, 480.0 - 50.0)
        cv2.circle(self.image, (int(centre[0]), int(centre[1])), int(radius), WHITE, -1)

    def detect(self) -> list[tuple[float, float]]:
        green = (self.image == np.array(GREEN, np.uint8)).all(axis=2)
        hsv = cv2.cvtColor(self.image, cv2.COLOR_RGB2HSV)
        harness = ModuleHarness(
            RobotDetector,
            CameraImageTop(image=self.image, horizontal_fov=FOV[0], vertical_fov=FOV[1]),
            CameraImageBottom(image=np.zeros((0, 0, 3), np.uint8)),
            SegmentedImage(top_hsv=hsv, top_green=green),
            FieldColor(valid=True),
            FieldBoundary(top=self.boundary),
            CameraMatrixBuffer.of(self.matrix, self.matrix),
        )
        return [(r.x, r.y) for r in harness.execute()[RobotsPercept].robots]


def near(found: list[tuple[float, float]], x: float, y: float, tolerance: float = 150.0) -> bool:
    return any(math.hypot(fx - x, fy - y) <= tolerance for fx, fy in found)


def test_a_robot_standing_on_the_field_is_found_where_it_stands() -> None:
    scene = Scene()
    scene.robot(1500.0, 300.0)
    found = scene.detect()
    assert len(found) == 1 and near(found, 1500.0, 300.0), found


def test_lines_and_the_ball_are_no_robots_but_a_robot_among_them_is() -> None:
    scene = Scene()
    scene.line(900.0)
    scene.line(2200.0)
    scene.ball(1200.0, -400.0)
    assert scene.detect() == []
    scene.robot(2000.0, -600.0)  # standing on the far line
    found = scene.detect()
    assert len(found) == 1 and near(found, 2000.0, -600.0), found


def test_what_stands_beyond_the_field_is_not_seen() -> None:
    scene = Scene(field_end=3000.0)
    scene.robot(4000.0, 0.0)  # in the hall, above the field's boundary in the image
    assert scene.detect() == []


def test_two_robots_side_by_side_are_two() -> None:
    scene = Scene()
    scene.robot(1800.0, -700.0)
    scene.robot(1800.0, 700.0)
    found = scene.detect()
    assert len(found) == 2 and near(found, 1800.0, -700.0) and near(found, 1800.0, 700.0), found


def benchmark() -> ModuleType:
    return load_benchmark("robots")


@pytest.mark.slow
def test_robots_in_a_rendered_match_world_are_found_and_nothing_else() -> None:
    """MuJoCo renders (both cameras, the NAO's sizes) of other robots in the stand pose: each visible one
    is found within 300 mm of its torso; an empty view finds none."""
    os.environ.setdefault("MUJOCO_GL", "egl")
    bench = benchmark()
    scenes = bench.RobotScenes(3)
    detection = bench.Detection()
    try:
        def found_in(viewer: tuple[float, float, float], others: list[tuple[float, float, float]]) -> tuple[list, list]:
            shots, truth = scenes.render(viewer, (0.0, 0.1), others)
            inputs = {c: (image, matrix, bench.horizontal_fov(*bench.SIZES[c]), bench.VERTICAL_FOV) for c, (image, matrix) in shots.items()}
            return detection(inputs), truth

        found, _ = found_in((-2000.0, 0.0, 0.0), [])
        assert found == []
        found, truth = found_in((-2000.0, 0.0, 0.0), [(-800.0, 400.0, math.pi), (0.0, -900.0, 1.0)])
        assert len(found) == 2, (found, truth)
        for x, y in truth:
            assert near(found, x, y, 300.0), (found, truth)
    finally:
        scenes.close()
