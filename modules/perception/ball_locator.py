"""BallLocator: where on the ground the detected ball is, through the camera matrices.

Each candidate is placed with the camera matrix of the instant its image was taken, interpolated
from the history motion hands over (``CameraMatrixBuffer``): with the newest matrix instead, a ball
seen while the head turns lands where the camera looks 30 to 40 ms later.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from tafel.core import Module, provides, requires
from tafel.debug import Canvas, DebugRequest, Plot
from tafel.modules.perception.image_geometry import focal_lengths, ground_point, pixel_ray, projectable
from tafel.representations.field import BALL_RADIUS
from tafel.representations.motion import CameraMatrix, CameraMatrixBuffer
from tafel.representations.perception import BallCandidate, BallImagePercept, BallPercept


@requires(BallImagePercept, CameraMatrixBuffer)
@provides(BallPercept)
class BallLocator(Module):
    """Intersects each candidate's ray with the plane at ball height and keeps the largest candidate
    whose size in the image fits the distance: a ball far away cannot look large."""

    ball_image_percept: BallImagePercept
    camera_matrix_buffer: CameraMatrixBuffer
    ball_percept: BallPercept

    draw_percept = DebugRequest("the located ball in its image and on the robot canvas")
    distance = Plot("mm from the robot to the located ball")

    @dataclass
    class Parameters:
        size_tolerance: float = 0.45
        """the radius may differ by this share from what the distance predicts"""
        time_aligned: bool = True
        """use the camera matrix of the image's time; false: the newest (to measure what alignment gains)"""

    parameters: Parameters

    def execute(self) -> None:
        percept = self.ball_percept
        percept.seen = False
        for candidate in self.ball_image_percept.candidates:
            buffer = self.camera_matrix_buffer
            matrix = buffer.at(candidate.camera, candidate.time_ns) if self.parameters.time_aligned else buffer.newest(candidate.camera)
            position = self.locate(candidate, matrix)
            if position is None:
                continue
            percept.seen = True
            percept.x, percept.y = float(position[0]), float(position[1])
            percept.image_x, percept.image_y, percept.radius = candidate.x, candidate.y, candidate.radius
            percept.camera = candidate.camera
            self.distance.add(math.hypot(percept.x, percept.y))
            if self.draw_percept:
                self.draw_percept.canvas(Canvas.image(candidate.camera)).circle(candidate.x, candidate.y, candidate.radius, color="blue", width=2)
                self.draw_percept.canvas(Canvas.ROBOT).circle(percept.x, percept.y, BALL_RADIUS, color="orange")
            return

    def locate(self, candidate: BallCandidate, matrix: CameraMatrix) -> np.ndarray | None:
        """The ball's centre on the ground (mm, robot frame), or None if position and size disagree."""
        if not matrix.valid or not projectable(candidate.horizontal_fov, candidate.vertical_fov):
            return None
        ray = pixel_ray(candidate.x, candidate.y, candidate.image_width, candidate.image_height,
                        candidate.horizontal_fov, candidate.vertical_fov)
        position = ground_point(ray, matrix.rotation, matrix.translation, BALL_RADIUS)
        if position is None:
            return None
        distance = float(np.linalg.norm(position - np.asarray(matrix.translation)))
        focal, _ = focal_lengths(candidate.image_width, candidate.image_height, candidate.horizontal_fov, candidate.vertical_fov)
        expected = focal * BALL_RADIUS / distance
        if abs(candidate.radius - expected) > self.parameters.size_tolerance * expected + 1.0:
            return None
        return position
