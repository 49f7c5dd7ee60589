"""FieldColorProvider: the field's green, estimated from the images rather than fixed, and both images
segmented by it once for every detector."""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np

from tafel.core import Module, bounded, provides, requires, uses
from tafel.debug import Plot
from tafel.modules.perception.image_geometry import camera_views
from tafel.modules.perception.pixel_statistics import (
    byte_median,
    channel_histogram,
    every,
    histogram_median,
    histogram_percentile,
)
from tafel.representations.motion import CameraMatrixBuffer
from tafel.representations.perception import CameraImageBottom, CameraImageTop, FieldColor, SegmentedImage

#: the most saturation (0..255) a pixel may have and still count as white (lines, posts, the ball)
WHITE_SATURATION_MAX = 70


def green_mask(color: FieldColor, hsv: np.ndarray) -> np.ndarray:
    """Which pixels of an HSV image (h x w x 3 uint8) are field green by ``color`` (h x w bool); the hue
    range may wrap round red (OpenCV hue is 0..179)."""
    low, high = color.hue - color.hue_tolerance, color.hue + color.hue_tolerance
    mask = cv2.inRange(hsv, (max(0.0, low), color.saturation_min, color.value_min), (min(179.0, high), 255, 255))
    if low < 0 or high > 179:  # the range wraps round red
        wrapped = (low + 180, 179.0) if low < 0 else (0.0, high - 180)
        mask = cv2.bitwise_or(mask, cv2.inRange(hsv, (wrapped[0], color.saturation_min, color.value_min), (wrapped[1], 255, 255)))
    np.bitwise_and(mask, 1, out=mask)  # 255 -> 1: a bool mask, without a second array
    return mask.view(bool)


@requires(CameraImageTop, CameraImageBottom)
@uses(CameraMatrixBuffer)
@provides(FieldColor, SegmentedImage)
class FieldColorProvider(Module):
    """The most frequent saturated hue among greenish pixels where the field must be: the bottom image, and
    the top image below the horizon (where the camera's pose is known; else its lower half), with a
    tolerance from its spread, smoothed over frames.

    Sampling below the horizon keeps the hall out: a robot that looks up sees walls, doors and boards in
    the top image's lower half, and a teal door filling it outvoted the carpet.

    Light changes move the estimate within a few frames; a frame with too little green (the robot
    looks at a wall, or is lifted) keeps the last estimate.
    """

    camera_image_top: CameraImageTop
    camera_image_bottom: CameraImageBottom
    camera_matrix_buffer: CameraMatrixBuffer
    field_color: FieldColor
    segmented_image: SegmentedImage

    hue = Plot("the field colour's hue, OpenCV 0..180")

    @dataclass
    class Parameters:
        hue_low: int = bounded(0, 180, 25)
        """OpenCV hue: the range a field can be in at all (yellowish to bluish green)"""
        hue_high: int = bounded(0, 180, 95)
        saturation_floor: int = bounded(0, 255, 50)
        """pixels less saturated than this are lines, robots or walls, never field"""
        horizon_margin: float = bounded(0.0, 0.5, 0.05)
        """share of the image height below the horizon where sampling starts (the pose is not exact)"""
        min_share: float = bounded(0.0, 1.0, 0.15)
        """share of the sampled pixels that must be green to update the estimate"""
        smoothing: float = bounded(0.0, 1.0, 0.3)
        """weight of this frame's estimate against the previous one"""
        step: int = bounded(1, 16, 4)
        """px between sampled pixels"""

    parameters: Parameters

    def execute(self) -> None:
        segmented = self.segmented_image
        for camera, image in (("top", self.camera_image_top.image), ("bottom", self.camera_image_bottom.image)):
            pixels = np.asarray(image)
            valid = pixels.ndim == 3 and pixels.shape[2] == 3 and pixels.size > 0
            hsv = cv2.cvtColor(np.ascontiguousarray(pixels), cv2.COLOR_RGB2HSV) if valid else np.zeros((0, 0, 3), np.uint8)
            setattr(segmented, f"{camera}_hsv", hsv)
        self.estimate()
        for camera in ("top", "bottom"):
            hsv = segmented.hsv(camera)
            green = green_mask(self.field_color, hsv) if hsv.size else np.zeros((0, 0), bool)
            setattr(segmented, f"{camera}_green", green)
            # white: the brightest unsaturated pixels off the field (sampled: a percentile of every pixel costs)
            step = self.parameters.step
            sampled = every(hsv, step)
            counts = np.zeros(256, np.int64)
            if sampled.size:  # the values' histogram of the unsaturated pixels off the field, without gathering them
                chosen = cv2.inRange(sampled, (0, 0, 0), (255, WHITE_SATURATION_MAX, 255))  # unsaturated
                chosen[every(green, step)] = 0  # and off the field
                counts = channel_histogram(sampled, 2, chosen)
            setattr(segmented, f"{camera}_white", histogram_percentile(counts, 99) if counts.any() else 255.0)

    def estimate(self) -> None:
        """This frame's field colour from samples of both images, blended into the last estimate."""
        p, out, segmented = self.parameters, self.field_color, self.segmented_image
        top_start = 0.5 * segmented.top_hsv.shape[0]
        for camera, _, projection in camera_views(self.camera_image_top, self.camera_image_bottom, self.camera_matrix_buffer):
            if camera == "top" and (projection.height, projection.width) == segmented.top_hsv.shape[:2]:
                horizon = max(projection.horizon(0.0), projection.horizon(projection.width - 1.0))  # its lower end
                top_start = float(np.clip(horizon + p.horizon_margin * projection.height, 0.0, 0.9 * projection.height))
        samples = [every(hsv[int(start) :], p.step).reshape(-1, 3)
                   for hsv, start in ((segmented.bottom_hsv, 0.0), (segmented.top_hsv, top_start)) if hsv.size]
        if not samples:
            return
        hsv = np.concatenate(samples).reshape(-1, 1, 3)
        chosen = cv2.inRange(hsv, (p.hue_low, p.saturation_floor, 30), (p.hue_high, 255, 255))  # bounds kept
        # the greenish pixels' hues, and below the peak's pixels' saturations and values, counted without gathering them
        counts = channel_histogram(hsv, 0, chosen.view(bool))
        if int(counts.sum()) < p.min_share * len(hsv):
            return
        highest = int(np.flatnonzero(counts)[-1]) if counts.any() else 0
        histogram = counts[: max(180, highest + 1)].astype(float)  # as np.bincount(hues, minlength=180)
        histogram = np.convolve(histogram, np.ones(5) / 5, mode="same")
        peak = float(np.argmax(histogram))
        # the peak is a whole hue: the greenish pixels within 15 of it, in their order (the spread's sum is taken in it)
        near = cv2.inRange(hsv, (max(p.hue_low, peak - 15), p.saturation_floor, 30), (min(p.hue_high, peak + 15), 255, 255)).view(bool)
        hues = hsv[:, 0, 0][near.ravel()]
        tolerance = float(np.clip(3.0 * hues.std() + 4.0, 6.0, 20.0))
        if len(hues):
            saturation_median, value_median = (histogram_median(channel_histogram(hsv, channel, near)) for channel in (1, 2))
        else:
            saturation_median = value_median = byte_median(hues)  # none: numpy's nan
        saturation = float(max(p.saturation_floor, 0.45 * saturation_median))
        value = float(max(25.0, 0.35 * value_median))
        weight = p.smoothing if out.valid else 1.0
        out.hue += weight * (peak - out.hue)
        out.hue_tolerance += weight * (tolerance - out.hue_tolerance)
        out.saturation_min += weight * (saturation - out.saturation_min)
        out.value_min += weight * (value - out.value_min)
        out.valid = True
        self.hue.add(out.hue)
