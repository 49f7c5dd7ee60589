"""Pixels to the ground and back, through a camera matrix: what every detector needs.

A camera frame has x along the optical axis, y left and z up; images have their origin top-left, x
right and y down (README: coordinate convention). The simulated cameras are pinholes without
distortion, described by the image size and the field of view.
"""

from __future__ import annotations

import math
from collections.abc import Iterator

import cv2
import numpy as np

from tafel.representations.motion import CameraMatrix, CameraMatrixBuffer
from tafel.representations.nao import FOOT_HEIGHT, HIP_OFFSET_Y, SOLE_BACK, SOLE_FRONT, SOLE_OUTSIDE
from tafel.representations.perception import CameraImage


def projectable(horizontal_fov: float, vertical_fov: float) -> bool:
    """Whether both fields of view (rad) describe a pinhole camera: above 0 (0 means not known) and below
    180 degrees. Only then do pixels and rays convert (``focal_lengths``)."""
    return all(math.isfinite(fov) and 0.0 < fov < math.pi for fov in (horizontal_fov, vertical_fov))


def focal_lengths(width: int, height: int, horizontal_fov: float, vertical_fov: float) -> tuple[float, float]:
    """(fx, fy) in px; ``ValueError`` for a field of view that is not ``projectable`` (0 would divide by zero)."""
    if not projectable(horizontal_fov, vertical_fov):
        raise ValueError(f"fields of view of {horizontal_fov!r} and {vertical_fov!r} rad describe no camera: "
                         "each must lie between 0 and pi (check projectable() first)")
    return (width / 2) / math.tan(horizontal_fov / 2), (height / 2) / math.tan(vertical_fov / 2)


def pixel_ray(x: float, y: float, width: int, height: int, horizontal_fov: float, vertical_fov: float) -> np.ndarray:
    """The direction of a pixel in the camera frame (x along the optical axis, y left, z up)."""
    fx, fy = focal_lengths(width, height, horizontal_fov, vertical_fov)
    return np.array([1.0, -(x - width / 2) / fx, -(y - height / 2) / fy])


def ground_point(ray_camera: np.ndarray, rotation: np.ndarray, translation: np.ndarray, height: float) -> np.ndarray | None:
    """Where a camera ray meets the plane ``z = height`` in the robot frame (mm), None above the horizon."""
    direction = np.asarray(rotation) @ ray_camera
    if direction[2] >= -1e-6:
        return None
    scale = (height - translation[2]) / direction[2]
    return np.asarray(translation) + scale * direction


def rows_times(rows: np.ndarray, matrix: np.ndarray, exact: bool) -> np.ndarray:
    """``rows @ matrix``; ``exact``: each row's product as for that row alone (a stack of 1 x n products)."""
    return np.asarray((rows[:, None, :] @ matrix)[:, 0]) if exact else rows @ matrix


class ImageProjection:
    """One camera's matrix and intrinsics, with vectorized conversions between pixels and the ground."""

    def __init__(self, matrix: CameraMatrix, width: int, height: int, horizontal_fov: float, vertical_fov: float) -> None:
        self.rotation = np.asarray(matrix.rotation, dtype=float)
        self.translation = np.asarray(matrix.translation, dtype=float)
        self.width, self.height = width, height
        self.fx, self.fy = focal_lengths(width, height, horizontal_fov, vertical_fov)

    def rays(self, xs: np.ndarray, ys: np.ndarray, exact: bool = False) -> np.ndarray:
        """Directions (N x 3, robot frame, not normalized) of the pixels (xs, ys). ``exact``: each row as a
        call for that pixel alone gives it, to the last bit (numpy's product of many rows at once rounds
        differently; a stack of 1 x 3 products does not)."""
        xs, ys = np.asarray(xs, float), np.asarray(ys, float)
        if xs.shape != ys.shape:
            raise ValueError(f"pixels' columns and rows differ in shape: {xs.shape} and {ys.shape}")
        camera = np.empty((*xs.shape, 3))  # filled in place: np.stack's Python around three small arrays cost more than they
        camera[..., 0] = 1.0
        np.divide(self.width / 2 - xs, self.fx, out=camera[..., 1])  # -(x - w/2) / fx: negation and subtraction round alike
        np.divide(self.height / 2 - ys, self.fy, out=camera[..., 2])
        return rows_times(camera, self.rotation.T, exact)

    def to_ground(self, xs: np.ndarray, ys: np.ndarray, z: float = 0.0, exact: bool = False) -> tuple[np.ndarray, np.ndarray]:
        """The points (N x 2, mm, robot frame) where the pixels' rays meet the plane at height ``z``, and
        which of them do (rays at or above the horizon do not). ``exact``: as for ``rays``."""
        rays = self.rays(xs, ys, exact)
        down = rays[:, 2]
        hits = down < -1e-6
        scale = np.divide(z - self.translation[2], down, out=np.zeros(len(down)), where=hits)  # 0 where a ray misses the plane
        return self.translation[:2] + scale[:, None] * rays[:, :2], hits

    def to_image(self, points: np.ndarray, exact: bool = False) -> tuple[np.ndarray, np.ndarray]:
        """Pixels (N x 2) of robot-frame points (N x 3, mm), and which lie in front of the camera.
        ``exact``: as for ``rays``."""
        local = rows_times(np.asarray(points, float) - self.translation, self.rotation, exact)
        front = local[:, 0] > 1.0
        depth = np.where(front, local[:, 0], 1.0)
        return np.stack([self.width / 2 - self.fx * local[:, 1] / depth, self.height / 2 - self.fy * local[:, 2] / depth], axis=1), front

    def horizon(self, x: float) -> float:
        """The row (px) of the horizon at column ``x`` (can lie outside the image)."""
        # the horizon is where rays are level: z component of R @ (1, u, v) is 0
        u = -(x - self.width / 2) / self.fx
        r = self.rotation[2]
        if abs(r[2]) < 1e-9:
            return -1e9 if r[0] + r[1] * u > 0 else 1e9
        v = -(r[0] + r[1] * u) / r[2]
        return self.height / 2 - v * self.fy


#: where the robot's own body can be in the robot frame (mm), as boxes ((x0, x1), (y0, y1), (z0, z1)): both
#: feet with the walk's reach (steps of 60 mm either way), the legs, and each arm hanging beside the
#: torso as the stand and the walk hold it. A camera sees these parts when it looks down or aside.
FEET_REACH = 60.0
BODY_BOXES = (
    ((-SOLE_BACK - FEET_REACH, SOLE_FRONT + FEET_REACH), (-(HIP_OFFSET_Y + SOLE_OUTSIDE + FEET_REACH), HIP_OFFSET_Y + SOLE_OUTSIDE + FEET_REACH),
     (0.0, FOOT_HEIGHT + 20.0)),
    ((-90.0, 130.0), (-(HIP_OFFSET_Y + 70.0), HIP_OFFSET_Y + 70.0), (0.0, 340.0)),
    ((-130.0, 170.0), (60.0, 240.0), (120.0, 460.0)),
    ((-130.0, 170.0), (-240.0, -60.0), (120.0, 460.0)),
)


def own_body_mask(projection: ImageProjection, shape: tuple[int, int]) -> np.ndarray:
    """Where the robot's own body may show in an image (h x w bool): detectors must not take its feet
    and arms for lines. Boxes round the feet, legs and arms projected into the image (the body
    contour teams use, for the parts of the body a camera can see)."""
    mask = np.zeros(shape, np.uint8)
    paint_own_body(projection, mask)
    return mask.view(bool)


def paint_own_body(projection: ImageProjection, mask: np.ndarray) -> None:
    """Set the pixels of ``own_body_mask`` to 1 in ``mask`` (h x w uint8), among other things drawn there. Every box's
    points projected at once."""
    pixels, front = projection.to_image(BODY_POINTS_ALL)
    for box in BODY_SLICES:
        box_front = front[box]
        if np.count_nonzero(box_front) >= 3:  # the part of the box in front of the camera (a grid of points: boxes reach behind it)
            cv2.fillConvexPoly(mask, cv2.convexHull(np.minimum(np.maximum(pixels[box][box_front], -1e4), 1e4).astype(np.int32)), 1)


#: each box of ``BODY_BOXES`` as a grid of points, so that the part in front of a camera can be projected
BODY_POINTS = [np.array(np.meshgrid(*(np.linspace(low, high, 6) for low, high in box))).reshape(3, -1).T for box in BODY_BOXES]
#: ``BODY_POINTS`` in one array, and each box's part of it
BODY_POINTS_ALL = np.concatenate(BODY_POINTS)
BODY_SLICES = [slice(start, start + len(points)) for start, points in zip(np.cumsum([0, *map(len, BODY_POINTS)]).tolist(), BODY_POINTS)]


#: the last projection worked out per camera, with what it was worked out from (``camera_views``)
_PROJECTIONS: dict[str, tuple[tuple[object, ...], ImageProjection]] = {}


def matrix_source(buffer: CameraMatrixBuffer, camera: str) -> tuple[object, ...]:
    """Everything ``buffer.at(camera, t)`` reads: its count and the filled entries' times and ``camera``'s matrices."""
    count = int(buffer.count)
    rotation, translation = (buffer.top_rotation, buffer.top_translation) if camera == "top" else (buffer.bottom_rotation, buffer.bottom_translation)
    return (count, *(np.asarray(values)[:count].tobytes() for values in (buffer.time_ns, rotation, translation)))


def camera_views(top: CameraImage, bottom: CameraImage, buffer: CameraMatrixBuffer) -> Iterator[tuple[str, CameraImage, ImageProjection]]:
    """(camera, image, projection) for each camera whose image is there and whose matrix at the image's
    time is known: what every detector that works on the ground loops over.

    Six modules ask for the same frame's projections: each camera's is worked out once and kept with everything it
    comes from (the image's size, fields of view and time, and the buffer's entries), and given again while those are
    the same (the same projection: read-only, none of its users changes it)."""
    for camera, image in (("top", top), ("bottom", bottom)):
        pixels = np.asarray(image.image)
        if pixels.ndim != 3 or pixels.size == 0 or not projectable(image.horizontal_fov, image.vertical_fov):
            continue  # no image, or its field of view is not known
        source = (pixels.shape[1], pixels.shape[0], image.horizontal_fov, image.vertical_fov, image.time_ns, *matrix_source(buffer, camera))
        kept = _PROJECTIONS.get(camera)
        if kept is not None and kept[0] == source:
            yield camera, image, kept[1]
            continue
        matrix = buffer.at(camera, image.time_ns)
        if matrix.valid and np.isfinite(matrix.rotation).all() and np.isfinite(matrix.translation).all():
            projection = ImageProjection(matrix, pixels.shape[1], pixels.shape[0], image.horizontal_fov, image.vertical_fov)
            projection.rotation.flags.writeable = projection.translation.flags.writeable = False
            _PROJECTIONS[camera] = (source, projection)
            yield camera, image, projection
