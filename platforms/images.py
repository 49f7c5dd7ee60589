"""Recorded camera images with the camera's pose: folders of PNG/JPEG files and NAO raw YUV422 frames.

What the video platform plays when its source is a folder (or one image), and what
``benchmarks/real_images.py`` reads. The camera's pose of each image comes from, in this order:

1. a JSON file beside the image (same name, ``.json``): HULKs' format (``camera_matrix.camera_to_ground``:
   a rotation quaternion ``[x, y, z, w]`` and a translation in metres, ``field_of_view`` in rad,
   ``position`` "Top"/"Bottom") or Tafel's own (``{"tafel_camera": {"camera", "rotation" 3x3,
   "translation" mm, "horizontal_fov", "vertical_fov"}}``, as ``pose_json`` writes it);
2. PNG text chunks ``pitch``, ``roll`` (the torso's tilt), ``headPitch``, ``headYaw`` (rad), as Nao-Team
   HTWK store them: the camera then sits where a standing NAO's head puts it;
3. the pose given in configuration or on the command line (``CameraPose``: height, pitch, roll, yaw);
4. a standing robot looking straight ahead.

Every result says which of these it used (``PosedImage.pose_source``). Frames (x along the optical axis,
y left, z up) and units (mm, rad) as everywhere in Tafel; the robot frame's origin is on the ground.
"""

from __future__ import annotations

import json
import math
import struct
import zlib
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import cv2
import numpy as np

from tafel.representations.motion import CameraMatrix
from tafel.representations.nao import BOTTOM_CAMERA, HORIZONTAL_FOV, NECK_OFFSET_Z, TOP_CAMERA, VERTICAL_FOV, CameraMount

#: file endings read as images (OpenCV decodes them), and the NAO's raw frames
IMAGE_SUFFIXES = (".png", ".jpg", ".jpeg", ".bmp")
RAW_SUFFIXES = (".yuv", ".yuv422", ".raw")
#: the NAO's cameras deliver YUV422 (YUYV) frames of these sizes; a raw file's size tells which
RAW_SIZES = {640 * 480 * 2: (640, 480), 1280 * 960 * 2: (1280, 960), 320 * 240 * 2: (320, 240)}
#: the torso's height (mm, above the ground) and its x offset from the robot frame's origin in the stand pose
STAND_TORSO_HEIGHT = 312.9
STAND_TORSO_X = 1.3


class ImageSourceError(ValueError):
    """An image or its pose file cannot be read; the message says which file and what would be right."""


@dataclass
class CameraPose:
    """A camera's pose given by hand: ``height`` above the ground (mm), ``pitch`` (rad, positive looks
    down), ``roll`` (rad, a right-handed turn about the optical axis) and ``yaw`` (rad, positive looks left)."""

    height: float
    pitch: float = 0.0
    roll: float = 0.0
    yaw: float = 0.0

    @classmethod
    def parse(cls, text: str) -> CameraPose:
        """``"HEIGHT,PITCH,ROLL,YAW"`` (mm and rad; trailing values may be left out)."""
        try:
            values = [float(v) for v in str(text).split(",")]
        except ValueError:
            values = []
        if not 1 <= len(values) <= 4 or not all(math.isfinite(v) for v in values) or values[0] <= 0:
            raise ImageSourceError(f"camera pose {text!r} is not HEIGHT,PITCH,ROLL,YAW: give the camera's height above the ground "
                                   "in mm (above 0) and its pitch (down positive), roll and yaw in rad, e.g. 500,0.3,0,0")
        return cls(*values)

    def matrix(self) -> CameraMatrix:
        rotation = rotation_z(self.yaw) @ rotation_y(self.pitch) @ rotation_x(self.roll)
        return CameraMatrix(rotation, np.array([0.0, 0.0, self.height]), True)

    def text(self) -> str:
        return f"{self.height:.0f} mm high, pitch {self.pitch:.3f}, roll {self.roll:.3f}, yaw {self.yaw:.3f} rad"


@dataclass
class PosedImage:
    """One recorded image (RGB) with the camera that took it, its pose and field of view, and where the
    pose came from (``json (HULKs)``, ``png text``, ``given``, ``nominal``)."""

    path: Path
    image: np.ndarray
    camera: str
    matrix: CameraMatrix
    horizontal_fov: float
    vertical_fov: float
    pose_source: str


def rotation_x(angle: float) -> np.ndarray:
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])


def rotation_y(angle: float) -> np.ndarray:
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def rotation_z(angle: float) -> np.ndarray:
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def quaternion_matrix(x: float, y: float, z: float, w: float) -> np.ndarray:
    """The rotation of a unit quaternion (normalized first)."""
    n = math.sqrt(x * x + y * y + z * z + w * w)
    if not math.isfinite(n) or n < 1e-9:
        raise ValueError(f"quaternion {[x, y, z, w]} is no rotation: it must have a length above 0")
    x, y, z, w = x / n, y / n, z / n, w / n
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                     [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                     [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])


def standing_camera(camera: str, head_yaw: float = 0.0, head_pitch: float = 0.0, pitch: float = 0.0, roll: float = 0.0) -> CameraMatrix:
    """Where a standing NAO's camera is for these head angles and this torso tilt (rad): torso at its
    stand height, tilted by (roll, pitch), the neck, head yaw, head pitch and the camera's mount."""
    mount: CameraMount = TOP_CAMERA if camera == "top" else BOTTOM_CAMERA
    tilted = rotation_x(roll) @ rotation_y(pitch)
    head = tilted @ rotation_z(head_yaw) @ rotation_y(head_pitch)
    neck = np.array([STAND_TORSO_X, 0.0, STAND_TORSO_HEIGHT]) + tilted @ np.array([0.0, 0.0, NECK_OFFSET_Z])
    return CameraMatrix(head @ rotation_y(mount.tilt), neck + head @ np.asarray(mount.position, float), True)


def png_text(path: Path) -> dict[str, str]:
    """The text chunks (tEXt, zTXt, iTXt) of a PNG file; {} for any other file."""
    data = path.read_bytes()
    if not data.startswith(b"\x89PNG\r\n\x1a\n"):
        return {}
    texts: dict[str, str] = {}
    at = 8
    while at + 8 <= len(data):
        length, kind = struct.unpack(">I4s", data[at : at + 8])
        body = data[at + 8 : at + 8 + length]
        at += 12 + length
        try:
            if kind == b"tEXt":
                key, _, value = body.partition(b"\0")
                texts[key.decode("latin-1")] = value.decode("latin-1")
            elif kind == b"zTXt":
                key, _, rest = body.partition(b"\0")
                texts[key.decode("latin-1")] = zlib.decompress(rest[1:]).decode("latin-1")
            elif kind == b"iTXt":
                key, _, rest = body.partition(b"\0")
                compressed, rest = rest[0], rest[2:]
                _language, _, rest = rest.partition(b"\0")
                _translated, _, value = rest.partition(b"\0")
                texts[key.decode("latin-1")] = (zlib.decompress(value) if compressed else value).decode("utf-8")
        except (ValueError, zlib.error, IndexError):
            continue  # a broken chunk holds no pose; the image itself may still be fine
        if kind == b"IEND":
            break
    return texts


def pose_json(camera: str, matrix: CameraMatrix, horizontal_fov: float, vertical_fov: float) -> dict[str, Any]:
    """Tafel's own pose file's content (what the NAO platform's recordings and ``read_pose_json`` use)."""
    return {"tafel_camera": {"camera": camera, "rotation": np.asarray(matrix.rotation).tolist(),
                             "translation": np.asarray(matrix.translation).tolist(), "horizontal_fov": horizontal_fov,
                             "vertical_fov": vertical_fov}}


def read_pose_json(path: Path) -> tuple[str | None, CameraMatrix, tuple[float, float] | None, str]:
    """(camera or None, matrix, (horizontal, vertical) field of view or None, format) from a pose file."""
    try:
        data = json.loads(path.read_text())
    except (OSError, ValueError) as error:
        raise ImageSourceError(f"{path}: cannot read the camera pose ({error}); it must be JSON in HULKs' format "
                               "(camera_matrix.camera_to_ground) or Tafel's (tafel_camera)") from error
    try:
        if isinstance(data, dict) and "tafel_camera" in data:
            own = data["tafel_camera"]
            rotation = np.asarray(own["rotation"], float).reshape(3, 3)
            translation = np.asarray(own["translation"], float).reshape(3)
            fov = (float(own["horizontal_fov"]), float(own["vertical_fov"])) if "horizontal_fov" in own else None
            camera = own.get("camera")
            matrix, kind = CameraMatrix(rotation, translation, True), "json (Tafel)"
        else:
            hulks = data["camera_matrix"]
            ground = hulks["camera_to_ground"]
            rotation = quaternion_matrix(*(float(v) for v in ground["rotation"]))
            translation = np.asarray(ground["translation"], float).reshape(3) * 1000.0
            fov = tuple(float(v) for v in hulks["field_of_view"]) if "field_of_view" in hulks else None
            position = str(data.get("position", "")).lower()
            camera = position if position in ("top", "bottom") else None
            matrix, kind = CameraMatrix(rotation, translation, True), "json (HULKs)"
    except (KeyError, TypeError, ValueError) as error:
        raise ImageSourceError(f"{path}: no camera pose in it ({error!r} missing or wrong); expected HULKs' "
                               "camera_matrix.camera_to_ground {rotation: [x, y, z, w], translation: [m, m, m]} "
                               "or Tafel's tafel_camera {rotation: 3x3, translation: [mm, mm, mm]}") from error
    if not (np.isfinite(matrix.rotation).all() and np.isfinite(matrix.translation).all()):
        raise ImageSourceError(f"{path}: the camera pose has values that are not finite numbers")
    if camera not in (None, "top", "bottom"):
        raise ImageSourceError(f"{path}: camera {camera!r} is neither top nor bottom")
    return camera, matrix, (fov if fov and all(0 < f < math.pi for f in fov) else None), kind  # type: ignore[return-value]


def camera_of(path: Path) -> str | None:
    """The camera a file name says (HTWK's ``_U``/``_L``, names with ``top``/``bottom``), None if it says none."""
    stem = path.stem.lower()
    if stem.endswith("_u") or "top" in stem or "upper" in stem:
        return "top"
    if stem.endswith("_l") or "bottom" in stem or "lower" in stem:
        return "bottom"
    return None


def read_image(path: Path) -> np.ndarray:
    """An RGB image from an image file or a NAO raw YUV422 (YUYV, full range) frame."""
    if path.suffix.lower() in RAW_SUFFIXES:
        data = np.fromfile(path, np.uint8)
        if data.size not in RAW_SIZES:
            sizes = ", ".join(f"{w}x{h} ({n} bytes)" for n, (w, h) in RAW_SIZES.items())
            raise ImageSourceError(f"{path}: {data.size} bytes is no NAO raw YUV422 frame; expected one of {sizes}")
        width, height = RAW_SIZES[data.size]
        yuyv = data.reshape(height, width, 2)
        u, v = np.repeat(yuyv[:, 0::2, 1], 2, axis=1), np.repeat(yuyv[:, 1::2, 1], 2, axis=1)
        # full-range YUV, as the NAO's cameras deliver it (OpenCV's YUYV conversion assumes video range)
        return cv2.cvtColor(np.dstack([yuyv[..., 0], v, u]), cv2.COLOR_YCrCb2RGB)
    image = cv2.imread(str(path), cv2.IMREAD_COLOR)
    if image is None:
        raise ImageSourceError(f"{path}: OpenCV cannot decode it; images must be PNG, JPEG or BMP, or NAO raw YUV422 frames (.yuv)")
    return cv2.cvtColor(image, cv2.COLOR_BGR2RGB)


def image_files(folder: Path) -> list[Path]:
    """The images and raw frames of a folder, in file-name order."""
    return sorted(p for p in folder.iterdir() if p.is_file() and p.suffix.lower() in IMAGE_SUFFIXES + RAW_SUFFIXES)


def nominal_fov(width: int, height: int) -> tuple[float, float]:
    """The NAO's field of view; for an image whose aspect is not 4:3 the vertical one follows from the width."""
    if abs(width * 3 - height * 4) <= 4:
        return HORIZONTAL_FOV, VERTICAL_FOV
    return HORIZONTAL_FOV, 2 * math.atan(math.tan(HORIZONTAL_FOV / 2) * height / width)


def posed_image(path: Path, given: CameraPose | None = None, camera: str | None = None,
                fov: tuple[float, float] | None = None) -> PosedImage:
    """The image at ``path`` with its camera's pose from the first source that has one (see the module's
    docstring). ``camera`` is the camera unless the pose file says (else the file's name, else top); ``fov`` overrides
    the field of view of images whose pose file gives none."""
    image = read_image(path)
    height, width = image.shape[:2]
    named = camera or camera_of(path) or "top"
    horizontal, vertical = fov or nominal_fov(width, height)
    beside = path.with_suffix(".json")
    if beside.is_file():
        said, matrix, recorded_fov, kind = read_pose_json(beside)
        if recorded_fov:
            horizontal, vertical = recorded_fov
        return PosedImage(path, image, said or named, matrix, horizontal, vertical, kind)
    texts = png_text(path) if path.suffix.lower() == ".png" else {}
    if any(key in texts for key in ("pitch", "roll", "headPitch", "headYaw")):
        try:
            angles = {key: float(texts.get(key, 0.0)) for key in ("pitch", "roll", "headPitch", "headYaw")}
        except ValueError as error:
            raise ImageSourceError(f"{path}: its PNG text chunks pitch, roll, headPitch, headYaw must be numbers (rad): {error}") from error
        matrix = standing_camera(named, angles["headYaw"], angles["headPitch"], angles["pitch"], angles["roll"])
        return PosedImage(path, image, named, matrix, horizontal, vertical, "png text")
    if given is not None:
        return PosedImage(path, image, named, given.matrix(), horizontal, vertical, f"given ({given.text()})")
    return PosedImage(path, image, named, standing_camera(named), horizontal, vertical, "nominal (a standing robot looking ahead)")


def options_pose(options: Mapping[str, Any]) -> CameraPose | None:
    """The pose ``--camera-pose`` or the configuration gives, None without one."""
    text = options.get("camera_pose")
    return CameraPose.parse(text) if text not in (None, "") else None
