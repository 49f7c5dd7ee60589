"""SPLBallDetector under what real images showed it (held-out competition frames, README "Real images"): a dark carpet
whose green is as dark as the ball's black, a ball in front of a farther goal post or below a line running away from
the camera, and a blurred ball whose candidate lies off its centre."""

from __future__ import annotations

import math

import cv2
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tafel.core.framework.manager import make_module
from tafel.modules.perception import ball_checks, spl_ball_detector
from tafel.modules.perception.ball_checks import carpet_below_post, fit_visible, green_above
from tafel.modules.perception.ball_spots import Spot
from tafel.modules.perception.spl_ball_detector import SPLBallDetector
from tests.support.painted_balls import SureModel, found, found_at, painted_ball

#: a dark carpet (BGR; value 60) as in a dim hall
DARK_CARPET = (30, 60, 25)


def leg(image: np.ndarray, x: float, y: float, radius: float) -> None:
    """A robot's shin standing on what is painted next (the foot): light grey from the image's top down to it."""
    cv2.rectangle(image, (int(x - 0.7 * radius), 0), (int(x + 0.7 * radius), int(y)), (200, 200, 200), -1)


def farther_post(image: np.ndarray, x: float, y: float, radius: float) -> None:
    """A goal post behind the ball (as wide as the ball: not much farther): white from the image's top down to 1.8
    radii above the ball's centre."""
    cv2.rectangle(image, (int(x - 1.1 * radius), 0), (int(x + 1.1 * radius), int(y - 1.8 * radius)), (235, 235, 235), -1)


def test_a_ball_on_a_dark_carpet_is_found_by_its_white() -> None:
    """Black patches (50) no darker than 0.85 of the carpet (60): its white, nearly four times the carpet, vouches
    for them. The premise: without that (``white_over_dark_carpet`` beyond it) the checks turn the ball down."""
    image, ball = painted_ball(patch_grey=50, white=225, carpet=DARK_CARPET)
    assert found_at(found(image, SureModel(4.0)), ball)
    assert found(image, SureModel(4.0), white_over_dark_carpet=10.0) == []


def test_a_robots_foot_on_a_dark_carpet_is_no_ball_even_for_a_sure_classifier() -> None:
    """The same white with dark patches, a leg rising from it: a ball lies alone, its white vouches for nothing here."""
    image, _ = painted_ball(patch_grey=50, white=225, carpet=DARK_CARPET, behind=leg)
    assert found(image, SureModel(4.0)) == []


def test_the_second_look_does_not_let_a_white_vouch_for_grey_patches() -> None:
    """The second look's grey patches (at most 0.6 of the white) need black darker than the carpet: on a dark carpet
    a white vouches only for black ones, or a robot's toe there would pass."""
    detector: SPLBallDetector = make_module(SPLBallDetector, parameters=SPLBallDetector.Parameters())  # type: ignore[assignment]
    assert detector.looser().white_over_dark_carpet == math.inf
    assert detector.parameters.white_over_dark_carpet == 3.0


def test_a_ball_in_front_of_a_farther_post_is_found(monkeypatch: pytest.MonkeyPatch) -> None:
    """The carpet shows between the ball and the post above it: the ball is no post's foot. The premise: taken for
    one (the carpet between not looked at), it is not found."""
    image, ball = painted_ball(patch_grey=30, behind=farther_post)
    assert found_at(found(image, SureModel(4.0)), ball)
    monkeypatch.setattr(ball_checks, "carpet_below_post", lambda green, spot: False)
    assert not found_at(found(image, SureModel(4.0)), ball)


def column_mask(height: int, width: int, column: int, bottom: int) -> np.ndarray:
    """A green mask with a non-green column three pixels wide round ``column`` from row 0 down to ``bottom``."""
    green = np.ones((height, width), bool)
    green[:bottom, column - 1 : column + 2] = False
    return green


def test_a_post_standing_on_the_spot_leaves_no_carpet_below_it() -> None:
    spot = Spot(50.0, 60.0, 8.0, 8.0)
    assert not carpet_below_post(column_mask(100, 100, 50, 60), spot)  # the post reaches down to the spot: its foot
    assert carpet_below_post(column_mask(100, 100, 50, 45), spot)  # the post ends 15 px (1.9 radii) above it
    assert carpet_below_post(column_mask(100, 100, 20, 60), spot)  # a post to the side: the spot's column is carpet


def test_green_above_measures_only_what_lies_in_the_image() -> None:
    green = np.ones((40, 40), bool)
    assert green_above(green, Spot(20.0, 2.0, 6.0, 6.0), 1.2, 2.0, 0.5) == 0.0  # the rows lie above the image
    assert green_above(green, Spot(20.0, 30.0, 6.0, 6.0), 1.2, 2.0, 0.5) == 1.0
    green[:, 18:23] = False
    share = green_above(green, Spot(20.0, 30.0, 6.0, 6.0), 1.2, 2.0, 0.5)
    assert share == pytest.approx(2 / 7)  # columns 17 to 23: five of the seven not green
    assert green_above(green, Spot(20.0, 30.0, 2.0, 6.0), 1.2, 2.0, 0.5) == share  # the larger of the two radii


def ball_masks(x: float, y: float, radius: float, patches: list[tuple[float, float]] | None = None,
               size: int = 120) -> tuple[np.ndarray, np.ndarray]:
    """(hsv, green) of a white ball centred at (x, y) on a green field, with black patches of 0.3 radii at ``patches``
    (offsets in radii; by default five round the middle)."""
    image = np.zeros((size, size, 3), np.uint8)
    image[:] = (45, 140, 50)
    cv2.circle(image, (round(x), round(y)), round(radius), (230, 230, 230), -1)
    angles = np.linspace(0, 2 * math.pi, 5, endpoint=False)
    for dx, dy in patches if patches is not None else [(0.55 * math.cos(a), 0.55 * math.sin(a)) for a in angles]:
        cv2.circle(image, (round(x + dx * radius), round(y + dy * radius)), max(1, round(0.3 * radius)), (25, 25, 25), -1)
    hsv = cv2.cvtColor(image, cv2.COLOR_RGB2HSV)
    return hsv, (hsv[..., 0] > 30) & (hsv[..., 0] < 90) & (hsv[..., 1] > 60)


@settings(max_examples=60, deadline=None)
@given(st.floats(8.0, 25.0), st.floats(0.0, 2 * math.pi), st.floats(0.0, 0.6))
def test_the_fit_to_the_visible_outline_finds_the_centre_of_a_ball_from_off_its_centre(radius: float, direction: float,
                                                                                        off: float) -> None:
    """From a spot up to 0.6 radii off the centre, the circle fitted to the outline is the ball (within a pixel and a
    half: the outline's pixels are whole)."""
    hsv, green = ball_masks(60.0, 60.0, radius)
    spot = Spot(60.0 + off * radius * math.cos(direction), 60.0 + off * radius * math.sin(direction), radius, radius)
    fitted = fit_visible(hsv, green, spot)
    assert fitted is not None and math.hypot(fitted.x - 60.0, fitted.y - 60.0) <= 1.5, fitted


def test_a_candidate_off_a_balls_centre_is_checked_again_on_its_outline() -> None:
    """``recentred``: a thin spot on the white half of a ball whose patches lie on its other half (as a blurred ball's
    candidate lies off its centre) fails the dark-patch test there; centred on the outline, it passes. A spot on bare
    carpet stays where it was, with nothing found."""
    detector: SPLBallDetector = make_module(SPLBallDetector, parameters=SPLBallDetector.Parameters())  # type: ignore[assignment]
    hsv, green = ball_masks(60.0, 60.0, 14.0, patches=[(-0.6, -0.35), (-0.6, 0.35), (-0.25, 0.0)])
    off = Spot(66.0, 60.0, 8.0, 14.0)
    assert ball_checks.verdict(hsv, green, off, 230.0, detector.parameters) == (0.0, False, "dark")
    spot, score, failed = detector.recentred(hsv, green, off, 230.0, "dark")
    assert score > 0 and failed == "" and math.hypot(spot.x - 60.0, spot.y - 60.0) <= 1.5, (spot, score, failed)
    bare = Spot(15.0, 100.0, 10.0, 10.0)
    assert detector.recentred(hsv, green, bare, 230.0, "size") == (bare, 0.0, "size")


def line_below_post(image: np.ndarray, x: float, y: float, radius: float) -> None:
    """A goal post as wide as the ball ending 1.8 radii above its centre and, right above the ball, a field line that it
    touches (Team-NUST's frames: a ball at the goal-area line in front of the goal)."""
    cv2.rectangle(image, (int(x - 1.1 * radius), 0), (int(x + 1.1 * radius), int(y - 1.8 * radius)), (235, 235, 235), -1)
    cv2.rectangle(image, (0, int(y - 1.3 * radius)), (image.shape[1], int(y - 0.95 * radius)), (225, 225, 225), -1)


def test_a_ball_touching_a_line_below_a_post_is_found_though_its_candidate_lies_between_them(
        monkeypatch: pytest.MonkeyPatch) -> None:
    """The ball and the line make one blob, its peak between them and thinner than the ball (the candidate is forced
    there): the post above reads as rising from it. Centred on the ball's outline, the carpet shows between the ball
    and the post, and the ball is found; without the recentring (the premise), not."""
    image, ball = painted_ball(patch_grey=30, behind=line_below_post)
    x, y, radius = ball
    between = Spot(x, y - 0.5 * radius, 0.6 * radius, radius)
    monkeypatch.setattr(spl_ball_detector, "spots", lambda *args, **kwargs: [between])
    assert found_at(found(image, SureModel(4.0)), ball)
    assert not found_at(found(image, SureModel(4.0), recentre=False), ball)
