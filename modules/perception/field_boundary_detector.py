"""FieldBoundaryDetector: where the field ends in each image."""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np

from tafel.core import Module, bounded, provides, requires
from tafel.debug import drawing, request
from tafel.representations.perception import FieldBoundary, FieldColor, SegmentedImage

DRAW = request("FieldBoundaryDetector:draw", "the field boundary in both images")


def lower_hull(xs: np.ndarray, ys: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The largest convex function below the points (image y grows downwards, so: the boundary with the
    dents of goal posts and robots in front of it removed). ``xs`` ascending."""
    hull: list[int] = []
    for i in range(len(xs)):
        while len(hull) >= 2:
            a, b = hull[-2], hull[-1]
            # drop b if it lies above the segment a -> i (then b is a dent, not part of the hull)
            if (ys[b] - ys[a]) * (xs[i] - xs[a]) >= (ys[i] - ys[a]) * (xs[b] - xs[a]):
                hull.pop()
            else:
                break
        hull.append(i)
    return xs[hull], ys[hull]


@requires(SegmentedImage, FieldColor)
@provides(FieldBoundary)
class FieldBoundaryDetector(Module):
    """The green mask shrunk to cells; in each column of cells, the field starts at the highest cell
    below which green dominates; the lower convex hull of those points is the boundary, because the
    field seen from inside is convex, and whatever stands on it only hides parts of its edge."""

    @dataclass
    class Parameters:
        cell: int = bounded(2, 32, 4)
        """px per side of the cells the green mask is averaged over"""
        window: int = bounded(1, 20, 4)
        """cells below a boundary candidate that must be mostly green"""
        green_share: float = bounded(0.1, 1.0, 0.5)

    def execute(self) -> None:
        if not self.field_color.valid:
            return
        for camera in ("top", "bottom"):
            green = self.segmented_image.green(camera)
            if green.size == 0:
                continue
            rows = self.boundary(green)
            setattr(self.field_boundary, camera, rows)
            if DRAW:
                canvas = drawing(f"image:{camera}")
                step = max(1, len(rows) // 16)
                for x in range(0, len(rows) - step, step):
                    canvas.line(x, float(rows[x]), x + step, float(rows[x + step]), color="yellow", width=2)

    def boundary(self, green: np.ndarray) -> np.ndarray:
        """The boundary's row for every column of one image's green mask."""
        p = self.parameters
        height, width = green.shape
        cells = cv2.resize(green.astype(np.float32), (max(1, width // p.cell), max(1, height // p.cell)), interpolation=cv2.INTER_AREA)
        n_rows, n_cols = cells.shape
        # share of green in the window below each cell (the last rows look at what is left)
        padded = np.vstack([cells, np.zeros((p.window, n_cols), np.float32)])
        cumulative = np.vstack([np.zeros((1, n_cols), np.float32), np.cumsum(padded, axis=0)])
        below = (cumulative[p.window : p.window + n_rows] - cumulative[:n_rows]) / np.minimum(p.window, n_rows - np.arange(n_rows))[:, None]
        field = (below >= p.green_share) & (cells >= p.green_share)  # the cell itself is field, and so is what lies below it
        found = field.any(axis=0)
        tops = np.where(found, np.argmax(field, axis=0), n_rows).astype(np.float32) * p.cell
        xs = (np.arange(n_cols) + 0.5) * p.cell
        if not found.any():
            return np.full(width, float(height), np.float32)
        hull_x, hull_y = lower_hull(xs[found], tops[found])
        rows = np.interp(np.arange(width), hull_x, hull_y)
        return np.clip(rows, 0, height).astype(np.float32)
