"""The two ball modelers, through the mocked blackboard."""

from __future__ import annotations

import math

import numpy as np
import pytest

from tafel.core import ModuleManager
from tafel.core.testing import ModuleHarness
from tafel.modules.modeling.kalman_ball_modeler import KalmanBallModeler
from tafel.modules.modeling.simple_ball_modeler import SimpleBallModeler
from tafel.representations.infrastructure import FrameInfo
from tafel.representations.modeling import BallModel
from tafel.representations.perception import BallPercept

FRAME_NS = 33_333_333


def frame(i: int) -> FrameInfo:
    return FrameInfo(frame_number=i, time_ns=i * FRAME_NS)


@pytest.mark.parametrize("modeler", [SimpleBallModeler, KalmanBallModeler])
def test_no_percept_no_valid_model(run_module, modeler) -> None:
    bb = run_module(modeler, BallPercept(seen=False), frames=3)
    assert not bb[BallModel].valid and not bb[BallModel].seen


@pytest.mark.parametrize("modeler", [SimpleBallModeler, KalmanBallModeler])
def test_a_seen_ball_is_modelled_where_it_was_seen(run_module, modeler) -> None:
    bb = run_module(modeler, BallPercept(seen=True, x=1.0), frames=1)
    model = bb[BallModel]
    assert model.valid and model.seen
    assert model.x == pytest.approx(1.0) and model.y == pytest.approx(0.0)


@pytest.mark.parametrize("modeler", [SimpleBallModeler, KalmanBallModeler])
def test_model_is_forgotten_after_the_timeout(modeler) -> None:
    harness = ModuleHarness(modeler, BallPercept(seen=True, x=1000.0, y=200.0), frame(0))
    harness.execute()
    harness.set(BallPercept(seen=False))
    timeout = harness.module.parameters.forget_after
    last_valid = 0
    for i in range(1, 200):
        harness.set(frame(i))
        if harness.execute()[BallModel].valid:
            last_valid = i
    assert not harness[BallModel].seen
    assert last_valid * FRAME_NS * 1e-9 == pytest.approx(timeout, abs=FRAME_NS * 1e-9)
    assert harness[BallModel].x == pytest.approx(1000.0, abs=1.0)  # position kept


def test_simple_modeler_copies_every_percept() -> None:
    harness = ModuleHarness(SimpleBallModeler)
    for i, x in enumerate([100.0, 300.0, -50.0]):
        harness.set(BallPercept(seen=True, x=x, y=-x), frame(i))
        harness.execute()
        assert (harness[BallModel].x, harness[BallModel].y) == (x, -x)


def test_kalman_smooths_noise_better_than_the_plain_copy() -> None:
    truth = np.array([1500.0, 500.0])
    errors = {SimpleBallModeler: [], KalmanBallModeler: []}
    for modeler, sink in errors.items():
        harness = ModuleHarness(modeler)
        noise = np.random.default_rng(7)
        for i in range(90):
            measured = truth + noise.normal(0, 80.0, 2)
            harness.set(BallPercept(seen=True, x=measured[0], y=measured[1]), frame(i))
            harness.execute()
            if i >= 30:
                sink.append(math.hypot(harness[BallModel].x - truth[0], harness[BallModel].y - truth[1]))
    assert np.mean(errors[KalmanBallModeler]) < 0.5 * np.mean(errors[SimpleBallModeler])


def test_kalman_estimates_velocity_of_a_rolling_ball() -> None:
    harness = ModuleHarness(KalmanBallModeler)
    friction, v0 = harness.module.parameters.friction, -800.0
    for i in range(60):
        t = i * FRAME_NS * 1e-9
        x = 2000.0 + v0 / friction * (1.0 - math.exp(-friction * t))  # rolling ball slowed by friction
        harness.set(BallPercept(seen=True, x=x, y=100.0), frame(i))
        harness.execute()
    model = harness[BallModel]
    assert model.vx == pytest.approx(v0 * math.exp(-friction * 59 * FRAME_NS * 1e-9), rel=0.15)
    assert abs(model.vy) < 60.0
    assert model.position_std > 0


def test_kalman_predicts_while_the_ball_is_hidden() -> None:
    harness = ModuleHarness(KalmanBallModeler)
    for i in range(60):
        t = i * FRAME_NS * 1e-9
        harness.set(BallPercept(seen=True, x=1000.0 + 500.0 * t, y=0.0), frame(i))
        harness.execute()
    x_when_lost = harness[BallModel].x
    harness.set(BallPercept(seen=False))
    for i in range(60, 75):
        harness.set(frame(i))
        harness.execute()
    assert harness[BallModel].x > x_when_lost + 100.0  # kept rolling, slowed by friction
    assert harness[BallModel].valid and not harness[BallModel].seen


def test_kalman_restarts_when_the_ball_jumps() -> None:
    harness = ModuleHarness(KalmanBallModeler)
    for i in range(30):
        harness.set(BallPercept(seen=True, x=1000.0, y=0.0), frame(i))
        harness.execute()
    harness.set(BallPercept(seen=True, x=-2000.0, y=1500.0), frame(30))
    model = harness.execute()[BallModel]
    assert (model.x, model.y) == (pytest.approx(-2000.0), pytest.approx(1500.0))
    assert model.vx == 0.0


def test_both_modelers_are_alternatives_for_one_representation() -> None:
    manager = ModuleManager(
        [SimpleBallModeler, KalmanBallModeler],
        external=[BallPercept, FrameInfo],
        providers={"BallModel": "KalmanBallModeler"},
    )
    assert manager.order == ["KalmanBallModeler"]
    manager.set_provider("BallModel", "SimpleBallModeler")
    assert manager.order == ["SimpleBallModeler"]
