"""FieldBoundaryDetector: where the field ends in each image."""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np

from tafel.core import Module, bounded, provides, requires, uses
from tafel.debug import Canvas, DebugRequest
from tafel.modules.perception.field_color_provider import WHITE_SATURATION_MAX
from tafel.modules.perception.image_geometry import camera_views
from tafel.modules.perception.pixel_statistics import white_pixels
from tafel.representations.motion import CameraMatrixBuffer
from tafel.representations.perception import CameraImageBottom, CameraImageTop, FieldBoundary, FieldColor, SegmentedImage


def lower_hull(xs: np.ndarray, ys: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The largest convex function below the points (image y grows downwards, so: the boundary with the
    dents of goal posts and robots in front of it removed). ``xs`` ascending.

    The chain runs over the vertices of the points' convex hull (OpenCV's, a few of the points): the
    points inside it are never on the lower hull, and for the cells' points (whole px, exact in float32)
    the result is the chain over all points (``tests/test_perception_speed.py``)."""
    if len(xs) > 3:
        points = np.column_stack([xs, ys]).astype(np.float32)
        if np.array_equal(points[:, 0], xs) and np.array_equal(points[:, 1], ys):  # exact in float32: OpenCV's hull is exact
            vertices = np.sort(cv2.convexHull(points, returnPoints=False).ravel())
            return chain(xs[vertices], ys[vertices])
    return chain(xs, ys)


def chain(xs: np.ndarray, ys: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``lower_hull`` by the monotone chain over every point (``xs`` ascending)."""
    hull: list[int] = []
    x, y = xs.tolist(), ys.tolist()  # Python floats: numpy scalars made this loop several times slower
    for i in range(len(x)):
        while len(hull) >= 2:
            a, b = hull[-2], hull[-1]
            # drop b if it lies above the segment a -> i (then b is a dent, not part of the hull)
            if (y[b] - y[a]) * (x[i] - x[a]) >= (y[i] - y[a]) * (x[b] - x[a]):
                hull.pop()
            else:
                break
        hull.append(i)
    return xs[hull], ys[hull]


def highest_field_rows(field: np.ndarray, lines: np.ndarray, max_gap: int) -> np.ndarray:
    """For each column of the cells' ``field`` (rows x columns), the highest field row reached from the
    column's lowest field cell upwards across gaps of at most ``max_gap`` cells (cells on ``lines`` do
    not count as gap); the row count where a column has no field.

    All columns and rows at once: scanning from the bottom, a cell's gap is the number of gap cells
    since the last field cell below it; a column stops at the first cell whose gap is too long."""
    n_rows, n_cols = field.shape
    up = field[::-1]  # row 0 is the image's bottom row
    # int32 (the counts are at most the rows): half the memory numpy's default int64 moves, twice as fast
    step = np.cumsum(~up & ~lines[::-1], axis=0, dtype=np.int32)  # gap cells from the bottom up to each cell
    rows = np.arange(n_rows, dtype=np.int32)[:, None]
    last_field = np.maximum.accumulate(np.where(up, rows, np.int32(-1)), axis=0)  # the last field cell at or below
    started = last_field >= 0
    gap = step - np.take_along_axis(step, np.maximum(last_field, 0), axis=0)
    alive = ~np.logical_or.accumulate(started & (gap > max_gap), axis=0)
    reached = (alive & up)[::-1]  # back to image rows: the first reached row from the top is the highest
    return np.where(reached.any(axis=0), np.argmax(reached, axis=0), n_rows)


def local_medians(tops: np.ndarray, found: np.ndarray, reach: int) -> np.ndarray:
    """For each found column, the median of the found columns' ``tops`` within ``reach`` columns of it.
    One window per column over the tops with NaN where none was found, sorted at once (NaN last), and
    the middle of each window's found tops taken (a median per column in Python, and then np.nanmedian,
    took most of the detector's time)."""
    n_cols = len(tops)
    padded = np.full(n_cols + 2 * reach, np.nan, np.float32)
    padded[reach : reach + n_cols][found] = tops[found]
    columns = np.nonzero(found)[0]
    ordered = np.sort(np.lib.stride_tricks.sliding_window_view(padded, 2 * reach + 1)[columns], axis=1)
    counted = np.concatenate([[0], np.cumsum(~np.isnan(padded))])
    counts = counted[columns + 2 * reach + 1] - counted[columns]  # found columns in each window (at least the column itself)
    rows = np.arange(len(columns))
    return (ordered[rows, (counts - 1) // 2] + ordered[rows, counts // 2]) / np.float32(2)


def cell_shares(mask: np.ndarray, cell: int) -> np.ndarray:
    """The share of each ``cell`` x ``cell`` square of a mask that is set (float32), as
    ``cv2.resize(mask.astype(np.float32), ..., interpolation=cv2.INTER_AREA)`` gives it: where the cells
    tile the mask and hold a power of two pixels, from each cell's count (the same values, a fraction of
    the time: OpenCV's area resize of the bytes, each set pixel weighing the cell's area, or the mask's
    integral image); else by that resize."""
    height, width = mask.shape
    n_rows, n_cols = max(1, height // cell), max(1, width // cell)
    area = cell * cell
    if height % cell or width % cell or area & (area - 1):
        return cv2.resize(mask.astype(np.float32), (n_cols, n_rows), interpolation=cv2.INTER_AREA)
    if mask.dtype == np.bool_ and area <= 255:  # each pixel weighs the cell's area: OpenCV's area mean of the bytes is the count
        counts = cv2.resize(mask.view(np.uint8) * np.uint8(area), (n_cols, n_rows), interpolation=cv2.INTER_AREA)
        return counts.astype(np.float32) * (np.float32(1) / np.float32(area))
    corners = cv2.integral(mask.view(np.uint8) if mask.dtype == np.bool_ else mask.astype(np.uint8))[::cell, ::cell]
    counts = corners[1:, 1:] - corners[:-1, 1:] - corners[1:, :-1] + corners[:-1, :-1]
    return counts.astype(np.float32) * (np.float32(1) / np.float32(area))


@requires(SegmentedImage, FieldColor)
@uses(CameraImageTop, CameraImageBottom, CameraMatrixBuffer)
@provides(FieldBoundary)
class FieldBoundaryDetector(Module):
    """The green mask shrunk to cells; each column of cells is followed upwards from its lowest field
    cell, over gaps (lines, the ball, feet) no longer than ``max_gap``, to where the field ends; the
    lower convex hull of those points is the boundary, because the field seen from inside is convex,
    and whatever stands on it only hides parts of its edge.

    Real halls hold green too (doors, boards, cases, a robot's teal-lit parts): such green above the
    field's edge is cut off from the carpet by the hall's floor, so the scan from below never reaches
    it, and where the camera's pose is known nothing above the horizon can be field at all. One such
    point above the edge would otherwise pull the whole hull up."""

    segmented_image: SegmentedImage
    field_color: FieldColor
    camera_image_top: CameraImageTop
    camera_image_bottom: CameraImageBottom
    camera_matrix_buffer: CameraMatrixBuffer
    field_boundary: FieldBoundary

    draw = DebugRequest("the field boundary in both images")

    @dataclass
    class Parameters:
        cell: int = bounded(2, 32, 4)
        """px per side of the cells the green mask is averaged over"""
        window: int = bounded(1, 20, 4)
        """cells below a boundary candidate that must be mostly green"""
        green_share: float = bounded(0.1, 1.0, 0.5)
        max_gap: float = bounded(0.0, 0.5, 0.05)
        """the longest stretch of a column without field that the scan upwards crosses (share of the image height)"""
        outlier_window: float = bounded(0.01, 1.0, 0.2)
        """share of the columns on either side whose median a column's field edge is compared with"""
        outlier_rise: float = bounded(0.0, 1.0, 0.04)
        """share of the image height a column's field edge may rise above the median of its ``outlier_window``"""
        white_value: float = bounded(0.1, 1.0, 0.6)
        """white (a line the scan crosses): unsaturated and at least this share of the image's brightest value"""
        horizon_margin: float = bounded(0.0, 0.5, 0.03)
        """share of the image height above the horizon that may still be field (the camera's pose is not exact)"""

    parameters: Parameters

    def execute(self) -> None:
        if not self.field_color.valid:
            return
        horizons = {camera: projection for camera, _, projection in
                    camera_views(self.camera_image_top, self.camera_image_bottom, self.camera_matrix_buffer)}
        p = self.parameters
        for camera in ("top", "bottom"):
            green = self.segmented_image.green(camera)
            if green.size == 0:
                continue
            projection = horizons.get(camera)
            horizon = None
            if projection is not None and (projection.width, projection.height) == (green.shape[1], green.shape[0]):
                # the horizon is a straight line in the image: its rows at both edges give every column's
                horizon = np.linspace(projection.horizon(0.0), projection.horizon(green.shape[1] - 1.0), green.shape[1]).astype(np.float32)
            hsv = self.segmented_image.hsv(camera)
            white = white_pixels(hsv, WHITE_SATURATION_MAX, p.white_value * self.segmented_image.white(camera))
            rows = self.boundary(green, horizon, white)
            setattr(self.field_boundary, camera, rows)
            if self.draw:
                canvas = self.draw.canvas(Canvas.image(camera))
                step = max(1, len(rows) // 16)
                for x in range(0, len(rows) - step, step):
                    canvas.line(x, float(rows[x]), x + step, float(rows[x + step]), color="yellow", width=2)

    def boundary(self, green: np.ndarray, horizon: np.ndarray | None = None, white: np.ndarray | None = None) -> np.ndarray:
        """The boundary's row for every column of one image's green mask; ``horizon``: the horizon's row
        in every column, where the camera's pose is known; ``white``: the white pixels (lines, which the
        scan upwards crosses however wide they look)."""
        p = self.parameters
        height, width = green.shape
        cells = cell_shares(green, p.cell)
        n_rows, n_cols = cells.shape
        # share of green in the window below each cell (the last rows look at what is left)
        padded = np.vstack([cells, np.zeros((p.window, n_cols), np.float32)])
        cumulative = np.vstack([np.zeros((1, n_cols), np.float32), np.cumsum(padded, axis=0)])
        below = (cumulative[p.window : p.window + n_rows] - cumulative[:n_rows]) / np.minimum(p.window, n_rows - np.arange(n_rows))[:, None]
        field = (below >= p.green_share) & (cells >= p.green_share)  # the cell itself is field, and so is what lies below it
        if horizon is not None:  # nothing above the horizon is field
            xs_cells = np.minimum(((np.arange(n_cols) + 0.5) * p.cell).astype(int), width - 1)
            lowest = (horizon[xs_cells] - p.horizon_margin * height) / p.cell
            field &= np.arange(n_rows)[:, None] >= lowest[None, :]
        # from each column's lowest field cell upwards, across gaps of at most max_gap
        max_gap = int(round(p.max_gap * height / p.cell))
        lines = np.zeros_like(field)
        if white is not None and white.shape == green.shape:
            lines = cell_shares(white, p.cell) >= p.green_share
        top = highest_field_rows(field, lines, max_gap)
        found = top < n_rows
        tops = top.astype(np.float32) * p.cell
        if found.sum() >= 3:  # outliers: far above the median of the columns around them (green in the hall)
            reach = max(1, int(p.outlier_window * n_cols))
            indices = np.nonzero(found)[0]
            local = local_medians(tops, found, reach)
            found[indices[tops[indices] < local - p.outlier_rise * height]] = False
        xs = (np.arange(n_cols) + 0.5) * p.cell
        if not found.any():
            return np.full(width, float(height), np.float32)
        hull_x, hull_y = lower_hull(xs[found], tops[found])
        rows = np.interp(np.arange(width), hull_x, hull_y)
        return np.clip(rows, 0, height).astype(np.float32)
