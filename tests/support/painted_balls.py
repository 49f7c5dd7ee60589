"""Painted camera images of a ball on the carpet for SPLBallDetector's tests, and the detector run over them: a
standing NAO's top camera at 320x240, the ball of the size a ball has where it is painted."""

from __future__ import annotations

import math
from collections.abc import Callable
from types import SimpleNamespace

import cv2
import numpy as np

from tafel.modules.perception.image_geometry import ImageProjection
from tafel.representations.field import BALL_RADIUS
from tafel.representations.motion import CameraMatrix
from tafel.representations.perception import BallCandidate, BallImagePercept
from tafel.tools.simulation.scene_frames import Perception

FOV = (math.radians(56.3), math.radians(43.7))
WIDTH, HEIGHT = 320, 240
PITCH = 0.4
#: a lit carpet (BGR)
CARPET = (45, 140, 50)


class SureModel:
    """A classifier stub with one score for every candidate (a logit)."""

    def __init__(self, score: float) -> None:
        self.score = score

    def scores(self, rows: np.ndarray) -> np.ndarray:
        return np.full(len(np.atleast_2d(rows)), self.score, np.float32)


def camera() -> CameraMatrix:
    """A standing NAO's top camera, level, pitched down by ``PITCH``."""
    c, s = math.cos(PITCH), math.sin(PITCH)
    return CameraMatrix(np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]]), np.array([0.0, 0.0, 503.0]), True)


def ball_radius(x: float, y: float) -> float:
    """The radius (px) a ball on the ground has at pixel (x, y)."""
    projection = ImageProjection(camera(), WIDTH, HEIGHT, *FOV)
    centre, hit = projection.to_ground(np.array([x]), np.array([y]), BALL_RADIUS)
    assert hit[0]
    return projection.fx * BALL_RADIUS / float(np.linalg.norm(np.append(centre[0], BALL_RADIUS) - projection.translation))


def painted_ball(patch_grey: int, white: int = 230, carpet: tuple[int, int, int] = CARPET, noise: float = 4.0, seed: int = 3,
                 behind: Callable[[np.ndarray, float, float, float], None] | None = None,
                 ) -> tuple[np.ndarray, tuple[float, float, float]]:
    """A noisy carpet (BGR ``carpet``, ``noise`` its standard deviation) with a ball at (160, 150), ``white`` with six
    patches ``patch_grey``; ``behind(image, x, y, radius)`` paints what lies behind it first. The image and the ball's
    centre and radius (px)."""
    rng = np.random.default_rng(seed)
    image = np.empty((HEIGHT, WIDTH, 3), np.uint8)
    image[:] = carpet
    x, y = 160.0, 150.0
    radius = ball_radius(x, y)
    if behind is not None:
        behind(image, x, y, radius)
    paint_ball(image, x, y, radius, white, patch_grey)
    image[:] = np.clip(image.astype(int) + rng.normal(0, noise, image.shape), 0, 255).astype(np.uint8)
    return image, (x, y, radius)


def paint_ball(image: np.ndarray, x: float, y: float, radius: float, white: int, patch_grey: int) -> None:
    """A ball at (x, y) (px) into ``image``: a disc ``white`` with six patches ``patch_grey``, five round the middle."""
    cv2.circle(image, (int(x), int(y)), int(round(radius)), (white,) * 3, -1)
    for angle in np.linspace(0, 2 * math.pi, 5, endpoint=False):
        cv2.circle(image, (int(x + 0.55 * radius * math.cos(angle)), int(y + 0.55 * radius * math.sin(angle))), max(1, int(0.3 * radius)),
                   (patch_grey,) * 3, -1)
    cv2.circle(image, (int(x), int(y)), max(1, int(0.3 * radius)), (patch_grey,) * 3, -1)


def found(image: np.ndarray, model: SureModel | None, **parameters: object) -> list[BallCandidate]:
    """The detector's candidates in ``image`` (top camera) with the classifier ``model`` (None: the classifier off)."""
    perception = Perception()
    detector = perception.manager.module("SPLBallDetector")
    detector.parameters.classifier = model is not None
    detector.model = model
    for name, value in parameters.items():
        setattr(detector.parameters, name, value)
    view = SimpleNamespace(image=image, horizontal_fov=FOV[0], vertical_fov=FOV[1], matrix=camera())
    empty = SimpleNamespace(image=np.zeros((0, 0, 3), np.uint8), horizontal_fov=0.0, vertical_fov=0.0, matrix=CameraMatrix())
    for _ in range(2):
        board = perception({"top": view, "bottom": empty})  # type: ignore[dict-item]
    return board[BallImagePercept].candidates


def found_at(candidates: list[BallCandidate], ball: tuple[float, float, float]) -> bool:
    """Whether exactly one candidate was reported and its centre lies within the ball."""
    x, y, radius = ball
    return len(candidates) == 1 and math.hypot(candidates[0].x - x, candidates[0].y - y) <= radius
