"""BallDetector: the orange ball in both camera images, and where it lies on the ground."""

from __future__ import annotations

import math
from dataclasses import dataclass

import cv2
import numpy as np

from core import Module, provides, requires
from debug import drawing, plot, request, stopwatch
from representations.field import BALL_RADIUS
from representations.motion import CameraMatrixBottom, CameraMatrixTop
from representations.perception import BallPercept, CameraImageBottom, CameraImageTop

DRAW_PERCEPT = request("BallDetector:draw_percept", "circle around the detected ball in the image")
DRAW_CANDIDATES = request("BallDetector:draw_candidates", "every orange blob, rejected ones in red")


@dataclass
class Candidate:
    camera: str
    x: float  # px
    y: float
    radius: float
    fill: float  # share of the enclosing circle that is orange


def pixel_ray(x: float, y: float, width: int, height: int, horizontal_fov: float, vertical_fov: float) -> np.ndarray:
    """The direction of a pixel in the camera frame (x along the optical axis, y left, z up)."""
    fx = (width / 2) / math.tan(horizontal_fov / 2)
    fy = (height / 2) / math.tan(vertical_fov / 2)
    return np.array([1.0, -(x - width / 2) / fx, -(y - height / 2) / fy])


def ground_point(ray_camera: np.ndarray, rotation: np.ndarray, translation: np.ndarray, height: float) -> np.ndarray | None:
    """Where a camera ray meets the plane ``z = height`` in the robot frame (mm), None above the horizon."""
    direction = np.asarray(rotation) @ ray_camera
    if direction[2] >= -1e-6:
        return None
    scale = (height - translation[2]) / direction[2]
    return np.asarray(translation) + scale * direction


@requires(CameraImageTop, CameraImageBottom, CameraMatrixTop, CameraMatrixBottom)
@provides(BallPercept)
class BallDetector(Module):
    """Colour segmentation in HSV, then shape checks on each blob: round enough (share of its enclosing
    circle), large enough, and about as large as a ball at the distance the camera matrix gives."""

    @dataclass
    class Parameters:
        hue_min: int = 3
        """OpenCV hue (0..180) of orange, lower end"""
        hue_max: int = 22
        saturation_min: int = 140
        value_min: int = 90
        min_radius: float = 2.0
        """px"""
        min_fill: float = 0.55
        """share of the enclosing circle that must be orange"""
        size_tolerance: float = 0.45
        """the radius may differ by this share from what the distance predicts"""

    def execute(self) -> None:
        percept = self.ball_percept
        percept.seen = False
        best: tuple[Candidate, np.ndarray] | None = None
        for camera, image, matrix in (("top", self.camera_image_top, self.camera_matrix_top),
                                      ("bottom", self.camera_image_bottom, self.camera_matrix_bottom)):
            if image.horizontal_fov <= 0 or not matrix.valid:
                continue
            with stopwatch("BallDetector:segmentation"):
                candidates = self.candidates(camera, np.asarray(image.image))
            for candidate in candidates:
                position = self.on_ground(candidate, image, matrix)
                accepted = position is not None
                if DRAW_CANDIDATES:
                    drawing(f"image:{camera}").circle(candidate.x, candidate.y, candidate.radius, color="orange" if accepted else "red")
                if accepted and (best is None or candidate.radius > best[0].radius):
                    best = (candidate, position)
        if best is None:
            return
        candidate, position = best
        percept.seen = True
        percept.x, percept.y = float(position[0]), float(position[1])
        percept.image_x, percept.image_y, percept.radius = candidate.x, candidate.y, candidate.radius
        percept.camera = candidate.camera
        plot("BallDetector:distance", math.hypot(percept.x, percept.y))
        if DRAW_PERCEPT:
            drawing(f"image:{candidate.camera}").circle(candidate.x, candidate.y, candidate.radius, color="blue", width=2)
            drawing("field").circle(percept.x, percept.y, BALL_RADIUS, color="orange")

    def candidates(self, camera: str, image: np.ndarray) -> list[Candidate]:
        """Round orange blobs of one image, largest first."""
        p = self.parameters
        if image.ndim != 3 or image.shape[2] != 3 or image.size == 0:
            return []
        hsv = cv2.cvtColor(np.ascontiguousarray(image), cv2.COLOR_RGB2HSV)
        mask = cv2.inRange(hsv, (p.hue_min, p.saturation_min, p.value_min), (p.hue_max, 255, 255))
        contours, _ = cv2.findContours(mask, cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_SIMPLE)
        found = []
        for contour in contours:
            (x, y), radius = cv2.minEnclosingCircle(contour)
            if radius < p.min_radius:
                continue
            area = max(cv2.contourArea(contour), float(len(contour)))
            fill = area / (math.pi * radius * radius)
            if fill < p.min_fill:
                continue
            found.append(Candidate(camera, float(x), float(y), float(radius), fill))
        return sorted(found, key=lambda c: -c.radius)

    def on_ground(self, candidate: Candidate, image: CameraImageTop | CameraImageBottom, matrix: CameraMatrixTop | CameraMatrixBottom) -> np.ndarray | None:
        """The ball's centre on the ground (mm, robot frame), or None if position and size disagree."""
        height, width = image.image.shape[:2]
        ray = pixel_ray(candidate.x, candidate.y, width, height, image.horizontal_fov, image.vertical_fov)
        position = ground_point(ray, matrix.rotation, matrix.translation, BALL_RADIUS)
        if position is None:
            return None
        distance = float(np.linalg.norm(position - np.asarray(matrix.translation)))
        focal = (width / 2) / math.tan(image.horizontal_fov / 2)
        expected = focal * BALL_RADIUS / distance
        if abs(candidate.radius - expected) > self.parameters.size_tolerance * expected + 1.0:
            return None
        return position
