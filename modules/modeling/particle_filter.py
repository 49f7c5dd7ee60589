"""The SelfLocator's particle cloud: field poses (N x 3: x mm, y mm, rotation rad) moved by the odometry with noise,
spread round a pose the robot was told, resampled by their weights, and summed up as one pose."""

from __future__ import annotations

import math
from typing import Protocol

import numpy as np

from tafel.representations import field
from tafel.representations.geometry import Pose2D


class FilterParameters(Protocol):
    """What these functions read of SelfLocator.Parameters."""

    rotation_noise: float
    roughening: float  # mm
    roughening_rotation: float  # rad
    translation_noise: float


KNOWN_POSE_STD, KNOWN_ROTATION_STD = 30.0, 0.03  # mm and rad: the particles' spread round a pose told (KnownPose)


def seen_from(poses: np.ndarray, points: np.ndarray) -> np.ndarray:
    """Robot-frame points (M x 2, mm) as seen from each of the field poses (N x 3: mm, mm, rad): N x M x 2
    field positions (mm)."""
    x, y, heading = (poses[:, i : i + 1] for i in range(3))
    c, s = np.cos(heading), np.sin(heading)
    return np.stack([x + c * points[:, 0] - s * points[:, 1], y + s * points[:, 0] + c * points[:, 1]], axis=-1)


def moved(pose: np.ndarray, forward: float, left: float, turn: float) -> np.ndarray:
    """A field pose (x, y, rotation) after a step given in its own frame."""
    return np.array(tuple(Pose2D(*pose) * Pose2D(forward, left, turn)))


def walk(particles: np.ndarray, forward: float, left: float, turn: float, p: FilterParameters, rng: np.random.Generator) -> None:
    """Each particle (in place) moved by the step (``forward``, ``left``, ``turn``: the odometry's in the previous
    robot frame), with noise that grows with the motion."""
    n = len(particles)
    step = math.hypot(forward, left)
    forwards = forward + rng.normal(0.0, p.translation_noise * step + 1.0, n)  # each particle's step
    lefts = left + rng.normal(0.0, p.translation_noise * step + 1.0, n)
    turns = turn + rng.normal(0.0, p.rotation_noise * abs(turn) + 0.0002 * step + 0.002, n)
    heading = particles[:, 2]
    particles[:, 0] += np.cos(heading) * forwards - np.sin(heading) * lefts
    particles[:, 1] += np.sin(heading) * forwards + np.cos(heading) * lefts
    particles[:, 2] = np.remainder(heading + turns + math.pi, math.tau) - math.pi


def spread_round(told: np.ndarray, n: int, rng: np.random.Generator) -> np.ndarray:
    """``n`` particles at a pose the robot was told (x, y, rotation), a little spread."""
    particles = told + rng.normal(0.0, [KNOWN_POSE_STD, KNOWN_POSE_STD, KNOWN_ROTATION_STD], (n, 3))
    particles[:, 2] = np.remainder(particles[:, 2] + math.pi, math.tau) - math.pi
    return particles


def on_field_prior(particles: np.ndarray, outside_std: float) -> np.ndarray:
    """Log-prior of each particle's place: a robot far beyond the lines is taken off by the referee, and
    one beyond the carpet stands in the wall; so poses out there need much more evidence (``outside_std``: mm
    beyond the lines at which a pose is one standard deviation unlikely)."""
    outside = np.maximum(np.abs(particles[:, 0]) - field.LENGTH / 2, 0.0) + np.maximum(np.abs(particles[:, 1]) - field.WIDTH / 2, 0.0)
    return -0.5 * (outside / outside_std) ** 2


def resampled(particles: np.ndarray, weights: np.ndarray, p: FilterParameters, rng: np.random.Generator) -> np.ndarray:
    """The particles drawn anew by their normalized ``weights`` (low variance), roughened against their collapse onto
    a few, once the weights' effective number is below half the particles'; else the particles as they are."""
    if 1.0 / np.sum(weights**2) < 0.5 * len(weights):
        particles = particles[low_variance_indices(weights, rng)]
        n = len(particles)
        particles[:, :2] += rng.normal(0.0, p.roughening, (n, 2))
        particles[:, 2] += rng.normal(0.0, p.roughening_rotation, n)
    return particles


def low_variance_indices(weights: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    """Indices of a low-variance (systematic) resampling of normalized ``weights``."""
    n = len(weights)
    positions = (rng.random() + np.arange(n)) / n
    return np.minimum(np.searchsorted(np.cumsum(weights), positions), n - 1)


def near(particles: np.ndarray, centre: np.ndarray) -> np.ndarray:
    """Which particles are within 600 mm and 0.6 rad of ``centre``."""
    return (np.hypot(particles[:, 0] - centre[0], particles[:, 1] - centre[1]) < 600.0) & (
        np.abs(np.remainder(particles[:, 2] - centre[2] + math.pi, math.tau) - math.pi) < 0.6)


def mean_pose(cluster: np.ndarray) -> tuple[float, float, float, float, float]:
    """The particles' mean pose (x, y, rotation) and their spreads round it: the deviation (mm) of their places and
    the circular deviation (rad) of their rotations."""
    x, y = float(cluster[:, 0].mean()), float(cluster[:, 1].mean())
    rotation = float(math.atan2(np.sin(cluster[:, 2]).mean(), np.cos(cluster[:, 2]).mean()))
    spread = np.hypot(cluster[:, 0] - x, cluster[:, 1] - y)
    deviation = float(math.sqrt(np.mean(spread**2)))
    rotation_deviation = float(math.sqrt(max(0.0, -2.0 * math.log(max(1e-9, math.hypot(np.sin(cluster[:, 2]).mean(), np.cos(cluster[:, 2]).mean()))))))
    return x, y, rotation, deviation, rotation_deviation
