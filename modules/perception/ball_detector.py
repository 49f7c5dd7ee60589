"""BallDetector: round orange blobs in both camera images (image positions only)."""

from __future__ import annotations

import math
from dataclasses import dataclass

import cv2
import numpy as np

from tafel.core import Module, provides, requires
from tafel.debug import Canvas, DebugRequest, Stopwatch
from tafel.representations.perception import BallCandidate, BallImagePercept, CameraImageBottom, CameraImageTop


@requires(CameraImageTop, CameraImageBottom)
@provides(BallImagePercept)
class BallDetector(Module):
    """Colour segmentation in HSV, then a shape check on each blob: large enough, and round enough (the
    share of its enclosing circle that is orange). Needs nothing but images, so it runs on a webcam too;
    ``BallLocator`` puts the candidates on the ground where camera matrices exist."""

    camera_image_top: CameraImageTop
    camera_image_bottom: CameraImageBottom
    ball_image_percept: BallImagePercept

    draw_candidates = DebugRequest("circle around every ball candidate in the images")
    segmentation = Stopwatch("colour segmentation and blob check of one image")

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
        max_candidates: int = 5

    parameters: Parameters

    def execute(self) -> None:
        found: list[BallCandidate] = []
        for camera, image in (("top", self.camera_image_top), ("bottom", self.camera_image_bottom)):
            pixels = np.asarray(image.image)
            if pixels.size == 0:
                continue
            with self.segmentation:
                candidates = self.candidates(camera, pixels)
            for candidate in candidates:
                candidate.horizontal_fov, candidate.vertical_fov = image.horizontal_fov, image.vertical_fov
                candidate.time_ns = image.time_ns
                if self.draw_candidates:
                    self.draw_candidates.canvas(Canvas.image(camera)).circle(candidate.x, candidate.y, candidate.radius, color="orange")
            found += candidates
        found.sort(key=lambda c: -c.radius)
        self.ball_image_percept.candidates = found[: self.parameters.max_candidates]

    def candidates(self, camera: str, image: np.ndarray) -> list[BallCandidate]:
        """Round orange blobs of one RGB image, largest first."""
        p = self.parameters
        if image.ndim != 3 or image.shape[2] != 3:
            return []
        hsv = cv2.cvtColor(np.ascontiguousarray(image), cv2.COLOR_RGB2HSV)
        mask = cv2.inRange(hsv, (p.hue_min, p.saturation_min, p.value_min), (p.hue_max, 255, 255))
        contours, _ = cv2.findContours(mask, cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_SIMPLE)
        height, width = image.shape[:2]
        found = []
        for contour in contours:
            (x, y), radius = cv2.minEnclosingCircle(contour)
            if radius < p.min_radius:
                continue
            area = max(cv2.contourArea(contour), float(len(contour)))
            fill = area / (math.pi * radius * radius)
            if fill >= p.min_fill:
                found.append(BallCandidate(camera, float(x), float(y), float(radius), fill, width, height))
        return sorted(found, key=lambda c: -c.radius)
