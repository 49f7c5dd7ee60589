"""The band above the field boundary in which GoalPostDetector finds the posts' edges: each column's colour change
(``edge_profile``) and its peaks (``edge_peaks``), the band's means (``band_means``), and whether the band between a
pair of edges is white and unlike both sides: for all pairs at once from running sums (``band_passes``), for one pair
from the slices (``band_checks``). Sums from integral images, exact integers (``corner_sums``)."""

from __future__ import annotations

import cv2
import numpy as np


def ycrcb(image: np.ndarray, rows: slice, columns: slice = slice(None)) -> np.ndarray:
    """Those rows and columns of the (RGB) image in YCrCb (a pixel's conversion depends on it alone: only the pixels
    looked at are converted, the band's and the posts')."""
    return cv2.cvtColor(np.ascontiguousarray(image[rows, columns]), cv2.COLOR_RGB2YCrCb)


def edge_profile(integral: np.ndarray, low: np.ndarray, high: np.ndarray, step: int = 1) -> np.ndarray:
    """For each column, the strength of a vertical edge in its band (rows ``high`` up to ``low`` of the
    image whose ``cv2.integral`` is ``integral``): the length of the colour change from ``step`` px left
    of it to ``step`` px right of it, averaged over those rows. Averaged before its length is taken, so
    an edge that runs straight up through the band adds up and noise cancels; over a few px, so that the
    soft edge of a shaded round post counts as much as a sharp one."""
    width = integral.shape[1] - 1
    columns = np.arange(step, width - step)
    low, high = low[columns], high[columns]
    # float32 as the running sums this replaced: the integers are exact in it, the length rounds the same
    change = (band_sums(integral, low, high, columns + step) - band_sums(integral, low, high, columns - step)).astype(np.float32)
    profile = np.zeros(width, np.float32)
    profile[columns] = row_norms(change) / np.maximum(low - high, 1)
    return profile


def edge_peaks(profile: np.ndarray, minimum: float) -> np.ndarray:
    """Columns where ``profile`` is at least ``minimum`` and no lower than its neighbours (one per plateau)."""
    padded = np.concatenate([[-np.inf], profile, [-np.inf]])
    peak = (profile >= minimum) & (profile >= padded[:-2]) & (profile > padded[2:])
    return np.nonzero(peak)[0]


def band_means(integral: np.ndarray, low: np.ndarray, high: np.ndarray) -> np.ndarray:
    """For each column, the mean of its pixels in its band (rows ``high`` up to ``low`` of the image whose
    ``cv2.integral`` is ``integral``), channels last where the image has them."""
    width = integral.shape[1] - 1
    count = np.maximum(low - high, 1).reshape((width,) + (1,) * (integral.ndim - 2))
    return np.asarray(band_sums(integral, low, high, np.arange(width)).astype(np.float32) / count)


def band_passes(band_white: np.ndarray, band_colour: np.ndarray, left: np.ndarray, right: np.ndarray, contrast_min: float,
                slack: float) -> tuple[np.ndarray, np.ndarray]:
    """For pairs of edges at columns ``left`` and ``right`` (at least 2 apart, inside the image): which may
    pass the band's checks (white between the edges, unlike both sides: ``band_checks``)
    and which lie within ``slack`` of a threshold there. From running sums, all pairs at once: their
    means may differ from the slices' in the last bits, so only a pair off by more than ``slack`` is sure."""
    width = len(band_white)
    post_width = right - left
    margin, side = post_width // 4, np.maximum(2, post_width // 2)
    first = left + 1 + margin // 2
    stop = np.maximum(left + 2 + margin // 2, right - margin // 2)
    white_prefix = np.concatenate([[0.0], band_white.cumsum()])
    colour_prefix = np.concatenate([np.zeros((1, 3)), band_colour.cumsum(axis=0)])
    inside = window_means(colour_prefix, first, stop)
    white = window_means(white_prefix, first, stop)
    passes, near = white >= 0.6 - slack, white < 0.6 + slack
    for outside_first, outside_stop in ((np.maximum(0, left - side), left), (right + 1, np.minimum(width, right + 1 + side))):
        contrast = row_norms(inside - window_means(colour_prefix, outside_first, outside_stop))
        passes &= contrast >= contrast_min - slack
        near |= contrast < contrast_min + slack
    return passes, near


def band_checks(band_white: np.ndarray, band_colour: np.ndarray, left: int, right: int, contrast_min: float) -> bool:
    """Whether the band above the boundary (each column's share of white ``band_white`` and mean colour
    ``band_colour``) is white between the edges at columns ``left`` and ``right`` and unlike both sides by
    ``contrast_min`` (the slices' means: for the pairs whose running sums lie near a threshold)."""
    post_width = right - left
    side = max(2, post_width // 2)
    margin = post_width // 4
    inner = slice(left + 1 + margin // 2, max(left + 2 + margin // 2, right - margin // 2))
    if band_white[inner].mean() < 0.6:
        return False
    inside = band_colour[inner].mean(axis=0)
    return all(np.linalg.norm(inside - outside.mean(axis=0)) >= contrast_min
               for outside in (band_colour[max(0, left - side) : left], band_colour[right + 1 : right + 1 + side]))


def window_means(prefix: np.ndarray, first: np.ndarray, stop: np.ndarray) -> np.ndarray:
    """The means of ``values[first:stop]`` for each pair of bounds, ``prefix`` being ``values``' running sum
    with a zero in front (up to rounding: for the checks that only let through what may pass)."""
    count = (stop - first).reshape((-1,) + (1,) * (prefix.ndim - 1))
    return np.asarray((prefix[stop] - prefix[first]) / count)


def band_sums(integral: np.ndarray, low: np.ndarray, high: np.ndarray, columns: np.ndarray) -> np.ndarray:
    """For each of ``columns``, the sum of its pixels in the rows ``high`` up to (not with) ``low`` (of the
    image whose ``cv2.integral`` is ``integral``): exact integers, where a cumulative sum down the rows
    costs a pass over every pixel of the band's rows (and numpy's is slow along them)."""
    return corner_sums(integral, high, low, columns, columns + 1)


def corner_sums(integral: np.ndarray, top: np.ndarray, bottom: np.ndarray, left: np.ndarray, right: np.ndarray) -> np.ndarray:
    """The sums of the boxes from rows ``top`` and columns ``left`` up to (not with) ``bottom`` and ``right``
    from the image's ``cv2.integral``: its four corners taken from the flat array (numpy's take is several
    times faster than indexing by rows and columns)."""
    stride = integral.shape[1]
    flat = integral.reshape((-1, *integral.shape[2:]))
    return np.asarray(flat.take(bottom * stride + right, axis=0) - flat.take(top * stride + right, axis=0)
                      - flat.take(bottom * stride + left, axis=0) + flat.take(top * stride + left, axis=0))


def row_norms(vectors: np.ndarray) -> np.ndarray:
    """``np.linalg.norm(vectors, axis=1)`` of real vectors, as numpy computes it (the square root of the
    squares summed along the rows) without its Python around it: called a few dozen times a frame."""
    return np.asarray(np.sqrt(np.add.reduce(vectors * vectors, axis=1)))
