"""One clock for every frame: image times, the camera matrix history, and one origin for all processes."""

from __future__ import annotations

import math
import time
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from tafel.core.logs import read_log
from tafel.core.runtime import clock
from tafel.core.testing import ModuleHarness
from tafel.modules.motion.camera_matrix_buffer_provider import CameraMatrixBufferProvider
from tafel.representations.infrastructure import FrameInfo
from tafel.representations.motion import CAMERA_MATRIX_HISTORY, CameraMatrixBottom, CameraMatrixBuffer, CameraMatrixTop
from tafel.representations.perception import CameraImageTop
from tests.support.head_sweep import summary, sweep_errors
from tests.support.simulation import Simulation
from tests.test_cli_runtime import dummy


def yaw(angle: float) -> np.ndarray:
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def buffer_of(entries: list[tuple[int, float, float]]) -> CameraMatrixBuffer:
    """(time_ns, yaw rad, x mm) per entry, the same for both cameras."""
    buffer = CameraMatrixBuffer(count=len(entries))
    for i, (time_ns, angle, x) in enumerate(entries):
        buffer.time_ns[i] = time_ns
        buffer.top_rotation[i] = buffer.bottom_rotation[i] = yaw(angle)
        buffer.top_translation[i] = buffer.bottom_translation[i] = (x, 0.0, 500.0)
    return buffer


def test_the_matrix_at_an_image_time_is_interpolated_between_the_nearest_two() -> None:
    buffer = buffer_of([(0, 0.0, 0.0), (10_000_000, 0.2, 10.0), (20_000_000, 0.4, 30.0)])
    middle = buffer.at("top", 15_000_000)
    assert middle.valid
    np.testing.assert_allclose(middle.rotation, yaw(0.3), atol=1e-12)
    np.testing.assert_allclose(middle.translation, (20.0, 0.0, 500.0))
    np.testing.assert_allclose(buffer.at("bottom", 2_500_000).rotation, yaw(0.05), atol=1e-12)
    # outside the history: the nearest entry
    np.testing.assert_allclose(buffer.at("top", -5).rotation, yaw(0.0), atol=1e-12)
    np.testing.assert_allclose(buffer.at("top", 10**12).translation, (30.0, 0.0, 500.0))
    np.testing.assert_allclose(buffer.newest("top").rotation, yaw(0.4), atol=1e-12)


def test_an_empty_buffer_gives_invalid_matrices_and_cameras_are_named() -> None:
    assert not CameraMatrixBuffer().at("top", 0).valid and not CameraMatrixBuffer().newest("bottom").valid
    with pytest.raises(ValueError, match="'top' or 'bottom'"):
        buffer_of([(0, 0.0, 0.0)]).at("left", 0)


@given(st.lists(st.floats(-1.5, 1.5), min_size=2, max_size=10), st.floats(0.0, 1.0))
def test_interpolated_rotations_stay_rotations_and_hit_the_entries(angles: list[float], share: float) -> None:
    buffer = buffer_of([(i * 10_000_000, a, 10.0 * i) for i, a in enumerate(angles)])
    for i, angle in enumerate(angles):
        np.testing.assert_allclose(buffer.at("top", i * 10_000_000).rotation, yaw(angle), atol=1e-7)  # entries 10 nanoradians apart may merge
    between = buffer.at("top", int(share * 10_000_000))
    np.testing.assert_allclose(between.rotation @ between.rotation.T, np.eye(3), atol=1e-9)
    assert np.linalg.det(between.rotation) == pytest.approx(1.0)
    expected = angles[0] + share * (angles[1] - angles[0])
    np.testing.assert_allclose(between.rotation, yaw(expected), atol=1e-6)


def test_the_provider_keeps_the_newest_matrices_oldest_first() -> None:
    harness = ModuleHarness(CameraMatrixBufferProvider)
    for frame in range(CAMERA_MATRIX_HISTORY + 15):
        harness.set(FrameInfo(frame_number=frame, time_ns=frame * 10_000_000),
                    CameraMatrixTop(rotation=yaw(0.01 * frame), translation=np.array([frame, 0.0, 0.0]), valid=True),
                    CameraMatrixBottom(rotation=yaw(-0.01 * frame), translation=np.array([0.0, frame, 0.0]), valid=True))
        harness.execute()
    buffer = harness[CameraMatrixBuffer]
    assert buffer.count == CAMERA_MATRIX_HISTORY
    first = 15
    assert list(buffer.time_ns) == [f * 10_000_000 for f in range(first, first + CAMERA_MATRIX_HISTORY)]
    assert buffer.top_translation[0][0] == first and buffer.bottom_translation[-1][1] == first + CAMERA_MATRIX_HISTORY - 1
    np.testing.assert_allclose(buffer.at("bottom", 200_000_000).rotation, yaw(-0.2), atol=1e-12)


def test_the_provider_waits_for_valid_matrices_and_starts_over_when_time_goes_back() -> None:
    harness = ModuleHarness(CameraMatrixBufferProvider)
    harness.set(FrameInfo(time_ns=0), CameraMatrixTop(), CameraMatrixBottom())
    assert harness.execute()[CameraMatrixBuffer].count == 0
    valid = {"rotation": np.eye(3), "translation": np.zeros(3), "valid": True}
    for time_ns in (10, 20, 30, 5):
        harness.set(FrameInfo(time_ns=time_ns), CameraMatrixTop(**valid), CameraMatrixBottom(**valid))
        harness.execute()
    buffer = harness[CameraMatrixBuffer]
    assert buffer.count == 1 and buffer.time_ns[0] == 5


@pytest.mark.slow
def test_simulated_images_are_taken_camera_latency_before_they_arrive() -> None:
    sim = Simulation("mujoco", camera_latency_ms=40, cameras="on")
    try:
        sim.run(0.5)
        frame, image = sim.blackboard("cognition")[FrameInfo], sim.blackboard("cognition")[CameraImageTop]
        assert frame.time_ns > 0 and image.time_ns == frame.time_ns - 40_000_000
    finally:
        sim.close()
    sim = Simulation("mujoco", cameras="on")
    try:
        sim.run(0.2)
        assert sim.blackboard("cognition")[CameraImageTop].time_ns == sim.blackboard("cognition")[FrameInfo].time_ns
    finally:
        sim.close()


@pytest.mark.slow
def test_camera_latency_option_is_checked() -> None:
    result = dummy("--frames", "1")  # the dummy has no cameras: the option belongs to the simulators
    assert result.returncode == 0
    from tests.test_cli_runtime import tafel

    bad = tafel("run", "--platform", "mujoco", "--camera-latency-ms", "-5", "--frames", "1", "--no-debug")
    assert bad.returncode == 2 and "--camera-latency-ms takes a finite number of ms from 0 to 1000, got -5" in bad.stderr


@pytest.mark.slow
def test_every_process_of_a_concurrent_program_shares_one_origin(tmp_path: Path) -> None:
    """Processes adopt the supervisor's origin: with it set 1000 s back, every frame time is past 1000 s."""
    from tafel.core.framework.config import load_config
    from tafel.core.logs.recording import Recorder, select
    from tafel.core.runtime import ConcurrentRuntime, Limits
    from tafel.core.runtime.platform import load_platform
    from tafel.core.runtime.program import plan_program
    from tafel.tools.launch.defaults import DEFAULT_CONFIG
    from tafel.tools.launch.program import discover_modules

    discover_modules()
    platform = load_platform("dummy")
    plans = plan_program(load_config(DEFAULT_CONFIG, "dummy"), platform)
    recorder = Recorder(select(plans, []))
    path = tmp_path / "clock.mcap"
    recorder.start(path)
    saved = clock.origin_ns()
    clock.set_origin(time.monotonic_ns() - 1000 * 10**9)
    try:
        ConcurrentRuntime(plans, platform, {}, recorder=recorder).run(Limits(frames=60, speed=1.0))
    finally:
        clock.set_origin(saved)
    contents = read_log(path)
    times = {context: [m.time_ns for m in contents.messages if m.topic == f"{context}/FrameInfo"] for context in ("motion", "cognition")}
    assert len(times["motion"]) >= 50 and len(times["cognition"]) >= 10
    for context, values in times.items():  # a process with its own origin would start near 0
        assert 1000 * 10**9 <= min(values) < 1100 * 10**9, context


@pytest.mark.slow
def test_time_aligned_matrices_keep_the_ball_in_place_while_the_head_sweeps() -> None:
    aligned = summary(sweep_errors("mujoco", 40.0, aligned=True, seconds=4.0, speed=3.0))
    newest = summary(sweep_errors("mujoco", 40.0, aligned=False, seconds=4.0, speed=3.0))
    assert aligned["percepts"] >= 50 and newest["percepts"] >= 50
    assert aligned["max"] < 0.10, aligned
    assert newest["mean"] > 3 * aligned["mean"], (aligned, newest)  # the sweep really tests the latency
