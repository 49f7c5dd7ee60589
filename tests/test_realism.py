"""``--realism``: the camera pipeline (platforms/realism.py), the realistic scene, the option and its end to end run."""

from __future__ import annotations

import math
from pathlib import Path

import cv2
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tafel.core.runtime.platform import PlatformOptionError, load_platform
from tafel.platforms.field_world import SceneLook, carpet_texture, field_parts, scene_look
from tafel.platforms.realism import (
    LEVELS,
    CameraRealism,
    image_shift,
    jpeg_round_trip,
    motion_blur,
    parse_realism,
    realism_level,
    yuv422_round_trip,
)
from tafel.platforms.robot_model import mjcf, mjcf_assets

REPO = Path(__file__).resolve().parent.parent


def scene(height: int = 120, width: int = 160, seed: int = 0) -> np.ndarray:
    """A rendered-looking test image: green with white lines and a random texture."""
    rng = np.random.default_rng(seed)
    image = np.zeros((height, width, 3), np.uint8)
    image[:] = (40, 140, 50)
    image[height // 3 :: 17, :] = 255
    image[:, width // 4 :: 23] = 255
    return np.clip(image.astype(int) + rng.integers(-30, 30, image.shape), 0, 255).astype(np.uint8)


def sharpness(image: np.ndarray) -> float:
    """Mean absolute difference between neighbouring pixels: falls as an image gets blurred."""
    values = image.astype(float)
    return float(np.abs(np.diff(values, axis=1)).mean() + np.abs(np.diff(values, axis=0)).mean())


def yaw(angle: float) -> np.ndarray:
    """A camera turned by ``angle`` about the world's up axis (columns forward, left, up)."""
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


@pytest.mark.parametrize("level", ["mild", "full"])
def test_the_same_seed_gives_the_same_images_and_another_seed_other_ones(level: str) -> None:
    settings_ = realism_level(level)
    assert settings_ is not None
    images = [scene(seed=k) for k in range(3)]
    first_pipeline, again_pipeline = CameraRealism(settings_, 7, "top"), CameraRealism(settings_, 7, "top")
    first = [first_pipeline(image, (3.0, 1.0)) for image in images]
    again = [again_pipeline(image, (3.0, 1.0)) for image in images]
    assert not np.array_equal(first_pipeline(images[0], (3.0, 1.0)), first[0])  # each frame its own noise
    other = CameraRealism(settings_, 8, "top")(images[0], (3.0, 1.0))
    bottom = CameraRealism(settings_, 7, "bottom")(images[0], (3.0, 1.0))
    assert all(np.array_equal(a, b) for a, b in zip(first, again))
    assert not np.array_equal(first[0], other)
    assert not np.array_equal(first[0], bottom)  # the two cameras of one run differ


@settings(max_examples=25, deadline=None)
@given(height=st.integers(2, 64), width=st.integers(2, 64), seed=st.integers(0, 2**32 - 1), level=st.sampled_from(["mild", "full"]),
       fill=st.sampled_from(["black", "white", "random"]), shift=st.tuples(st.floats(-80, 80), st.floats(-80, 80)))
def test_the_pipeline_keeps_shape_and_dtype_and_clips_instead_of_wrapping(height: int, width: int, seed: int, level: str, fill: str,
                                                                          shift: tuple[float, float]) -> None:
    rng = np.random.default_rng(seed)
    image = {"black": np.zeros((height, width, 3), np.uint8), "white": np.full((height, width, 3), 255, np.uint8),
             "random": rng.integers(0, 256, (height, width, 3)).astype(np.uint8)}[fill]
    settings_ = realism_level(level)
    assert settings_ is not None
    out = CameraRealism(settings_, seed)(image, shift)
    assert out.shape == image.shape and out.dtype == np.uint8 and out.flags.c_contiguous
    # uint8 holds 0..255 by its type; what can go wrong is wrapping round (white past 255 comes out near 0,
    # black below 0 near 255). A tiny image is all corner, where vignetting and a cast darken white to ~130.
    if fill == "white":
        assert out.mean() > 100
    if fill == "black":
        assert out.mean() < 100


def test_yuv422_halves_the_chroma_resolution_and_keeps_the_luma() -> None:
    image = np.zeros((8, 16, 3), np.uint8)
    image[:, 0::2] = (220, 40, 40)  # red and blue columns one pixel wide: chroma changes every pixel
    image[:, 1::2] = (40, 40, 220)
    out = yuv422_round_trip(image)
    chroma = cv2.cvtColor(out, cv2.COLOR_RGB2YUV)[:, :, 1:].astype(int)
    chroma_in = cv2.cvtColor(image, cv2.COLOR_RGB2YUV)[:, :, 1:].astype(int)
    assert np.abs(chroma_in[:, 0::2] - chroma_in[:, 1::2]).max() > 100
    assert np.abs(chroma[:, 0::2] - chroma[:, 1::2]).max() <= 2  # each horizontal pair shares its chroma
    luma_in = cv2.cvtColor(image, cv2.COLOR_RGB2YUV)[:, :, 0].astype(int)
    assert np.abs(cv2.cvtColor(out, cv2.COLOR_RGB2YUV)[:, :, 0].astype(int) - luma_in).max() <= 3


def test_jpeg_leaves_a_lower_quality_further_from_the_original() -> None:
    image = scene()
    errors = [np.abs(jpeg_round_trip(image, q).astype(int) - image).mean() for q in (95, 70, 30)]
    assert errors[0] < errors[1] < errors[2]


def test_blur_grows_with_the_cameras_angular_speed() -> None:
    image = scene(240, 320)
    focal = (160 / math.tan(math.radians(56.3) / 2), 120 / math.tan(math.radians(43.7) / 2))
    dt, exposure = 1 / 30, 0.02
    shifts = [image_shift(yaw(0.0), yaw(speed * dt), dt, exposure, focal) for speed in (0.0, 0.5, 1.0, 2.0, 4.0)]
    assert shifts[0] == (0.0, 0.0)
    assert abs(shifts[2][0]) == pytest.approx(focal[0] * 1.0 * exposure, rel=1e-6) and abs(shifts[2][1]) < 1e-9  # a yaw smears sideways
    blurred = [sharpness(motion_blur(image, shift)) for shift in shifts]
    assert all(a > b for a, b in zip(blurred[1:], blurred[2:]))
    assert blurred[0] >= blurred[1] > blurred[-1]
    # a pitch smears up and down
    c, s = math.cos(0.05), math.sin(0.05)
    pitched = np.array([[c, 0.0, -s], [0.0, 1.0, 0.0], [s, 0.0, c]])
    dx, dy = image_shift(np.eye(3), pitched, dt, exposure, focal)
    assert abs(dy) > 10 * abs(dx)


def test_a_slanted_blur_smears_along_its_direction() -> None:
    image = np.zeros((64, 64, 3), np.uint8)
    image[32, 32] = 255
    out = motion_blur(image, (12.0, 12.0))[:, :, 0].astype(float)
    ys, xs = np.nonzero(out)
    assert np.corrcoef(xs, ys)[0, 1] > 0.8  # the dot became a diagonal streak


def test_an_unknown_level_is_refused_with_the_levels_named() -> None:
    with pytest.raises(PlatformOptionError, match=r"--realism takes one of off, mild, full"):
        parse_realism("ultra")
    with pytest.raises(PlatformOptionError, match=r"--realism takes one of off, mild, full"):
        load_platform("mujoco")({"realism": "on"})
    assert parse_realism(None) == "off" and parse_realism("FULL") == "full"
    assert realism_level("off") is None
    assert set(LEVELS) == {"off", "mild", "full"}


def test_a_wrong_key_or_range_in_the_levels_file_is_named(tmp_path: Path) -> None:
    text = (REPO / "config" / "realism.toml").read_text()
    bad = tmp_path / "realism.toml"
    bad.write_text(text.replace("exposure_flicker = 0.02", "exposure_flickr = 0.02"))
    with pytest.raises(PlatformOptionError, match=r"realism.toml \[mild\] has no key 'exposure_flickr'; did you mean 'exposure_flicker'"):
        realism_level("mild", bad)
    bad.write_text(text.replace("jpeg_quality = [85, 95]", "jpeg_quality = [95, 85]"))
    with pytest.raises(PlatformOptionError, match=r"jpeg_quality takes \[low, high\] with low <= high"):
        realism_level("mild", bad)


def test_the_plain_scene_is_unchanged_and_the_realistic_one_adds_only_what_does_not_collide() -> None:
    plain = field_parts()
    assert [p.name for p in field_parts(look=None)] == [p.name for p in plain]
    assert not any(p.name.startswith("hall_") or "_cord" in p.name or p.material for p in plain)
    look = scene_look(3, [(0.2, 0.5, 0.2), (0.1, 0.4, 0.2)], 0.1, clutter=True, nets=True)
    realistic = field_parts(look=look)
    added = [p for p in realistic if p.name not in {q.name for q in plain}]
    assert any(p.name.startswith("hall_person") for p in added) and any("_cord" in p.name for p in added)
    assert not any(p.collides for p in added) and all(p.in_cameras for p in added)
    assert [p for p in realistic if p.name == "carpet"][0].rgba[:3] in ((0.2, 0.5, 0.2), (0.1, 0.4, 0.2))
    assert field_parts(look=look) == realistic  # seeded
    assert field_parts(look=SceneLook(4, look.carpet, 0.1)) != realistic


def test_the_carpet_texture_is_seeded_tiles_and_keeps_its_green() -> None:
    look = SceneLook(5, (0.18, 0.55, 0.2), 0.12)
    texture = carpet_texture(look)
    assert texture.shape == (256, 256, 3) and texture.dtype == np.uint8
    assert np.array_equal(texture, carpet_texture(look))
    mean = texture.reshape(-1, 3).mean(axis=0) / 255
    assert np.allclose(mean, look.carpet, atol=0.03) and texture[:, :, 1].std() > 2
    # it tiles: the step across the seam is no larger than steps inside
    seam = np.abs(texture[:, 0].astype(int) - texture[:, -1]).mean()
    inside = np.abs(np.diff(texture.astype(int), axis=1)).mean()
    assert seam < 2 * inside


def test_the_realistic_model_loads_in_mujoco_with_its_texture_and_shadows() -> None:
    mujoco = pytest.importorskip("mujoco")
    look = scene_look(1, [(0.2, 0.5, 0.2)], 0.1, clutter=True, nets=True)
    model = mujoco.MjModel.from_xml_string(mjcf(look=look, shadows=True), mjcf_assets("spl", look))
    assert model.ntex == 2 and model.vis.quality.shadowsize > 0
    assert model.ngeom > mujoco.MjModel.from_xml_string(mjcf(), mjcf_assets("spl")).ngeom + 100


@pytest.mark.slow  # starts MuJoCo and a tafel run
def test_a_realistic_run_renders_other_images_than_the_plain_one_and_the_program_runs() -> None:
    from tafel.representations.perception import CameraImageTop
    from tests.support.simulation import Simulation
    from tests.test_cli_runtime import tafel

    images = {}
    for level in ("off", "full", "full"):
        sim = Simulation("mujoco", seed=4, realism=level)
        try:
            sim.run(0.5)
            images.setdefault(level, []).append(sim.blackboard("cognition")[CameraImageTop].image.copy())
        finally:
            sim.close()
    plain, realistic, again = images["off"][0], images["full"][0], images["full"][1]
    assert plain.shape == realistic.shape and realistic.dtype == np.uint8
    assert np.abs(plain.astype(int) - realistic).mean() > 5  # other light, noise, hall: not the plain render
    assert np.array_equal(realistic, again)  # same seed, same images
    result = tafel("run", "--platform", "mujoco", "--realism", "--frames", "60", "--speed", "max", "--no-debug", timeout=300)
    assert result.returncode == 0, result.stderr
    assert "cognition" in result.stdout
