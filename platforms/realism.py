"""What a real NAO camera makes of a scene: the simulators' ``--realism LEVEL`` (off, mild, full).

A rendered image is perfect: the same exposure and white balance always, no noise, no blur, full
colour resolution. ``CameraRealism`` turns it into what the robot's camera would deliver, in the order
light takes: motion blur (the camera turns while the shutter is open), vignetting, exposure and
contrast, white balance and a colour cast, sensor noise (dark noise and photon noise), the NAO's YUV422
(chroma at half the horizontal resolution), then JPEG artefacts. What varies from run to run
(exposure, white balance, cast, vignetting, noise level, shutter time, JPEG quality) is drawn once per
run and camera from the seed; the noise and a little exposure flicker are drawn every frame. Same seed,
same frames: same images.

The levels' ranges are data: ``config/realism.toml``. ``RealismLevel`` also says what the scene gets
(hall clutter, visible goal nets, shadows, carpet greens); the engines build that (``field_world``).
"""

from __future__ import annotations

import math
import tomllib
import typing
from dataclasses import dataclass
from functools import cache
from pathlib import Path
from typing import Annotated

import cv2
import numpy as np

from tafel.core.framework.naming import did_you_mean
from tafel.core.framework.values import Range, convert
from tafel.core.runtime.platform import PlatformOptionError

#: the levels ``--realism`` takes; ``off`` is the plain render (the default of ``tafel run``)
LEVELS = ("off", "mild", "full")
#: the levels' settings (shipped in the package with the configuration)
REALISM_FILE = Path(__file__).resolve().parent.parent / "config" / "realism.toml"
#: the camera's index in the seed, so that both cameras of one run differ
CAMERA_INDEX = {"top": 0, "bottom": 1}
#: the longest blur (px) at 640 pixels width: a faster turn smears no further (the kernel stays small)
MAX_BLUR_PX = 48.0
#: the most box blurs a slanted blur is made of
BLUR_PIECES = 8
#: px of spare noise round the image: each frame takes its noise from a random place in one seeded field
NOISE_MARGIN = 32

Positive = Annotated[float, Range(0.0, 100.0)]
Share = Annotated[float, Range(0.0, 1.0)]
Grey = Annotated[float, Range(-255.0, 255.0)]
Quality = Annotated[int, Range(0, 100)]


@dataclass(frozen=True)
class RealismLevel:
    """One level of ``config/realism.toml``: [low, high] ranges drawn per run, the rest per frame or fixed."""

    exposure_gain: tuple[Positive, Positive]
    exposure_flicker: Share
    white_balance: tuple[Positive, Positive]
    colour_cast: tuple[Grey, Grey]
    contrast: tuple[Share, Share]
    vignetting: tuple[Share, Share]
    noise_sigma: tuple[Positive, Positive]
    shot_noise: Positive
    exposure_ms: tuple[Positive, Positive]
    chroma_subsampling: bool
    jpeg_quality: tuple[Quality, Quality]
    posed_head_speed: tuple[Positive, Positive]
    hall_clutter: bool
    goal_nets: bool
    shadows: bool
    carpet_greens: list[tuple[Share, Share, Share]]
    carpet_texture: Share


def parse_realism(value: object) -> str:
    """``--realism``: off, mild or full (None: off)."""
    return convert(value if value is not None else "off", str, where="--realism", choices=LEVELS, error=PlatformOptionError,
                   expected=f"one of {', '.join(LEVELS)} (off: the plain render; mild: a well-lit hall and a good camera; "
                            "full: the spread of real NAO images)").lower()


@cache
def realism_level(name: str, path: Path = REALISM_FILE) -> RealismLevel | None:
    """The settings of level ``name`` (None for off), checked against ``RealismLevel``."""
    name = parse_realism(name)
    if name == "off":
        return None
    with path.open("rb") as handle:
        levels = tomllib.load(handle)
    if name not in levels:
        raise PlatformOptionError(f"{path} has no [{name}] table; it needs one for each of {', '.join(LEVELS[1:])}")
    table = levels[name]
    hints = typing.get_type_hints(RealismLevel, include_extras=True)
    for key in table:
        if key not in hints:
            raise PlatformOptionError(f"{path.name} [{name}] has no key {key!r}; {did_you_mean(key, list(hints))}")
    missing = [key for key in hints if key not in table]
    if missing:
        raise PlatformOptionError(f"{path.name} [{name}] needs {', '.join(missing)} (see the [full] table for their meaning)")
    level = RealismLevel(**{key: convert(table[key], kind, where=f"{path.name} [{name}] {key}", error=PlatformOptionError)
                            for key, kind in hints.items()})
    for field_name in ("exposure_gain", "white_balance", "colour_cast", "contrast", "vignetting", "noise_sigma", "exposure_ms",
                       "jpeg_quality", "posed_head_speed"):
        low, high = getattr(level, field_name)
        if low > high:
            raise PlatformOptionError(f"{path.name} [{name}] {field_name} takes [low, high] with low <= high, got [{low}, {high}]")
    if not level.carpet_greens:
        raise PlatformOptionError(f"{path.name} [{name}] carpet_greens takes at least one [r, g, b] colour (0 to 1)")
    return level


# ------------------------------------------------------------------------------------------ steps
def motion_blur(image: np.ndarray, shift: tuple[float, float]) -> np.ndarray:
    """``image`` smeared along ``shift`` (dx, dy in px: how far the scene moved in the image while the
    shutter was open); a shift under half a pixel leaves it as it is.

    The line is a staircase of up to ``BLUR_PIECES`` box blurs along the major axis, each shifted along
    the minor one: a few cheap passes where a 2-D kernel of the line would take ten times as long."""
    dx, dy = shift
    length = math.hypot(dx, dy)
    limit = MAX_BLUR_PX * image.shape[1] / 640.0
    if length > limit:
        dx, dy, length = dx * limit / length, dy * limit / length, limit
    if length < 0.5:
        return image
    horizontal = abs(dx) >= abs(dy)
    major, minor = (abs(dx), abs(dy)) if horizontal else (abs(dy), abs(dx))
    pieces = min(BLUR_PIECES, int(minor) + 1)
    piece = max(1, round(major / pieces))
    boxed = cv2.blur(image, (piece, 1) if horizontal else (1, piece), borderType=cv2.BORDER_REFLECT)
    if pieces == 1:
        return boxed
    offsets = [(round(((i + 0.5) / pieces - 0.5) * dx), round(((i + 0.5) / pieces - 0.5) * dy)) for i in range(pieces)]
    pad = max(max(abs(ox), abs(oy)) for ox, oy in offsets)
    padded = cv2.copyMakeBorder(boxed, pad, pad, pad, pad, cv2.BORDER_REFLECT)
    height, width = image.shape[:2]
    total = np.zeros(image.shape, np.uint16)
    for ox, oy in offsets:  # the piece at offset (ox, oy) shows what lies (ox, oy) away
        total += padded[pad + oy : pad + oy + height, pad + ox : pad + ox + width]
    return ((total + pieces // 2) // pieces).astype(np.uint8)


@cache
def vignetting_map(height: int, width: int) -> np.ndarray:
    """Squared distance from the image's centre, 1 at the corners (height x width x 1, float32)."""
    y, x = np.mgrid[0:height, 0:width].astype(np.float32)
    r2 = ((x - (width - 1) / 2) ** 2 + (y - (height - 1) / 2) ** 2) / (((width - 1) / 2) ** 2 + ((height - 1) / 2) ** 2)
    return r2[:, :, None]


def yuv422_round_trip(image: np.ndarray) -> np.ndarray:
    """RGB uint8 through the NAO's YUV422: luma per pixel, chroma (U, V) shared by each horizontal pair."""
    yuv = cv2.cvtColor(image, cv2.COLOR_RGB2YUV)
    width = yuv.shape[1] - yuv.shape[1] % 2
    pairs = yuv[:, :width, 1:].reshape(yuv.shape[0], width // 2, 2, 2).astype(np.uint16)
    shared = ((pairs[:, :, 0] + pairs[:, :, 1] + 1) // 2).astype(np.uint8)
    yuv[:, :width, 1:] = np.repeat(shared, 2, axis=1)
    return cv2.cvtColor(yuv, cv2.COLOR_YUV2RGB)


def jpeg_round_trip(image: np.ndarray, quality: int) -> np.ndarray:
    """RGB uint8 saved as JPEG at ``quality`` (1..100) and read back: blocks, ringing, chroma smear."""
    ok, data = cv2.imencode(".jpg", image[:, :, ::-1], [cv2.IMWRITE_JPEG_QUALITY, int(quality)])
    if not ok:
        raise RuntimeError("OpenCV could not encode a JPEG image")
    return cv2.imdecode(data, cv2.IMREAD_COLOR)[:, :, ::-1]


def image_shift(previous: np.ndarray, now: np.ndarray, seconds: float, exposure_s: float, focal_px: tuple[float, float]) -> tuple[float, float]:
    """How far (dx, dy px) the scene moves in the image during the exposure, for a camera that turned
    from ``previous`` to ``now`` (3x3 rotations; columns forward, left, up in the world) in ``seconds``."""
    if seconds <= 0:
        return 0.0, 0.0
    relative = previous.T @ now  # the new camera axes in the old camera's frame
    turn, _ = cv2.Rodrigues(relative)
    rate = turn.ravel() / seconds  # rad/s about forward, left, up
    return float(focal_px[0] * rate[2] * exposure_s), float(focal_px[1] * rate[1] * exposure_s)


# --------------------------------------------------------------------------------------- pipeline
class CameraRealism:
    """One camera's pipeline for one run: what varies per run is drawn here from ``seed``."""

    def __init__(self, level: RealismLevel, seed: int, camera: str = "top") -> None:
        self.level = level
        self.rng = np.random.default_rng([seed, CAMERA_INDEX.get(camera, 2), 31])
        draw = self.rng.uniform
        self.gain = draw(*level.exposure_gain)
        warmth = draw(*level.white_balance)  # a colour temperature off the camera's: red up, blue down, or the other way
        self.white_balance = np.array([warmth, 1.0, 1.0 / warmth], np.float32)
        self.cast = np.array([draw(*level.colour_cast) for _ in range(3)], np.float32)
        self.contrast = draw(*level.contrast)
        self.vignetting = draw(*level.vignetting)
        self.noise_sigma = draw(*level.noise_sigma)
        self.exposure_s = draw(*level.exposure_ms) / 1000.0
        low, high = level.jpeg_quality
        self.jpeg_quality = int(self.rng.integers(low, high + 1)) if high > 0 else 0
        self.offset = ((1.0 - self.contrast) * 128.0 + self.cast).astype(np.float32)
        self.seed, self.camera = seed, camera
        self._shape: tuple[int, int] = (0, 0)
        self._factor = self._noise = np.zeros((0, 0, 3), np.float32)

    def __call__(self, image: np.ndarray, shift: tuple[float, float] = (0.0, 0.0)) -> np.ndarray:
        """``image`` (height x width x 3 RGB uint8) as this camera delivers it; ``shift``: the scene's motion
        in the image during the exposure (px, ``image_shift``). The result has the same shape and dtype."""
        height, width = image.shape[:2]
        factor, noise = self._fields(height, width)
        flicker = 1.0 + self.level.exposure_flicker * float(self.rng.standard_normal())
        pixels = motion_blur(image, shift).astype(np.float32)
        pixels *= factor  # vignetting, exposure, white balance and contrast (about mid-grey)
        pixels *= flicker
        pixels += self.offset  # the contrast's offset and a tinted light
        np.clip(pixels, 0.0, 255.0, out=pixels)
        # dark noise and photon noise; the noise field is seeded once, each frame reads it from a random place, turned or not
        oy, ox = self.rng.integers(0, NOISE_MARGIN + 1, 2)
        sign = 1.0 if self.rng.random() < 0.5 else -1.0
        sigma = np.sqrt(self.noise_sigma**2 + self.level.shot_noise * pixels)
        sigma *= noise[oy : oy + height, ox : ox + width]
        pixels += sigma if sign > 0 else -sigma
        pixels += 0.5
        np.clip(pixels, 0.0, 255.0, out=pixels)
        out = pixels.astype(np.uint8)
        if self.level.chroma_subsampling:
            out = yuv422_round_trip(out)
        if self.jpeg_quality:
            out = jpeg_round_trip(out, self.jpeg_quality)
        return np.ascontiguousarray(out)

    def _fields(self, height: int, width: int) -> tuple[np.ndarray, np.ndarray]:
        """The per-pixel factor of this run and its noise field, for images of this size (made once)."""
        if self._shape != (height, width):
            self._shape = (height, width)
            gains = (self.gain * self.contrast * self.white_balance).astype(np.float32)
            self._factor = ((1.0 - self.vignetting * vignetting_map(height, width)) * gains).astype(np.float32)
            noise_rng = np.random.default_rng([self.seed, CAMERA_INDEX.get(self.camera, 2), height, width])
            self._noise = noise_rng.standard_normal((height + NOISE_MARGIN, width + NOISE_MARGIN, 3), dtype=np.float32)
        return self._factor, self._noise

    def posed_shift(self, focal_px: float) -> tuple[float, float]:
        """A seeded head turn for posed scenes (no motion of their own): mostly sideways, as heads scan."""
        speed = self.rng.uniform(*self.level.posed_head_speed)
        angle = self.rng.normal(0.0, 0.4)
        return focal_px * speed * self.exposure_s * math.cos(angle), focal_px * speed * self.exposure_s * math.sin(angle)
