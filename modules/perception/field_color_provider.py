"""FieldColorProvider: the field's green, estimated from the images rather than fixed, and both images
segmented by it once for every detector."""

from __future__ import annotations

import math
from dataclasses import dataclass

import cv2
import numpy as np

from tafel.core import Module, bounded, provides, requires, uses
from tafel.debug import Plot
from tafel.modules.perception.image_geometry import camera_views
from tafel.representations.motion import CameraMatrixBuffer
from tafel.representations.perception import CameraImageBottom, CameraImageTop, FieldColor, SegmentedImage

#: the most saturation (0..255) a pixel may have and still count as white (lines, posts, the ball)
WHITE_SATURATION_MAX = 70


def below(hsv: np.ndarray, channel: int, threshold: float) -> np.ndarray:
    """``hsv[..., channel] < threshold`` (h x w bool) for an image of uint8 channels, by OpenCV: the channel
    taken out once and thresholded, faster than numpy on the interleaved channel (same pixels)."""
    if hsv.size == 0 or not math.isfinite(threshold):
        return hsv[..., channel] < threshold
    limit = math.ceil(threshold) - 1  # for integers, v < t exactly when v <= ceil(t) - 1
    if limit < 0:
        return np.zeros(hsv.shape[:2], bool)
    if limit >= 255:
        return np.ones(hsv.shape[:2], bool)
    return cv2.threshold(cv2.extractChannel(hsv, channel), limit, 1, cv2.THRESH_BINARY_INV)[1].view(bool)


def white_pixels(hsv: np.ndarray, saturation_max: float, value_min: float) -> np.ndarray:
    """``(hsv[..., 1] <= saturation_max) & (hsv[..., 2] >= value_min)`` (h x w bool) for an image of uint8
    channels, in one pass of OpenCV's inRange (same pixels)."""
    if hsv.size == 0 or not (math.isfinite(saturation_max) and math.isfinite(value_min)):
        return (hsv[..., 1] <= saturation_max) & (hsv[..., 2] >= value_min)
    high, low = math.floor(saturation_max), math.ceil(value_min)  # the bounds as integers, both kept
    if high < 0 or low > 255:
        return np.zeros(hsv.shape[:2], bool)
    mask = cv2.inRange(hsv, (0, 0, max(low, 0)), (255, min(high, 255), 255))
    np.bitwise_and(mask, 1, out=mask)  # 255 -> 1: a bool mask
    return mask.view(bool)


def byte_median(values: np.ndarray) -> float:
    """``np.median`` of uint8 values (the same number), from their histogram instead of a partitioned copy."""
    if len(values) == 0:
        return float(np.median(values))  # nan, with numpy's warning
    return histogram_median(np.bincount(values, minlength=256))


def histogram_median(counts: np.ndarray) -> float:
    """``byte_median`` of the values whose histogram is ``counts`` (how many of each of 0..255; at least one value)."""
    cumulative = np.cumsum(counts)
    count = int(cumulative[-1])
    low, high = np.searchsorted(cumulative, [(count - 1) // 2, count // 2], side="right")
    return (int(low) + int(high)) / 2


def byte_percentile(values: np.ndarray, q: float) -> float:
    """``np.percentile(values, q)`` of uint8 values (the same number: its two neighbouring order statistics
    from the values' histogram, then numpy's linear interpolation between them), without numpy's
    partitioned copy of the values."""
    if len(values) == 0 or not 0 <= q <= 100:
        return float(np.percentile(values, q))  # nan with numpy's warning, or numpy's error
    return histogram_percentile(np.bincount(values, minlength=256), q)


def histogram_percentile(counts: np.ndarray, q: float) -> float:
    """``byte_percentile`` of the values whose histogram is ``counts`` (how many of each of 0..255; at least one value;
    0 <= q <= 100)."""
    cumulative = np.cumsum(counts)
    count = int(cumulative[-1])
    virtual = (count - 1) * (q / 100)  # where the percentile lies among the sorted values
    previous = count - 1 if virtual >= count - 1 else math.floor(virtual)
    gamma = virtual - (-1 if virtual >= count - 1 else previous)  # numpy indexes the last value as -1
    low, high = (float(v) for v in np.searchsorted(cumulative, [previous, min(previous + 1, count - 1)], side="right"))
    difference = high - low
    return low + difference * gamma if gamma < 0.5 else high - difference * (1 - gamma)


def every(image: np.ndarray, step: int) -> np.ndarray:
    """``image[::step, ::step]`` (h x w, or h x w x channels; uint8 or bool) as a contiguous array: the whole blocks of
    ``step`` x ``step`` pixels by OpenCV's nearest-neighbour resize (it takes pixel ``step * i`` for pixel ``i``: the
    same pixels, a fraction of the time numpy takes for the strided copy), the last part-block's row and column by numpy."""
    height, width = image.shape[:2]
    rows, columns = height - height % step, width - width % step  # the whole blocks
    pixels_contiguous = image.ndim in (2, 3) and image.strides[-1] == 1 and (image.ndim == 2 or image.strides[1] == image.shape[2])
    if step <= 1 or not rows or not columns or image.dtype not in (np.uint8, np.bool_) or not pixels_contiguous:
        return np.ascontiguousarray(image[::step, ::step])  # OpenCV takes rows of contiguous pixels only
    core = cv2.resize(image[:rows, :columns].view(np.uint8), (columns // step, rows // step), interpolation=cv2.INTER_NEAREST)
    core = core.reshape(rows // step, columns // step, *image.shape[2:]).view(image.dtype)
    if rows == height and columns == width:
        return core
    out = np.empty((-(-height // step), -(-width // step), *image.shape[2:]), image.dtype)
    out[: rows // step, : columns // step] = core
    out[: rows // step, columns // step :] = image[:rows:step, columns::step]
    out[rows // step :] = image[rows::step, ::step]
    return out


def channel_histogram(image: np.ndarray, channel: int, mask: np.ndarray) -> np.ndarray:
    """How many of ``image``'s pixels (h x w x channels, uint8) where ``mask`` (h x w, bool or uint8: not 0) is set have
    each value 0..255 in ``channel`` (int64): ``np.bincount(image[..., channel][mask != 0], minlength=256)`` without
    gathering them."""
    if not image.size:
        return np.zeros(256, np.int64)
    counts = cv2.calcHist([np.ascontiguousarray(image)], [channel], np.ascontiguousarray(mask).view(np.uint8), [256], [0, 256])
    return counts.ravel().astype(np.int64)  # float32 counts: exact below 2**24 pixels


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
