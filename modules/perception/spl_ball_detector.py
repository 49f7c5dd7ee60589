"""SPLBallDetector: the SPL ball (white with black patches) in both images, as image positions."""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import cv2
import numpy as np

from tafel.core import Module, bounded, provides, requires
from tafel.debug import Canvas, DebugRequest, Stopwatch
from tafel.modules.perception.ball_classifier import BallClassifier, features
from tafel.modules.perception.image_geometry import ImageProjection, camera_views
from tafel.modules.perception.pixel_statistics import (
    below,
    byte_median,
    channel_histogram,
    every,
    histogram_median,
    histogram_percentile,
    white_pixels,
)
from tafel.representations.field import BALL_RADIUS
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

#: px round a candidate of the band search that its checks look at: its thickness (a ball at most 14.5 px, from the
#: distance transform of the pixels within 17 px), its black patches (a square of its thickness) and its centre
#: moved twice by up to a radius (9 px), then its disc (9 px); beyond them, the band's pixels change nothing
EDGE_REACH = 30

#: candidates after ``SPLBallDetector.spots``' tests up to which the greedy choice among them runs as a Python loop
#: (a frame mostly leaves a few dozen; beyond, numpy's calls on arrays cost less than the loop)
FEW_PEAKS = 64
#: every byte's value (int64), to sum bytes from their histogram
BYTE_VALUES = np.arange(256, dtype=np.int64)
#: ``HYPOT[i, j]``: ``np.hypot(j, i)`` (px), for the pixels' distances from a spot on a whole pixel (``distances``)
HYPOT_REACH = 128
HYPOT = np.hypot(np.arange(HYPOT_REACH, dtype=float)[None, :], np.arange(HYPOT_REACH, dtype=float)[:, None])

#: the tests of ``SPLBallDetector.verdict`` whose thresholds the second look loosens: a spot that failed another one
#: (too few pixels, under a post, too much green round it) fails it again with the looser thresholds
LOOSER_TESTS = ("saturation", "dark", "black")


def distances(x0: int, x1: int, y0: int, y1: int, x: float, y: float) -> np.ndarray:
    """The distance (px) of each pixel of columns ``x0:x1`` and rows ``y0:y1`` from (x, y): ``np.hypot`` of the offsets.
    From a whole pixel (the distance transform's peaks mostly are), within ``HYPOT_REACH``, the offsets are whole and
    the distances are looked up in ``HYPOT`` (hypot's value does not depend on the offsets' signs): the same numbers,
    a fraction of the time."""
    if float(x).is_integer() and float(y).is_integer():
        dx0, dx1, dy0, dy1 = x0 - int(x), x1 - int(x), y0 - int(y), y1 - int(y)  # the offsets of the first and after the last
        if max(-dx0, dx1 - 1, -dy0, dy1 - 1) < HYPOT_REACH:
            return HYPOT.take(np.abs(np.arange(dy0, dy1)), axis=0).take(np.abs(np.arange(dx0, dx1)), axis=1)
    return np.hypot(np.arange(x0, x1)[None, :] - x, np.arange(y0, y1)[:, None] - y)


def carpet_sample(hsv: np.ndarray, green: np.ndarray) -> np.ndarray:
    """The carpet's pixels (N x 3, HSV) on every fourth row and column: what the measures of the light use."""
    return hsv[::4, ::4][green[::4, ::4]]


@dataclass
class CarpetLight:
    """The measures of the light from ``carpet_sample``: how many pixels it holds, and their median value and
    saturation (0 where it holds none)."""

    count: int
    value: float
    saturation: float


def carpet_light(hsv: np.ndarray, green: np.ndarray) -> CarpetLight:
    """``carpet_sample``'s count and medians (the same numbers), from the sample's histograms instead of its pixels."""
    sampled, carpet = every(hsv, 4), every(green, 4)
    values, saturations = (channel_histogram(sampled, channel, carpet) for channel in (2, 1))
    count = int(values.sum())
    if not count:
        return CarpetLight(0, 0.0, 0.0)
    return CarpetLight(count, histogram_median(values), histogram_median(saturations))


def ball_ranges(centres: np.ndarray, eye: np.ndarray) -> np.ndarray:
    """mm from the camera at ``eye`` (x, y, z) to balls lying at ``centres`` (N x 2, their centres ``BALL_RADIUS`` up):
    ``np.linalg.norm`` of the offsets (N x 3) along their rows, the same sums of squares in the same order, without
    building the points."""
    dx, dy, dz = centres[:, 0] - eye[0], centres[:, 1] - eye[1], BALL_RADIUS - eye[2]
    return np.sqrt(dx * dx + dy * dy + dz * dz)


def square_inside(spot: Spot, shape: tuple[int, ...]) -> bool:
    """Whether the classifier's square round ``spot`` (1.1 radii either side) lies within an image of ``shape``."""
    height, width = shape[:2]
    side = 1.1 * spot.radius
    return side <= spot.x <= width - side and side <= spot.y <= height - side


def carpet(hsv: np.ndarray, green: np.ndarray, light: CarpetLight | None = None) -> tuple[float, float]:
    """The carpet's median value and saturation (sampled), the measures of the light; (128, 128) without carpet.
    ``light``: ``carpet_light(hsv, green)`` where it is at hand."""
    if light is None:
        light = carpet_light(hsv, green)
    if light.count < 10:
        return 128.0, 128.0
    return light.value, light.saturation


def windows(xs: np.ndarray, ys: np.ndarray, columns: range, rows: range, shape: tuple[int, int], left: int = 0
            ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """For n points: the image columns (n x c) and rows (n x r) of a window round each (offsets ``columns`` from
    ``xs``, ``rows`` from ``ys``, both integers), which of its pixels lie in an image of ``shape`` whose first column
    is image column ``left`` (n x r x c), and the indices (n x r x c) that gather them from it (the nearest inside
    for those outside)."""
    height, width = shape
    cols = xs[:, None] + np.asarray(columns)[None, :]
    rws = ys[:, None] + np.asarray(rows)[None, :]
    inside = ((rws >= 0) & (rws < height))[:, :, None] & ((cols >= left) & (cols < left + width))[:, None, :]
    flat = np.minimum(np.maximum(rws, 0), height - 1)[:, :, None] * width + np.minimum(np.maximum(cols - left, 0), width - 1)[:, None, :]
    return cols, rws, inside, flat


def centroids(mask: np.ndarray, xs: np.ndarray, ys: np.ndarray, radii: np.ndarray, left: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """For each point (xs, ys; px, float): the centroid of ``mask``'s pixels within its radius; the point itself where
    there are none. ``left``: the image column of the mask's first one (xs and the centroids' x are the image's)."""
    if len(xs) == 0:
        return xs, ys
    reach = int(math.ceil(float(radii.max())))
    span = range(-reach, reach + 1)
    cols, rows, inside, flat = windows(np.rint(xs).astype(int), np.rint(ys).astype(int), span, span, mask.shape, left)
    dx, dy = cols - xs[:, None], rows - ys[:, None]
    near = (mask.ravel()[flat] > 0) & inside & ((dx * dx)[:, None, :] + (dy * dy)[:, :, None] <= (radii * radii)[:, None, None])
    count = np.count_nonzero(near, axis=(1, 2))
    some = count > 0
    share = np.maximum(count, 1)
    x = np.where(some, (near.sum(axis=1) * cols).sum(axis=1) / share, xs)
    y = np.where(some, (near.sum(axis=2) * rows).sum(axis=1) / share, ys)
    return x, y


def green_below(green: np.ndarray, xs: np.ndarray, ys: np.ndarray, radii: np.ndarray) -> np.ndarray:
    """For each point (px): the carpet's share of the lower half of the ring 1.2 to 1.7 radii round it (0 where the
    ring lies out of the image): a ball lies on the carpet."""
    if len(xs) == 0:
        return np.zeros(0)
    reach = int(math.ceil(1.7 * float(radii.max()))) + 1
    cols, rows, inside, flat = windows(xs.astype(int), ys.astype(int), range(-reach, reach + 1), range(reach + 1), green.shape)
    d = np.hypot((cols - xs[:, None])[:, None, :], (rows - ys[:, None])[:, :, None])
    ring = (d >= (1.2 * radii)[:, None, None]) & (d <= (1.7 * radii)[:, None, None]) & (rows > ys[:, None])[:, :, None] & inside
    count = np.count_nonzero(ring, axis=(1, 2))
    return np.where(count > 0, np.count_nonzero(green.ravel()[flat] & ring, axis=(1, 2)) / np.maximum(count, 1), 0.0)


def white_halves(value: np.ndarray, xs: np.ndarray, ys: np.ndarray, radii: np.ndarray, left: int = 0) -> np.ndarray:
    """For each point (px): the lesser share of white (at least 0.6 of the brightest) in the left and the right half
    of the disc of its radius in the value image (0 where a half lies out of it): a ball's black patches lie among
    its white, on both sides. ``left``: the image column of the value image's first one (xs are the image's)."""
    if len(xs) == 0:
        return np.zeros(0)
    reach = int(math.ceil(float(radii.max())))
    span = range(-reach, reach + 1)
    cols, rows, inside, flat = windows(np.rint(xs).astype(int), np.rint(ys).astype(int), span, span, value.shape, left)
    dx, dy = cols - xs[:, None], rows - ys[:, None]
    disc = ((dx * dx)[:, None, :] + (dy * dy)[:, :, None] <= (radii**2)[:, None, None]) & inside
    patch = value.ravel()[flat] if value.flags.c_contiguous else np.ascontiguousarray(value).ravel()[flat]
    brightest = np.where(disc, patch, 0).max(axis=(1, 2))
    white = patch >= (0.6 * brightest)[:, None, None]
    shares = []
    for side in (cols < xs[:, None], cols > xs[:, None]):
        half = disc & side[:, None, :]
        count = np.count_nonzero(half, axis=(1, 2))
        shares.append((count > 0, np.count_nonzero(white & half, axis=(1, 2)) / np.maximum(count, 1)))
    (left_seen, left_share), (right_seen, right_share) = shares
    return np.where(left_seen & right_seen, np.minimum(left_share, right_share), 0.0)


@dataclass
class Spot:
    """A place in the image where a ball of the expected size could be (px)."""

    x: float
    y: float
    radius: float
    expected: float
    edge: bool = False
    """found by ``edge_spots`` (the field's edge, where the hall behind is)"""


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
        found: list[BallCandidate] = []
        self.ball_image_percept.candidates = found
        self.examined = []
        if not self.field_color.valid:
            return
        if self.parameters.classifier and self.model is None:
            self.model = BallClassifier()
        for camera, image, projection in camera_views(self.camera_image_top, self.camera_image_bottom, self.camera_matrix_buffer):
            with self.image:
                hsv, green = self.segmented_image.hsv(camera), self.segmented_image.green(camera)
                sampled = carpet_light(hsv, green)  # one sample of the carpet for every measure of the light below
                strict = self.strict_green(hsv, green, sampled)
                boundary = self.field_boundary.rows(camera)
                spots = self.spots(strict, boundary, projection, self.dark_pixels(hsv, green, sampled))
                if self.parameters.edge_search and sampled.count >= 10:
                    spots += self.edge_spots(hsv, strict, boundary, projection, sampled.value, spots)
                white = self.segmented_image.white(camera)
                light: tuple[float, float] | None = None
                for spot in spots:
                    score, under_post, failed = self.verdict(hsv, green, spot, white)
                    if under_post:  # perhaps a ball behind a post, merged with it in the image: look beside it
                        beside = self.beside_post(hsv, green, spot, white)
                        score = self.check(hsv, green, beside, white, beside_post=True)[0] if beside else 0.0
                        spot = beside or spot
                    if score and self.near_edge(spot, green.shape):  # partly out of sight: centred on what is seen of it
                        fitted = self.fit_visible(hsv, green, spot)
                        refitted = self.check(hsv, green, fitted, white)[0] if fitted else 0.0
                        spot, score = (fitted, refitted) if fitted and refitted else (spot, score)
                    self.examined.append((camera, spot, score))
                    if score and self.parameters.classifier:
                        light = light or carpet(hsv, green, sampled)
                        score = self.classify(hsv, green, spot, score, light)
                    elif (not score and failed in LOOSER_TESTS and self.parameters.classifier  # the second look's looser
                          and self.parameters.second_look):  # thresholds decide only where one of theirs failed
                        light = light or carpet(hsv, green, sampled)
                        score = self.second_look(hsv, green, spot, white, light)
                    if self.draw_candidates:
                        self.draw_candidates.canvas(Canvas.image(camera)).circle(spot.x, spot.y, spot.radius, color="blue" if score else "gray")
                    if score:
                        found.append(self.candidate(camera, image, spot, score))
        found.sort(key=lambda c: -c.fill)

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
        score = self.check(hsv, green, spot, white, parameters=self.looser())[0]
        return self.decide(hsv, green, spot, score, light, least=p.second_look_min) if score else 0.0

    def looser(self) -> SPLBallDetector.Parameters:
        """The second look's thresholds: the module's with ``second_*`` for the tests of ``LOOSER_TESTS``."""
        p = self.parameters
        return replace(p, dark_ratio=p.second_dark_ratio, black_contrast=p.second_black_contrast, saturation_max=p.second_saturation_max)

    def dark_pixels(self, hsv: np.ndarray, green: np.ndarray, sampled: CarpetLight | None = None) -> np.ndarray | None:
        """Pixels darker than ``black_contrast`` times the carpet's median value (the ball's black patches
        are); None without carpet to compare with. ``sampled``: ``carpet_light(hsv, green)`` where it is at hand."""
        if sampled is None:
            sampled = carpet_light(hsv, green)
        if sampled.count < 10:
            return None
        return below(hsv, 2, self.parameters.black_contrast * sampled.value)

    def strict_green(self, hsv: np.ndarray, green: np.ndarray, sampled: CarpetLight | None = None) -> np.ndarray:
        """The green mask without the pixels much less saturated than the carpet's median. ``sampled``:
        ``carpet_light(hsv, green)`` where it is at hand."""
        if not green.any():
            return green
        if sampled is None:
            sampled = carpet_light(hsv, green)
        median = sampled.saturation if sampled.count else byte_median(hsv[..., 1][green])
        threshold = self.parameters.strict_saturation * median
        limit = math.ceil(threshold) - 1 if math.isfinite(threshold) else -1  # for bytes, not below t is above ceil(t) - 1
        if hsv.size and 0 <= limit < 255:  # by OpenCV in one pass each, without numpy's negation and its arrays
            saturated = cv2.threshold(cv2.extractChannel(hsv, 1), limit, 1, cv2.THRESH_BINARY)[1]
            return cv2.bitwise_and(np.ascontiguousarray(green).view(np.uint8), saturated).view(bool)
        return green & ~below(hsv, 1, threshold)

    @staticmethod
    def dark_share(dark: np.ndarray, xs: np.ndarray, ys: np.ndarray, radii: np.ndarray) -> np.ndarray:
        """Share of dark pixels in the square of half side ``radii`` round each (x, y), by an integral image (of the
        part of the mask the squares cover: the same counts)."""
        height, width = dark.shape
        x0, x1 = np.minimum(np.maximum((xs - radii).astype(int), 0), width), np.minimum(np.maximum((xs + radii).astype(int) + 1, 0), width)
        y0, y1 = np.minimum(np.maximum((ys - radii).astype(int), 0), height), np.minimum(np.maximum((ys + radii).astype(int) + 1, 0), height)
        area = np.maximum((x1 - x0) * (y1 - y0), 1)
        if not len(area):
            return np.zeros(0)
        left, top = int(x0.min()), int(y0.min())
        part = dark[top : int(y1.max()), left : int(x1.max())]
        integral = cv2.integral(part.view(np.uint8) if part.dtype == np.bool_ else part.astype(np.uint8))
        x0, x1, y0, y1 = x0 - left, x1 - left, y0 - top, y1 - top
        return (integral[y1, x1] - integral[y0, x1] - integral[y1, x0] + integral[y0, x0]) / area

    @staticmethod
    def inside_image(spot: Spot, solid: np.ndarray, negated: bool = False) -> Spot:
        """A spot at the image's edge moved to where the ball's centre is: the peak of a ball cut by the
        edge lies on the edge, and the ball's far side is one expected radius from its centre. ``negated``:
        ``solid`` is the green mask, whose negation is the solid (only the row and column read are negated)."""
        height, width = solid.shape
        x, y, e = int(spot.x), int(spot.y), spot.expected
        if x < e or x > width - 1 - e:
            row = solid[min(max(y, 0), height - 1)]
            row = ~row if negated else row
            step = 1 if x < e else -1
            far = x
            while 0 <= far + step < width and row[far + step]:
                far += step
            spot.x = float(far - step * e)
        if y > height - 1 - e:  # a close ball cut by the image's bottom edge (its top is always in view)
            column = solid[:, min(max(int(spot.x), 0), width - 1)]
            column = ~column if negated else column
            far = min(y, height - 1)
            while far - 1 >= 0 and column[far - 1]:
                far -= 1
            spot.y = float(far + e)
        return spot

    @staticmethod
    def near_edge(spot: Spot, shape: tuple[int, ...]) -> bool:
        """Whether the ball at ``spot`` may reach out of the image (its expected radius and a half)."""
        height, width = shape[:2]
        reach = 1.5 * max(spot.expected, spot.radius)
        return spot.x < reach or spot.x > width - 1 - reach or spot.y < reach or spot.y > height - 1 - reach

    @staticmethod
    def fit_visible(hsv: np.ndarray, green: np.ndarray, spot: Spot, rays: int = 24) -> Spot | None:
        """The spot re-centred on the visible part of the ball's outline, or None if too little of it is seen.
        Near the image's edge the distance transform's peak is off the ball's centre (the edge cuts the ball,
        its shadow or a foot beside it widens the blob): along rays from the spot, the last of the ball's
        bright pixels before the carpet is a point of its outline; rays that leave the image first saw none.
        A circle of the expected radius is fitted to those points (Gauss-Newton, the worst fifth dropped)."""
        height, width = green.shape
        r = max(spot.expected, 1.0)
        angles = np.linspace(0.0, 2 * math.pi, rays, endpoint=False)
        steps = np.arange(0.3 * r, 1.8 * r, 1.0)
        xs = spot.x + np.cos(angles)[:, None] * steps[None, :]
        ys = spot.y + np.sin(angles)[:, None] * steps[None, :]
        seen = (xs >= 0) & (xs <= width - 1) & (ys >= 0) & (ys <= height - 1)
        xi, yi = np.clip(np.round(xs).astype(int), 0, width - 1), np.clip(np.round(ys).astype(int), 0, height - 1)
        inner = (np.hypot(xi - spot.x, yi - spot.y) <= 0.9 * r) & ~green[yi, xi]
        if inner.sum() < 3:
            return None
        bright = float(np.percentile(hsv[yi, xi, 2][inner], 90))
        ball = seen & ~green[yi, xi] & (hsv[yi, xi, 2] >= 0.6 * bright)
        last = np.where(ball.any(axis=1), steps.size - 1 - np.argmax(ball[:, ::-1], axis=1), -1)
        index = np.arange(rays)
        ends = (last >= 0) & (last + 1 < steps.size)
        ends &= seen[index, np.minimum(last + 1, steps.size - 1)]  # the outline is in sight, not cut by the edge
        points = np.column_stack([xs[index, np.maximum(last, 0)], ys[index, np.maximum(last, 0)]])[ends]
        if len(points) < rays // 4:
            return None
        centre = np.array([spot.x, spot.y])
        for keep in (1.0, 0.8):
            for _ in range(10):
                offset = points - centre
                distance = np.maximum(np.linalg.norm(offset, axis=1), 1e-6)
                residual = distance - r
                jacobian = -offset / distance[:, None]
                step = np.linalg.lstsq(jacobian, -residual, rcond=None)[0]
                centre = centre + step
                if np.linalg.norm(step) < 0.05:
                    break
            if keep < 1.0:
                break
            residual = np.abs(np.linalg.norm(points - centre, axis=1) - r)
            points = points[residual <= np.quantile(residual, 0.8)]
        if np.hypot(*(centre - (spot.x, spot.y))) > r:
            return None  # not the spot's ball any more
        return Spot(float(centre[0]), float(centre[1]), r, spot.expected)

    def spots(self, green: np.ndarray, boundary: np.ndarray, projection: ImageProjection, dark: np.ndarray | None = None) -> list[Spot]:
        """Peaks of the non-green field's distance transform whose thickness fits a ball there (and, given
        ``dark``, the pixels darker than the carpet, with black patches near them)."""
        p = self.parameters
        height, width = green.shape
        known = boundary.size == width
        top = max(0, int(boundary.min() - p.above_boundary)) if known else 0  # nothing above the field is looked at
        solid = ~green[top:]
        if known:  # on the field: from the boundary (less above_boundary) down; below its lowest row, every row is
            lowest = boundary - p.above_boundary
            limit = float(lowest.max())
            rows = min(height - top, max(0, math.ceil(limit) - top)) if math.isfinite(limit) else height - top
            solid[:rows] &= np.arange(top, top + rows)[:, None] >= lowest[None, :]
        solid = solid.view(np.uint8)
        if not solid.any():
            return []
        thickness = cv2.distanceTransform(solid, cv2.DIST_L2, 3)
        peaks = (thickness >= p.min_radius) & (thickness >= cv2.dilate(thickness, np.ones((3, 3), np.uint8)))
        index = np.flatnonzero(peaks)  # a third of np.nonzero's time on a 2-D mask, same order
        if len(index) == 0:
            return []
        ys, xs = np.divmod(index, width)
        radii = thickness.ravel()[index]
        ys = ys + top
        if known:  # the centre lies on the field; only the top may reach over its edge
            on_field = ys >= boundary[xs]
            xs, ys, radii = xs[on_field], ys[on_field], radii[on_field]
        if dark is not None and len(xs):  # a ball has black patches: spots without dark pixels near their centre are none
            # (a field without any green leaves the distance transform unbounded: radii beyond the image are none).
            # The cheaper test first: it leaves a fifth of the peaks, whose size is then compared with a ball's there
            reach = np.minimum(np.maximum(radii, 1.0), max(height, width))
            first, last = max(0, int((ys - reach).min())), min(height, int((ys + reach).max()) + 1)  # the rows the squares reach
            patched = self.dark_share(dark[first:last], xs, ys - first, reach) >= p.dark_spot_min
            xs, ys, radii = xs[patched], ys[patched], radii[patched]
        centres, hits = projection.to_ground(xs, ys, BALL_RADIUS)
        distance = ball_ranges(centres, projection.translation)
        expected = np.where(hits, projection.fx * BALL_RADIUS / np.maximum(distance, 1.0), 0.0)
        fits = hits & (radii >= p.size_low * expected) & (radii <= p.size_high * expected + 1.0)
        xs, ys, radii, expected = xs[fits], ys[fits], radii[fits], expected[fits]
        # the spots most like a ball's size first: lines are thinner, robots and the border thicker
        order = np.argsort(np.abs(np.log(np.maximum(radii, 0.5) / np.maximum(expected, 0.5))))
        xs, ys, radii, expected = xs[order], ys[order], radii[order], expected[order]
        # greedily, each spot taken keeps the ones after it that are too close to it out
        if len(xs) > FEW_PEAKS:
            return self.chosen_spots(green, xs, ys, radii, expected)
        # the few peaks a frame mostly leaves as Python numbers: a loop over them is cheaper than numpy's calls on
        # arrays of a few elements (the same arithmetic: x * x is numpy's square of the offsets)
        xl, yl, rl, el = xs.tolist(), ys.tolist(), radii.tolist(), expected.tolist()
        free = [True] * len(xl)
        chosen: list[Spot] = []
        for i in range(len(xl)):
            if len(chosen) >= p.max_spots:
                break
            if not free[i]:
                continue
            r, e = rl[i], el[i]
            spot = Spot(float(xl[i]), float(yl[i]), max(r, 0.5 * (r + e)), e)
            if spot.x < e or spot.x > width - 1 - e or spot.y > height - 1 - e:
                spot = self.inside_image(spot, green, negated=True)  # moved: it may now be a spot chosen already
                if any((spot.x - s.x) ** 2 + (spot.y - s.y) ** 2 <= (s.expected * 1.5) ** 2 for s in chosen):
                    continue
            chosen.append(spot)
            x, y, reach = spot.x, spot.y, (spot.expected * 1.5) ** 2
            for j in range(i + 1, len(xl)):
                if free[j]:
                    dx, dy = xl[j] - x, yl[j] - y
                    free[j] = dx * dx + dy * dy > reach
        return chosen

    def chosen_spots(self, green: np.ndarray, xs: np.ndarray, ys: np.ndarray, radii: np.ndarray, expected: np.ndarray) -> list[Spot]:
        """``spots``' greedy choice over many peaks (each spot taken keeps the ones after it that are too close to it
        out, all at once)."""
        p = self.parameters
        height, width = green.shape
        free = np.ones(len(xs), bool)
        chosen: list[Spot] = []
        start = 0
        while len(chosen) < p.max_spots and start < len(xs):
            start += int(np.argmax(free[start:]))
            if not free[start]:
                break
            x, y, r, e = xs[start], ys[start], radii[start], expected[start]
            start += 1
            spot = Spot(float(x), float(y), float(max(r, 0.5 * (r + e))), float(e))
            if spot.x < e or spot.x > width - 1 - e or spot.y > height - 1 - e:
                spot = self.inside_image(spot, green, negated=True)  # moved: it may now be a spot chosen already
                if any((spot.x - s.x) ** 2 + (spot.y - s.y) ** 2 <= (s.expected * 1.5) ** 2 for s in chosen):
                    continue
            chosen.append(spot)
            free[start:] &= (xs[start:] - spot.x) ** 2 + (ys[start:] - spot.y) ** 2 > (spot.expected * 1.5) ** 2
        return chosen

    def edge_spots(self, hsv: np.ndarray, green: np.ndarray, boundary: np.ndarray, projection: ImageProjection, carpet_value: float,
                   taken: list[Spot]) -> list[Spot]:
        """Far balls on the field's edge: there a ball reaches over the carpet into the hall, whose non-green merges with it
        in ``spots``' distance transform. In a band round the boundary only ball-coloured pixels count (white: brighter
        than the carpet, without colour; black: far darker than it), so the hall's middle greys part the ball from what
        is behind it; peaks of their distance transform whose thickness fits a small ball there, with black pixels
        near, away from the spots ``taken`` already."""
        p = self.parameters
        height, width = green.shape
        if boundary.size != width:
            return []
        columns = np.linspace(0, width - 1, 9).astype(int)  # a ball on the edge would be too large for the band here?
        centres, hits = projection.to_ground(columns, np.minimum(boundary[columns], height - 1), BALL_RADIUS)
        ranges = ball_ranges(centres, projection.translation)
        if not (hits & (projection.fx * BALL_RADIUS / np.maximum(ranges, 1.0) <= p.edge_max_radius)).any():
            return []  # the bottom camera, or the top one looking down: the edge is near, its balls stand out on the green
        top = max(0, int(boundary.min()) - p.edge_above)
        bottom = min(height, int(boundary.max()) + p.edge_below + 1)
        if bottom - top < 3:
            return []
        left, right, bottom = self.edge_window(boundary, projection, bottom)
        rows = np.arange(top, bottom)[:, None]
        band = (rows >= boundary[None, left:right] - p.edge_above) & (rows <= boundary[None, left:right] + p.edge_below)
        box = hsv[top:bottom, left:right]
        value = box[..., 2]
        black = below(box, 2, math.floor(p.edge_black * carpet_value) + 1)  # value <= edge_black * carpet_value
        white = white_pixels(box, p.saturation_max, p.edge_white * carpet_value)
        ballish = cv2.bitwise_and(cv2.morphologyEx(cv2.bitwise_and(cv2.bitwise_or(white.view(np.uint8), black.view(np.uint8)),
                                                                   (~green[top:bottom, left:right]).view(np.uint8)),
                                                   cv2.MORPH_CLOSE, np.ones((3, 3), np.uint8)), band.view(np.uint8))
        if not ballish.any():
            return []
        thickness = cv2.distanceTransform(ballish, cv2.DIST_L2, 3)
        peaks = (thickness >= p.min_radius) & (thickness >= cv2.dilate(thickness, np.ones((3, 3), np.uint8)))
        peaks &= thickness <= np.float64(p.size_high * p.edge_max_radius + 1.0)  # thicker than any ball the band looks for
        index = np.flatnonzero(peaks)
        if len(index) == 0:
            return []
        ys, xs = np.divmod(index, right - left)
        radii = thickness.ravel()[index]
        patched = self.dark_share(black, xs, ys, np.maximum(radii, 1.0)) >= p.dark_spot_min  # the cheaper test first
        xs, ys, radii = xs[patched], ys[patched], radii[patched]
        centres, hits = projection.to_ground(xs + left, ys + top, BALL_RADIUS)
        distance = ball_ranges(centres, projection.translation)
        expected = np.where(hits, projection.fx * BALL_RADIUS / np.maximum(distance, 1.0), 0.0)
        fits = hits & (expected <= p.edge_max_radius) & (radii >= p.size_low * expected) & (radii <= p.size_high * expected + 1.0)
        if not fits.any():
            return []
        xs, ys, radii, expected = xs[fits] + left, ys[fits] + top, radii[fits], expected[fits]
        order = np.argsort(np.abs(np.log(np.maximum(radii, 0.5) / np.maximum(expected, 0.5))))
        best = order[: 10 * p.edge_max_spots]  # the best fitting few: a noisy hall has thousands of peaks
        xs, ys, radii, expected = xs[best].astype(float), ys[best].astype(float), radii[best], expected[best]
        # each one's centre: the peak lies off the centre of a ball this small, the centroid of its pixels round it (twice)
        cx, cy = xs, ys - top
        for _ in range(2):
            cx, cy = centroids(ballish, cx, cy, expected, left)
        cy = cy + top
        on_carpet = green_below(green, cx, cy, expected) >= p.edge_green_below  # not a shoe or a box on the hall's floor
        # white on both sides, not white beside black (a pair of shoes, a white box with a dark one)
        whites = white_halves(value, cx, cy - top, expected, left) >= p.edge_white_halves
        chosen: list[Spot] = []
        for i in np.flatnonzero(on_carpet & whites):  # in their order; the others are never chosen
            x, y, e = float(xs[i]), float(ys[i]), float(expected[i])
            if any((x - s.x) ** 2 + (y - s.y) ** 2 <= (max(s.expected, e) * 1.5) ** 2 for s in (*taken, *chosen)):
                continue
            chosen.append(Spot(float(cx[i]), float(cy[i]), max(float(radii[i]), e), e, edge=True))
            if len(chosen) >= p.edge_max_spots:
                break
        return chosen

    def edge_window(self, boundary: np.ndarray, projection: ImageProjection, bottom: int) -> tuple[int, int, int]:
        """(first column, column after the last, row after the last) of the band (rows down to ``bottom``) round the part
        where a ball would be at most ``edge_max_radius`` px (nearer ones the candidates of the green find), with everything
        that decides about a ball there (``EDGE_REACH`` px round it); the band's whole rows where it is nowhere.
        Down a column a ball grows: in each column the ball's size at the band's top, middle and bottom row tells where
        that part ends (at the highest row where it is too large, or the band's bottom)."""
        p = self.parameters
        width = boundary.size
        xs = np.arange(width)
        levels = (-p.edge_above, (p.edge_below - p.edge_above) // 2, p.edge_below)  # px from the boundary
        rows = np.concatenate([np.minimum(np.maximum(boundary + level, 0), projection.height - 1) for level in levels])
        centres, hits = projection.to_ground(np.tile(xs, len(levels)), rows, BALL_RADIUS)
        offset = centres - projection.translation[:2]
        reach2 = np.einsum("ij,ij->i", offset, offset) + (BALL_RADIUS - projection.translation[2]) ** 2
        small = (hits & (reach2 >= (projection.fx * BALL_RADIUS / p.edge_max_radius) ** 2)).reshape(len(levels), width)
        # the band's top above the horizon: just below the horizon a ball is as small as can be
        small[0] |= ~hits[:width] & hits[-width:]
        seen = small[0] | small[1] | small[2]
        if not seen.any():
            return 0, width, bottom
        ends = rows.reshape(len(levels), width)
        last = np.where(small[1] | small[2] | ~hits[width : 2 * width], ends[2], ends[1])  # the lowest row it may reach
        columns = xs[seen]
        # OpenCV's distance transform rounds a pixel's distance as its place in the row's blocks of 64 lets it: the window
        # keeps the blocks the whole row has (the same distances to the last bit)
        left = max(0, int(columns[0]) - EDGE_REACH) // 64 * 64
        right = min(width, left + -(-(int(columns[-1]) + EDGE_REACH + 1 - left) // 64) * 64)
        if right > width - width % 64:
            right = width
        return left, right, min(bottom, int(last[seen].max()) + EDGE_REACH + 2)

    def check(self, hsv: np.ndarray, green: np.ndarray, spot: Spot, white: float, beside_post: bool = False,
              parameters: Parameters | None = None) -> tuple[float, bool]:
        """(0 if the spot is no ball, else a score in (0, 1]: how well it fits; whether a post rises over
        it). ``white``: the value (V) of the image's brightest non-green pixels. ``beside_post``: the
        spot was moved off a post already (its edge may still be in the way above). ``parameters``: other
        thresholds than the module's (``second_look``)."""
        score, under_post, _ = self.verdict(hsv, green, spot, white, beside_post, parameters)
        return score, under_post

    def verdict(self, hsv: np.ndarray, green: np.ndarray, spot: Spot, white: float, beside_post: bool = False,
                parameters: Parameters | None = None) -> tuple[float, bool, str]:
        """``check``'s (score, under a post) and the test a spot that is no ball failed (``LOOSER_TESTS``: one that the
        second look's thresholds loosen; "" for a ball)."""
        p = parameters or self.parameters
        height, width = green.shape
        r = spot.radius
        reach = int(math.ceil(r * 1.7)) + 1
        x0, x1 = max(0, int(spot.x) - reach), min(width, int(spot.x) + reach + 1)
        y0, y1 = max(0, int(spot.y) - reach), min(height, int(spot.y) + reach + 1)
        d = distances(x0, x1, y0, y1, spot.x, spot.y)
        inside, around = d <= 0.9 * r, (d >= 1.2 * r) & (d <= 1.7 * r)
        n_inside, n_around = np.count_nonzero(inside), np.count_nonzero(around)
        if n_inside < 3 or n_around < 3:
            return 0.0, False, "size"
        patch_green, patch = green[y0:y1, x0:x1], hsv[y0:y1, x0:x1]
        solid = np.greater(inside, patch_green)  # inside & ~patch_green: the ball's own pixels (green ones would count as dark)
        n_solid = np.count_nonzero(solid)
        if n_solid < 3:
            return 0.0, False, "size"
        if not beside_post and self.under_post(hsv, green, spot, white):
            return 0.0, True, "post"
        # the tests one by one, the cheapest first: most spots fail one of the first
        green_inside = (n_inside - n_solid) / n_inside  # the inside's green pixels are those not solid
        green_around = np.count_nonzero(patch_green & around) / n_around
        if green_inside > p.green_inside_max or green_around < p.green_around_min:
            return 0.0, False, "green"
        saturation = int(np.add.reduce(patch[..., 1][inside], dtype=np.int64)) / n_inside  # the mean: an exact sum, divided
        if saturation > p.saturation_max:
            return 0.0, False, "saturation"
        # the own pixels' values by their histogram: the 90th percentile (np.percentile's), and the dark ones (below
        # dark_ratio of it: the bytes below its ceiling) counted and summed from it, not gathered
        counts = np.bincount(patch[..., 2][solid], minlength=256)
        bright = histogram_percentile(counts, 90)
        dark_bytes = min(256, max(0, math.ceil(p.dark_ratio * bright)))
        n_dark = int(np.add.reduce(counts[:dark_bytes]))
        dark = n_dark / n_solid
        if not p.dark_share_min <= dark <= p.dark_share_max:
            return 0.0, False, "dark"
        carpet = patch[..., 2][around & patch_green]
        field_value = byte_median(carpet if carpet.size >= 3 else patch[..., 2][around])
        darkest = int(counts[:dark_bytes] @ BYTE_VALUES[:dark_bytes]) / n_dark if n_dark else math.inf  # the black patches' mean
        if darkest > p.black_contrast * field_value:
            return 0.0, False, "black"
        return float(min(1.0, 0.5 + dark + 0.3 * green_around - green_inside)), False, ""

    def under_post(self, hsv: np.ndarray, green: np.ndarray, spot: Spot, white: float) -> bool:
        """Whether ``post_columns`` flags the spot's own column (only that column measured)."""
        p = self.parameters
        column = int(spot.x)
        x0, x1 = max(0, int(spot.x - 3 * spot.radius)), min(green.shape[1], int(spot.x + 3 * spot.radius) + 1)
        y0, y1 = int(max(0, spot.y - 4 * spot.radius)), int(max(0, spot.y - 1.5 * spot.radius))
        if not x0 <= column < x1 or y1 - y0 < 2:
            return False
        r = max(1, int(spot.radius))
        own = hsv[max(0, int(spot.y) - r) : int(spot.y) + r + 1, max(0, int(spot.x) - r) : int(spot.x) + r + 1, 2]
        white = max(white, float(own.max())) if own.size else white
        above = hsv[y0:y1, column]
        whites = (above[:, 2] >= p.post_white * white) & (above[:, 1] <= p.saturation_max) & ~green[y0:y1, column]
        return bool(np.count_nonzero(whites) / len(whites) >= p.post_share)

    def post_columns(self, hsv: np.ndarray, green: np.ndarray, spot: Spot, white: float) -> tuple[int, np.ndarray]:
        """(first column, flags): for the columns within three radii of the spot, whether something white
        rises above the spot's row there (a goal post, or a robot's leg), judged on the rows 1.5 to 4
        radii above it. White is measured against the brighter of ``white`` and the spot's own white: where the
        image's white is taken too low, the hall's grey behind a far ball would be a post."""
        p = self.parameters
        r = max(1, int(spot.radius))
        own = hsv[max(0, int(spot.y) - r) : int(spot.y) + r + 1, max(0, int(spot.x) - r) : int(spot.x) + r + 1, 2]
        white = max(white, float(own.max())) if own.size else white
        x0, x1 = max(0, int(spot.x - 3 * spot.radius)), min(green.shape[1], int(spot.x + 3 * spot.radius) + 1)
        y0, y1 = int(max(0, spot.y - 4 * spot.radius)), int(max(0, spot.y - 1.5 * spot.radius))
        if y1 - y0 < 2 or x1 <= x0:
            return x0, np.zeros(max(0, x1 - x0), bool)
        above = hsv[y0:y1, x0:x1]
        whites = (above[..., 2] >= p.post_white * white) & (above[..., 1] <= p.saturation_max) & ~green[y0:y1, x0:x1]
        return x0, whites.mean(axis=0) >= p.post_share

    def beside_post(self, hsv: np.ndarray, green: np.ndarray, spot: Spot, white: float) -> Spot | None:
        """Where a ball seen next to a post (partly behind it) has its centre. A post hides a vertical
        strip of it, so the row where the non-green run leaving the post's side is longest is the
        ball's centre row, and that run ends at its far edge, one radius from the centre."""
        first, posts = self.post_columns(hsv, green, spot, white)
        height, width = green.shape
        post = np.nonzero(posts)[0]
        if len(post) == 0:
            return None
        low, high = max(0, int(spot.y - 2 * spot.radius)), min(height, int(spot.y + 2 * spot.radius) + 1)
        if low >= high:
            return None
        solid = ~green[low:high]  # the rows searched
        solid[:, first : first + len(posts)] &= ~posts
        # per row, right of the post then left of it: the non-green run from the post's side outwards
        extents, centres = [], []
        for edge, step in ((first + int(post.max()) + 1, 1), (first + int(post.min()) - 1, -1)):
            if not 0 <= edge < width:
                extents.append(np.zeros(high - low, int))
                centres.append(np.zeros(high - low))
                continue
            run = solid[:, edge::step] if step == 1 else solid[:, edge::-1]
            extent = np.where(run.all(axis=1), run.shape[1], np.argmin(run, axis=1))  # 0 where the edge is green
            extents.append(extent)
            centres.append((edge + step * (extent - 1)) - step * spot.expected)
        extent = np.column_stack(extents).ravel()  # row by row, right before left: the order the first longest is taken in
        usable = (extent > 0) & (extent <= 2 * spot.expected + 2)
        if not usable.any():
            return None
        best = int(np.argmax(np.where(usable, extent, -1)))
        if extent[best] < 0.5 * spot.expected:
            return None
        return Spot(float(np.column_stack(centres).ravel()[best]), float(low + best // 2), spot.expected, spot.expected)

    @staticmethod
    def candidate(camera: str, image: CameraImage, spot: Spot, score: float) -> BallCandidate:
        height, width = np.asarray(image.image).shape[:2]
        return BallCandidate(camera, spot.x, spot.y, spot.radius, score, width, height, image.horizontal_fov, image.vertical_fov,
                             image.time_ns)
