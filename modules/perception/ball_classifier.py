"""BallClassifier: decides whether a ball candidate is a ball, from a small, scale-normalised description of it.

The hand-made checks of ``SPLBallDetector`` tell a ball from lines and the carpet; real images hold
things they cannot tell from a ball (robots' black joints among white plastic, the dark feet of a goal
frame on the hall's floor, shoes). The classifier sees the candidate as the teams' networks do: the
grey values of the ball's square, shrunk to ``PATCH`` x ``PATCH`` and divided by its bright value (so
light and colour casts do not matter), the carpet's share in eight sectors round it (a ball lies on
the carpet; things at the field's edge have none above them) and a few colour figures measured
against the carpet. A small neural network decides: small (a few kB, shipped as ``ball_classifier.npz``
beside this file), fast (microseconds per candidate) and trained by
``python -m tafel.tools.simulation.train_ball_classifier`` on simulator renders with ground truth, seen through the
platforms' own camera pipeline and hall (``--realism``), plus real labelled images where given (none by default:
the only ones the project may train on are the real-image benchmark's).
"""

from __future__ import annotations

import math
from pathlib import Path

import cv2
import numpy as np

#: side (px) of the square the candidate's grey values are shrunk to
PATCH = 10
#: sectors of the ring round the candidate whose carpet share is measured (the first one is above it)
SECTORS = 8
#: the model shipped with the package
MODEL_PATH = Path(__file__).with_name("ball_classifier.npz")
FEATURES = PATCH * PATCH + SECTORS + 8


def features(hsv: np.ndarray, green: np.ndarray, x: float, y: float, radius: float, carpet_value: float,
             carpet_saturation: float) -> np.ndarray:
    """The description of the candidate at (x, y) with ``radius`` (px) in an HSV image and its green mask;
    ``carpet_value`` and ``carpet_saturation``: the carpet's median V and S, the measures of light.
    Parts outside the image count as neither green nor ball (they are filled by the image's edge)."""
    height, width = green.shape
    r = max(float(radius), 1.0)
    reach = int(math.ceil(1.8 * r)) + 1
    x0, y0 = int(x) - reach, int(y) - reach
    x1, y1 = int(x) + reach + 1, int(y) + reach + 1
    cx0, cy0, cx1, cy1 = max(0, x0), max(0, y0), min(width, x1), min(height, y1)
    out = np.zeros(FEATURES, np.float32)
    if cx1 <= cx0 or cy1 <= cy0:
        return out
    value = hsv[cy0:cy1, cx0:cx1, 2].astype(np.float32)
    saturation = hsv[cy0:cy1, cx0:cx1, 1].astype(np.float32)
    patch_green = green[cy0:cy1, cx0:cx1]
    yy, xx = np.mgrid[cy0:cy1, cx0:cx1]
    dx, dy = xx - x, yy - y
    d = np.hypot(dx, dy)
    inside = d <= 0.9 * r
    ring = (d >= 1.2 * r) & (d <= 1.8 * r)
    solid = inside & ~patch_green
    ball_values = value[solid] if solid.sum() >= 3 else value[inside] if inside.any() else value.ravel()
    bright = max(float(np.percentile(ball_values, 90)), 1.0)
    # the ball's square (side 2.2 r) shrunk; outside the image: the edge's grey values
    side = 1.1 * r
    corners = np.array([[x - side, y - side], [x + side, y - side], [x - side, y + side]], np.float32)
    target = np.array([[0, 0], [PATCH, 0], [0, PATCH]], np.float32)
    warp = cv2.getAffineTransform(corners, target)
    grey = cv2.warpAffine(cv2.extractChannel(np.ascontiguousarray(hsv), 2), warp, (PATCH, PATCH), flags=cv2.INTER_AREA, borderMode=cv2.BORDER_REPLICATE)
    out[: PATCH * PATCH] = np.clip(grey.astype(np.float32).ravel() / bright, 0.0, 2.0)
    # the carpet's share in each sector of the ring, clockwise from above (image y grows downwards)
    angle = (np.arctan2(dx, -dy) % (2 * math.pi)) / (2 * math.pi) * SECTORS
    sector = np.minimum(angle.astype(int), SECTORS - 1)
    i = PATCH * PATCH
    for s in range(SECTORS):
        here = ring & (sector == s)
        out[i + s] = float(patch_green[here].mean()) if here.any() else 0.0
    i += SECTORS
    carpet_value, carpet_saturation = max(carpet_value, 1.0), max(carpet_saturation, 1.0)
    dark = ball_values < 0.5 * bright
    out[i : i + 8] = [
        float(patch_green[inside].mean()) if inside.any() else 1.0,  # green inside
        float(dark.mean()),  # share of black patches
        float(saturation[inside].mean()) / carpet_saturation if inside.any() else 0.0,  # colour, against the carpet's
        bright / carpet_value,  # the white, against the carpet
        (float(ball_values[dark].mean()) if dark.any() else bright) / carpet_value,  # the black, against the carpet
        float(ball_values.std()) / bright,  # contrast inside
        float(value[ring].mean()) / carpet_value if ring.any() else 0.0,  # the ring's brightness
        ((cx1 - cx0) * (cy1 - cy0)) / float((x1 - x0) * (y1 - y0)),  # share of the square inside the image
    ]
    return out


class BallClassifier:
    """The shipped (or a given) model: ``scores`` > 0 means ball. A small multilayer perceptron (standardised
    features, one hidden layer of ReLUs, a logit out), evaluated with numpy: two matrix products, microseconds
    per candidate. (OpenCV 5 has no ``cv2.ml`` any more, and ``cv2.dnn`` would need the ``onnx`` package
    to write a model; this one needs nothing beyond numpy to train or run.)"""

    def __init__(self, path: Path | str = MODEL_PATH) -> None:
        path = Path(path)
        if not path.is_file():
            raise FileNotFoundError(f"no ball classifier model at {path}: train one with python -m tafel.tools.simulation.train_ball_classifier")
        with np.load(path) as data:
            self.mean, self.scale = data["mean"], data["scale"]
            self.w1, self.b1, self.w2, self.b2 = data["w1"], data["b1"], data["w2"], data["b2"]
        if self.mean.shape != (FEATURES,) or self.w1.shape[0] != FEATURES:
            raise ValueError(f"{path} expects {self.w1.shape[0]} features, this code makes {FEATURES}: retrain it "
                             "(python -m tafel.tools.simulation.train_ball_classifier)")

    def scores(self, rows: np.ndarray) -> np.ndarray:
        """The logit of each row of features (positive: a ball)."""
        rows = np.asarray(rows, np.float32).reshape(-1, FEATURES)
        hidden = np.maximum((rows - self.mean) / self.scale @ self.w1 + self.b1, 0.0)
        return (hidden @ self.w2 + self.b2).ravel()

    def save(self, path: Path | str) -> None:
        """Write the model (an ``.npz``, float16 weights: a few kB)."""
        with Path(path).open("wb") as out:
            np.savez_compressed(out, mean=self.mean, scale=self.scale, w1=self.w1.astype(np.float16), b1=self.b1.astype(np.float16),
                                w2=self.w2.astype(np.float16), b2=self.b2.astype(np.float16))


def train(rows: np.ndarray, labels: np.ndarray, hidden: int = 24, epochs: int = 600, seed: int = 0,
          decay: float = 1e-3) -> BallClassifier:
    """A ``BallClassifier`` fitted to ``rows`` (features) and ``labels`` (1 ball, 0 not) by full-batch Adam on
    the cross entropy, the balls weighted up to the others' total (they are rare), with weight decay;
    seeded, so the same data give the same model."""
    rows = np.asarray(rows, np.float32)
    labels = np.asarray(labels, np.float32)
    if rows.ndim != 2 or rows.shape[1] != FEATURES or len(rows) != len(labels):
        raise ValueError(f"training rows must be N x {FEATURES} with N labels, got {rows.shape} and {labels.shape}")
    if len(np.unique(labels)) != 2:
        raise ValueError("training needs both balls (label 1) and other candidates (label 0)")
    rng = np.random.default_rng(seed)
    model = BallClassifier.__new__(BallClassifier)
    model.mean = rows.mean(axis=0).astype(np.float32)
    model.scale = (rows.std(axis=0) + 1e-3).astype(np.float32)
    x = (rows - model.mean) / model.scale
    positives = max(float(labels.sum()), 1.0)
    weight = np.where(labels == 1, (len(labels) - positives) / positives, 1.0).astype(np.float32)
    weight /= weight.sum()
    params: list[np.ndarray] = [rng.normal(0.0, math.sqrt(2.0 / FEATURES), (FEATURES, hidden)).astype(np.float32), np.zeros(hidden, np.float32),
              rng.normal(0.0, math.sqrt(1.0 / hidden), (hidden, 1)).astype(np.float32), np.zeros(1, np.float32)]
    moments = [np.zeros_like(q) for q in params]
    squares = [np.zeros_like(q) for q in params]
    rate, beta1, beta2 = 0.01, 0.9, 0.999
    for step in range(1, epochs + 1):
        w1, b1, w2, b2 = params
        pre = x @ w1 + b1
        h = np.maximum(pre, 0.0)
        logit = (h @ w2 + b2).ravel()
        error = (1.0 / (1.0 + np.exp(-np.clip(logit, -30, 30))) - labels) * weight  # d(loss)/d(logit)
        g_w2 = h.T @ error[:, None] + decay * w2
        g_b2 = np.array([error.sum()], np.float32)
        back = (error[:, None] @ w2.T) * (pre > 0)
        g_w1 = x.T @ back + decay * w1
        g_b1 = back.sum(axis=0)
        for i, g in enumerate((g_w1, g_b1, g_w2, g_b2)):
            moments[i] = beta1 * moments[i] + (1 - beta1) * g
            squares[i] = beta2 * squares[i] + (1 - beta2) * g * g
            params[i] = params[i] - rate * (moments[i] / (1 - beta1**step)) / (np.sqrt(squares[i] / (1 - beta2**step)) + 1e-8)
    model.w1, model.b1, model.w2, model.b2 = (q.astype(np.float32) for q in params)
    return model
