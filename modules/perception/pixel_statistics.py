"""Pixel statistics the perception modules share: thresholds over an HSV image, medians and percentiles of byte
values (from histograms: exact, and without sorting), and subsampled views. Plain functions on numpy arrays."""

from __future__ import annotations

import math

import cv2
import numpy as np


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
