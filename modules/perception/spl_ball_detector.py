"""SPLBallDetector: the SPL ball (white with black patches) in both images, as image positions. How its candidates are
found is ``ball_spots`` (and ``far_ball_spots`` for far balls on the field's edge), how each is checked ``ball_checks``."""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from tafel.core import Module, bounded, provides, requires
from tafel.debug import Canvas, DebugRequest, Stopwatch
from tafel.modules.perception.ball_checks import LOOSER_TESTS, beside_post, check, fit_visible, near_edge, square_inside, verdict
from tafel.modules.perception.ball_classifier import BallClassifier, features
from tafel.modules.perception.ball_spots import Spot, carpet, carpet_light, dark_pixels, spots, strict_green
from tafel.modules.perception.far_ball_spots import edge_spots
from tafel.modules.perception.image_geometry import camera_views
from tafel.representations.motion import CameraMatrixBuffer
from tafel.representations.perception import (
    BallCandidate,
    BallImagePercept,
    CameraImage,
    CameraImageBottom,
    CameraImageTop,
    FieldBoundary,
    FieldColor,
    SegmentedImage,
)

#: the tests after whose failure a candidate is centred on its visible outline and checked again (``recentred``): the
#: dark-patch test (off a blurred ball's centre its patches are faint) and the post's (a ball touching a line above it
#: makes one blob with it, whose peak lies between them, and the line reads as a post rising from it)
RECENTRE_TESTS = ("dark", "post")


@requires(CameraImageTop, CameraImageBottom, SegmentedImage, FieldColor, FieldBoundary, CameraMatrixBuffer)
@provides(BallImagePercept)
class SPLBallDetector(Module):
    """Candidates, then a check of each.

    - Candidates: everything on the field that is not green, thinned by a distance transform. A ball
      is the thickest non-green thing of its size: its peak lies about one ball radius from the
      green, while a line of the same distance is half as thick and a robot far thicker. The size a
      ball would have at each pixel comes from the camera matrix of the image's time.
      The green that hides a ball is the carpet's full green: a white ball in a colour cast or in
      shadow can look faintly green, so pixels much less saturated than the carpet count as not green
      here (``strict_saturation``), or such a ball would be proposed too thin or not at all.
    - Check: a ball is not green inside, is green around most of its edge, has black patches (dark
      pixels among bright ones) and no colour. That tells it from line crossings, penalty marks,
      goal posts (their non-green continues upwards) and robots' feet (no black patches, too large).
      Real light needs the field as the measure: the ball's black patches are darker than the carpet
      around it (``black_contrast``); dark image corners, shadows and the hall's dark floor are
      uniformly dark and have no patches darker than the carpet beside them.
    - Real light (held-out competition frames): a candidate that fails the dark-patch or the post's test is centred on
      its visible outline and checked again (``recentre``: a blurred ball's candidate, or one of a ball touching a line,
      lies off its centre); on a dark carpet a ball's black is no darker than the carpet, and a white far brighter
      than the carpet vouches for it where the ball lies alone (``white_over_dark_carpet``); a ball in front of a
      farther post, with the carpet between them, is no post's foot.
    - Second look: a small ball smeared by the head's turn has grey patches, not black ones, and a cast gives
      its white a little colour; a candidate that fails only so passes looser checks (``second_*``) and is a
      ball if the classifier is sure of it (``second_look_min``).
    """

    camera_image_top: CameraImageTop
    camera_image_bottom: CameraImageBottom
    segmented_image: SegmentedImage
    field_color: FieldColor
    field_boundary: FieldBoundary
    camera_matrix_buffer: CameraMatrixBuffer
    ball_image_percept: BallImagePercept

    draw_candidates = DebugRequest("every ball candidate (grey) and accepted ball (blue) in the images")
    image = Stopwatch("the candidates of one image, found and checked")

    @dataclass
    class Parameters:
        size_low: float = bounded(0.2, 1.0, 0.55)
        """share of the expected radius the thickest point must reach"""
        size_high: float = bounded(1.0, 3.0, 1.5)
        min_radius: float = bounded(0.5, 10.0, 1.5)
        """px: smaller balls are not looked for"""
        max_spots: int = bounded(1, 50, 16)
        """candidates checked per image"""
        green_inside_max: float = bounded(0.0, 1.0, 0.25)
        green_around_min: float = bounded(0.0, 1.0, 0.3)
        dark_share_min: float = bounded(0.0, 1.0, 0.04)
        dark_share_max: float = bounded(0.0, 1.0, 0.6)
        dark_ratio: float = bounded(0.1, 1.0, 0.4)
        """a pixel is dark below this share of the bright pixels' value"""
        saturation_max: float = bounded(0.0, 255.0, 70.0)
        """mean saturation inside: the ball has no colour"""
        above_boundary: float = bounded(0.0, 50.0, 8.0)
        """px above the field boundary still searched: a ball on the border strip reaches over it"""
        post_share: float = bounded(0.0, 1.0, 0.6)
        """share of white pixels right above a spot that makes it the foot of a goal post (white: ``post_white``)"""
        post_white: float = bounded(0.1, 1.0, 0.55)
        """share of the image's brightest value a pixel reaches to count as white for ``post_share`` (posts are shaded)"""
        strict_saturation: float = bounded(0.0, 1.0, 0.75)
        """share of the carpet's median saturation a pixel needs to hide a ball candidate as green"""
        black_contrast: float = bounded(0.1, 1.5, 0.85)
        """the black patches (mean value) must be darker than this share of the carpet's value around"""
        white_over_dark_carpet: float = bounded(1.0, 10.0, 3.0)
        """on a dark carpet a ball's black is no darker than the carpet: a white at least this many times the carpet's
        value around vouches for its patches instead, for a ball lying alone (carpet above it and round twice
        ``green_around_min`` of its edge; shadows and dark corners have no such white, robots' feet a leg above)"""
        dark_spot_min: float = bounded(0.0, 1.0, 0.02)
        """share of dark pixels a candidate needs round its centre (a square of its thickness)"""
        classifier: bool = True
        """the learned classifier (``ball_classifier``) decides the candidates that passed the checks"""
        classifier_min: float = bounded(-5.0, 5.0, 0.0)
        """the classifier's score (a logit) a ball needs (higher: fewer false balls, more missed ones)"""
        classifier_at_edge: bool = False
        """the classifier also decides candidates whose square reaches out of the image"""
        second_look: bool = True
        """a candidate that fails the checks only by faint black patches or a little colour (a small ball blurred by the
        head's turn, in a colour cast) is a ball if it passes looser ones and the classifier is sure (``second_look_min``)"""
        second_dark_ratio: float = bounded(0.1, 1.0, 0.6)
        """the second look's looser check: a pixel is dark below this share of the bright pixels' value"""
        second_black_contrast: float = bounded(0.1, 1.5, 0.85)
        """the second look's looser check: the black patches darker than this share of the carpet's value"""
        second_saturation_max: float = bounded(0.0, 255.0, 90.0)
        """the second look's looser check: the mean saturation inside at most this"""
        second_look_min: float = bounded(-5.0, 10.0, 3.0)
        """the classifier's score (a logit) a candidate that passed only the looser checks needs"""
        recentre: bool = True
        """a candidate that fails the dark-patch or the post's test is centred on its visible outline and checked again
        (``recentred``, ``RECENTRE_TESTS``)"""
        edge_search: bool = True
        """far balls on the field's edge: also look for ball-coloured blobs in a band round the field boundary"""
        edge_above: int = bounded(0, 60, 14)
        """px above the field boundary the band reaches (a far ball lies on the edge and reaches over it)"""
        edge_below: int = bounded(0, 60, 20)
        """px below the field boundary the far-ball band reaches"""
        edge_max_radius: float = bounded(1.0, 30.0, 9.0)
        """px: the band looks only for balls at most this large (nearer ones stand out on the green)"""
        edge_white: float = bounded(0.5, 3.0, 1.1)
        """in the far-ball band, ball white is brighter than this share of the carpet's value"""
        edge_black: float = bounded(0.05, 1.0, 0.5)
        """in the far-ball band, ball black is darker than this share of the carpet's value; between white and black is the hall, which is no ball"""
        edge_max_spots: int = bounded(0, 20, 6)
        """candidates from the band checked per image, beside ``max_spots``"""
        edge_green_below: float = bounded(0.0, 1.0, 0.6)
        """the carpet's share of the lower half of the ring round a candidate from the band (a ball lies on the carpet)"""
        edge_white_halves: float = bounded(0.0, 1.0, 0.3)
        """the share of white a candidate from the band needs in each of its left and right halves"""
        edge_classifier_min: float = bounded(-5.0, 10.0, 3.0)
        """the classifier's score (a logit) a candidate from the band needs (the hall behind holds more that is no ball);
        the band's candidates whose square reaches out of the image are none"""

    parameters: Parameters

    def __init__(self) -> None:
        self.model: BallClassifier | None = None
        self.examined: list[tuple[str, Spot, float]] = []
        """this frame's candidates with their checks' score (0: rejected), for training and debugging"""

    def execute(self) -> None:
        p = self.parameters
        found: list[BallCandidate] = []
        self.ball_image_percept.candidates = found
        self.examined = []
        if not self.field_color.valid:
            return
        if p.classifier and self.model is None:
            self.model = BallClassifier()
        for camera, image, projection in camera_views(self.camera_image_top, self.camera_image_bottom, self.camera_matrix_buffer):
            with self.image:
                hsv, green = self.segmented_image.hsv(camera), self.segmented_image.green(camera)
                sampled = carpet_light(hsv, green)  # one sample of the carpet for every measure of the light below
                strict = strict_green(hsv, green, p, sampled)
                boundary = self.field_boundary.rows(camera)
                candidates = spots(strict, boundary, projection, p, dark_pixels(hsv, green, p, sampled))
                if p.edge_search and sampled.count >= 10:
                    candidates += edge_spots(hsv, strict, boundary, projection, sampled.value, candidates, p)
                white = self.segmented_image.white(camera)
                light: tuple[float, float] | None = None
                for spot in candidates:
                    score, under_post, failed = verdict(hsv, green, spot, white, p)
                    if failed in RECENTRE_TESTS and p.recentre:
                        moved, moved_score, moved_failed = self.recentred(hsv, green, spot, white, failed)
                        if moved is not spot:  # the fitted spot is no post's foot
                            spot, score, failed, under_post = moved, moved_score, moved_failed, False
                    if under_post:  # perhaps a ball behind a post, merged with it in the image: look beside it
                        beside = beside_post(hsv, green, spot, white, p)
                        score = check(hsv, green, beside, white, p, beside_post=True)[0] if beside else 0.0
                        spot = beside or spot
                    if score and near_edge(spot, green.shape):  # partly out of sight: centred on what is seen of it
                        fitted = fit_visible(hsv, green, spot)
                        refitted = check(hsv, green, fitted, white, p)[0] if fitted else 0.0
                        spot, score = (fitted, refitted) if fitted and refitted else (spot, score)
                    self.examined.append((camera, spot, score))
                    if score and p.classifier:
                        light = light or carpet(hsv, green, sampled)
                        score = self.classify(hsv, green, spot, score, light)
                    elif (not score and failed in LOOSER_TESTS and p.classifier  # the second look's looser
                          and p.second_look):  # thresholds decide only where one of theirs failed
                        light = light or carpet(hsv, green, sampled)
                        score = self.second_look(hsv, green, spot, white, light)
                    if self.draw_candidates:
                        self.draw_candidates.canvas(Canvas.image(camera)).circle(spot.x, spot.y, spot.radius, color="blue" if score else "gray")
                    if score:
                        found.append(self.candidate(camera, image, spot, score))
        found.sort(key=lambda c: -c.fill)

    def recentred(self, hsv: np.ndarray, green: np.ndarray, spot: Spot, white: float, failed: str) -> tuple[Spot, float, str]:
        """The spot centred on the visible outline of what it found (``fit_visible``) and checked again: (spot, score, the
        test failed). A blurred ball, or one with its shadow beside it, makes a blob wider than the ball whose
        distance-transform peak lies off its centre, with a thickness below its radius; the square checked there holds
        too little of its faint patches. The fitted spot is kept where it passes or fails only a test the second look
        loosens (``LOOSER_TESTS``); else ``spot`` is returned with 0 and ``failed``, as it is where fitting moves it by
        less than a pixel or finds too little outline."""
        moved = fit_visible(hsv, green, spot)
        if moved is None or math.hypot(moved.x - spot.x, moved.y - spot.y) < 1.0:
            return spot, 0.0, failed
        score, _, again = verdict(hsv, green, moved, white, self.parameters)
        return (moved, score, again) if score or again in LOOSER_TESTS else (spot, 0.0, failed)

    def classify(self, hsv: np.ndarray, green: np.ndarray, spot: Spot, score: float, light: tuple[float, float] | None = None) -> float:
        """``score`` if the classifier takes the spot for a ball, else 0. A ball cut by the image's edge is
        left to the checks: its square reaches out of the image, and the classifier, which learned far
        more edge-cut things that are no ball (dark corners, the hall), turns down the balls there too.
        ``light``: ``carpet(hsv, green)`` where it is at hand."""
        if not square_inside(spot, green.shape):
            return 0.0 if spot.edge else score if not self.parameters.classifier_at_edge else self.decide(hsv, green, spot, score, light)
        return self.decide(hsv, green, spot, score, light)

    def decide(self, hsv: np.ndarray, green: np.ndarray, spot: Spot, score: float, light: tuple[float, float] | None,
               least: float | None = None) -> float:
        """``score`` if the classifier's score reaches ``least`` (by default ``classifier_min``,
        ``edge_classifier_min`` for the band's candidates), else 0."""
        assert self.model is not None
        row = features(hsv, green, spot.x, spot.y, spot.radius, *(light or carpet(hsv, green)))
        if least is None:
            least = self.parameters.edge_classifier_min if spot.edge else self.parameters.classifier_min
        return score if float(self.model.scores(row)[0]) >= least else 0.0

    def second_look(self, hsv: np.ndarray, green: np.ndarray, spot: Spot, white: float, light: tuple[float, float] | None = None) -> float:
        """A score if ``spot``, which failed the checks, passes the looser ones (``second_*``) and the classifier takes
        it for a ball with a score of ``second_look_min`` at least; else 0. A small ball blurred by the head's turn has
        grey, not black, patches, and a colour cast gives its white some colour: the checks alone would take dark
        corners and robots' joints then, the classifier tells them apart. Not at the image's edge, where the
        classifier does not decide."""
        p = self.parameters
        if not square_inside(spot, green.shape):
            return 0.0
        score = check(hsv, green, spot, white, p, parameters=self.looser())[0]
        return self.decide(hsv, green, spot, score, light, least=p.second_look_min) if score else 0.0

    def looser(self) -> SPLBallDetector.Parameters:
        """The second look's thresholds: the module's with ``second_*`` for the tests of ``LOOSER_TESTS``. Its grey
        patches need black darker than the carpet: a white over a dark carpet vouches for black patches only (the
        first look's ``white_over_dark_carpet``), or a robot's toe on a dark carpet would pass."""
        p = self.parameters
        return replace(p, dark_ratio=p.second_dark_ratio, black_contrast=p.second_black_contrast,
                       white_over_dark_carpet=math.inf, saturation_max=p.second_saturation_max)

    @staticmethod
    def candidate(camera: str, image: CameraImage, spot: Spot, score: float) -> BallCandidate:
        height, width = np.asarray(image.image).shape[:2]
        return BallCandidate(camera, spot.x, spot.y, spot.radius, score, width, height, image.horizontal_fov, image.vertical_fov,
                             image.time_ns)
