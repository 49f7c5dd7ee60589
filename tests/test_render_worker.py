"""PyBullet's render worker (the top camera drawn in a process of its own) and the CPU figures the speed
benchmarks read the machine's limit from."""

from __future__ import annotations

import os
import time

import numpy as np
import pytest

from tafel.core.runtime.platform import PlatformOptionError
from tafel.platforms import pybullet_sim
from tafel.platforms.pybullet_sim import PybulletPlatform
from tafel.representations.infrastructure import FrameInfo
from tafel.representations.perception import CameraImageBottom, CameraImageTop
from tafel.tools.simulation.match import cpu_seconds
from tests.support.simulation import Simulation


def cognition_images(sim: Simulation, seconds: float) -> list[tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]]:
    """(top, bottom, top rendered here, bottom rendered here) right after each cognition frame of ``seconds``."""
    seen: list[tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]] = []
    last = [-1]

    def check(s: Simulation) -> None:
        board = s.blackboard("cognition")
        frame = board[FrameInfo].frame_number
        if frame != last[0]:
            last[0] = frame
            seen.append((board[CameraImageTop].image.copy(), board[CameraImageBottom].image.copy(),
                         s.platform.render("top"), s.platform.render("bottom")))

    sim.run(seconds, check)
    return seen


@pytest.mark.slow
def test_render_worker_images_are_those_one_process_renders() -> None:
    """While the robot walks (every joint and the ball moving), the worker's top image is, pixel for
    pixel, what the simulation's own world renders at that moment."""
    sim = Simulation("pybullet", scene="default", cameras="on", resolution="160x120", renderer="pybullet", render_worker="on")
    try:
        assert sim.platform.worker is not None
        frames = cognition_images(sim, 1.5)
        assert sim.platform.worker is not None, "the worker failed and the platform fell back"
    finally:
        sim.close()
    assert len(frames) >= 40
    for top, bottom, top_here, bottom_here in frames:
        assert top.shape == (120, 160, 3)
        np.testing.assert_array_equal(top, top_here)
        np.testing.assert_array_equal(bottom, bottom_here)
    assert len({top.tobytes() for top, *_ in frames}) > 10, "the images must change while the robot walks"


@pytest.mark.slow
def test_a_dead_render_worker_leaves_the_simulation_rendering_alone(capfd: pytest.CaptureFixture[str]) -> None:
    sim = Simulation("pybullet", scene="default", cameras="on", resolution="160x120", renderer="pybullet", render_worker="on")
    try:
        worker = sim.platform.worker
        assert worker is not None
        worker.process.kill()
        worker.process.join()
        frames = cognition_images(sim, 0.5)
        assert sim.platform.worker is None
    finally:
        sim.close()
    assert "rendering both cameras in this process" in capfd.readouterr().err
    for top, bottom, top_here, bottom_here in frames:
        np.testing.assert_array_equal(top, top_here)
        np.testing.assert_array_equal(bottom, bottom_here)


def test_render_worker_option_says_what_it_takes() -> None:
    with pytest.raises(PlatformOptionError, match="on, off or auto"):
        PybulletPlatform({"render_worker": "sometimes"})
    assert PybulletPlatform({"render_worker": "off", "cameras": "on"}).render_worker is False


@pytest.mark.parametrize(("cores", "load", "spare"), [(2, 0.3, True), (2, 1.0, True), (2, 4.5, False), (1, 0.0, False), (8, 6.5, True)])
def test_auto_render_worker_only_with_a_spare_core(monkeypatch: pytest.MonkeyPatch, cores: int, load: float, spare: bool) -> None:
    """On a machine whose cores are all busy, a second process only adds switching: auto renders in one."""
    monkeypatch.setattr(pybullet_sim.os, "cpu_count", lambda: cores)
    monkeypatch.setattr(pybullet_sim.os, "getloadavg", lambda: (load, load, load))
    assert pybullet_sim.spare_core() is spare


def test_cpu_seconds_reads_a_process_cpu_time() -> None:
    """What /proc says this process used is what the process itself counts (the match's limit comes from it)."""
    end = time.process_time() + 0.2
    while time.process_time() < end:
        pass
    measured, own = cpu_seconds(os.getpid()), time.process_time()
    assert measured is not None
    assert own - 0.1 <= measured <= own + 0.05
    assert cpu_seconds() == pytest.approx(time.process_time(), abs=0.05)
    assert cpu_seconds(2**22 + 12345) is None  # no such process
