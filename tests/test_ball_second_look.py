"""SPLBallDetector's second look (issue 31): a small ball blurred by the head's turn has grey, not black, patches and
fails the checks; it is a ball when it passes looser checks and the classifier is sure, and only then."""

from __future__ import annotations

import math

import cv2
import numpy as np
import pytest

from tests.support.painted_balls import CARPET, HEIGHT, WIDTH, SureModel, ball_radius, found, paint_ball


def blurred_ball_image(patch_grey: int) -> tuple[np.ndarray, tuple[float, float, float]]:
    """A carpet with a ball of the size a ball has there, its patches ``patch_grey`` (the white is 230), smeared
    sideways by a head turn; the ball's centre and radius (px)."""
    rng = np.random.default_rng(3)
    image = np.empty((HEIGHT, WIDTH, 3), np.uint8)
    image[:] = CARPET
    image[:] = np.clip(image.astype(int) + rng.normal(0, 4, image.shape), 0, 255).astype(np.uint8)
    x, y = 160.0, 150.0
    radius = ball_radius(x, y)
    paint_ball(image, x, y, radius, 230, patch_grey)
    kernel = np.full((1, 3), 1 / 3, np.float32)  # a short smear sideways
    return cv2.filter2D(image, -1, kernel), (x, y, radius)


def test_a_blurred_ball_with_grey_patches_fails_the_checks_alone() -> None:
    """The premise: patches at 0.5 of the white are not the checks' black (below 0.4 of it)."""
    image, _ = blurred_ball_image(patch_grey=115)
    assert found(image, None) == []


def test_a_blurred_ball_with_grey_patches_is_found_when_the_classifier_is_sure() -> None:
    image, (x, y, radius) = blurred_ball_image(patch_grey=115)
    candidates = found(image, SureModel(4.0))
    assert len(candidates) == 1 and math.hypot(candidates[0].x - x, candidates[0].y - y) <= radius, candidates


@pytest.mark.parametrize("score", [-3.0, 2.0])
def test_a_blurred_ball_with_grey_patches_is_not_reported_when_the_classifier_is_unsure(score: float) -> None:
    """Below ``second_look_min`` (3) the second look reports nothing: the checks' first look would take 0 and up."""
    image, _ = blurred_ball_image(patch_grey=115)
    assert found(image, SureModel(score)) == []


def test_the_second_look_can_be_switched_off() -> None:
    image, _ = blurred_ball_image(patch_grey=115)
    assert found(image, SureModel(4.0), second_look=False) == []


def test_a_grey_blob_without_patches_is_no_ball_even_for_a_sure_classifier() -> None:
    """The looser checks still ask for patches darker than the carpet: a uniform white blob is none."""
    image, _ = blurred_ball_image(patch_grey=230)
    assert found(image, SureModel(4.0)) == []
