"""The two ball modelers, through the mocked blackboard."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from tafel.core import ModuleManager
from tafel.core.testing import ModuleHarness
from tafel.modules.modeling.kalman_ball_modeler import KalmanBallModeler
from tafel.modules.modeling.simple_ball_modeler import SimpleBallModeler
from tafel.representations.infrastructure import FrameInfo
from tafel.representations.modeling import BallModel, RobotPose
from tafel.representations.motion_control import Odometry
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


def seen_at(harness: ModuleHarness, frames: range, x: float, y: float) -> BallModel:
    for i in frames:
        harness.set(BallPercept(seen=True, x=x, y=y), frame(i))
        harness.execute()
    return harness[BallModel]


def test_kalman_ignores_a_single_outlier() -> None:
    harness = ModuleHarness(KalmanBallModeler)
    seen_at(harness, range(30), 1000.0, 0.0)
    model = seen_at(harness, range(30, 31), -2000.0, 1500.0)  # one false detection far away
    assert (model.x, model.y) == (pytest.approx(1000.0, abs=20.0), pytest.approx(0.0, abs=20.0))
    model = seen_at(harness, range(31, 32), 1000.0, 0.0)
    assert model.x == pytest.approx(1000.0, abs=20.0)


def test_kalman_ignores_outliers_that_disagree_with_each_other() -> None:
    harness = ModuleHarness(KalmanBallModeler)
    seen_at(harness, range(30), 1000.0, 0.0)
    for i, (x, y) in enumerate([(-2000.0, 1500.0), (2500.0, -1500.0), (-500.0, -2000.0), (3000.0, 2000.0)]):
        model = seen_at(harness, range(30 + i, 31 + i), x, y)
        assert model.x == pytest.approx(1000.0, abs=50.0)


def test_kalman_restarts_when_the_ball_really_jumps() -> None:
    harness = ModuleHarness(KalmanBallModeler)
    seen_at(harness, range(30), 1000.0, 0.0)
    restart_after = harness.module.parameters.restart_after
    model = seen_at(harness, range(30, 30 + restart_after - 1), -2000.0, 1500.0)
    assert model.x == pytest.approx(1000.0, abs=50.0)  # not yet: could still be false detections
    model = seen_at(harness, range(30 + restart_after - 1, 30 + restart_after), -2000.0, 1500.0)
    assert (model.x, model.y) == (pytest.approx(-2000.0), pytest.approx(1500.0))
    assert model.vx == 0.0


@pytest.mark.parametrize(("forward", "left", "turn"), [(300.0, 0.0, 0.0), (0.0, 200.0, 0.0), (0.0, 0.0, math.pi / 2), (250.0, -100.0, 0.6)])
def test_kalman_follows_the_robots_own_motion_by_odometry(forward: float, left: float, turn: float) -> None:
    """The robot walks and turns without seeing a resting ball: the model moves the other way."""
    harness = ModuleHarness(KalmanBallModeler, Odometry())
    seen_at(harness, range(30), 1500.0, 500.0)
    steps = 30
    for i in range(1, steps + 1):
        share = i / steps
        harness.set(BallPercept(seen=False), frame(30 + i), Odometry(x=forward * share, y=left * share, rotation=turn * share))
        harness.execute()
    model = harness[BallModel]
    # where the ball is as seen from the robot's final pose (the path's shape does not matter for a
    # resting ball: only the end pose)
    dx, dy = 1500.0 - forward, 500.0 - left
    c, s = math.cos(turn), math.sin(turn)
    expected = (c * dx + s * dy, -s * dx + c * dy)
    assert model.valid
    assert math.hypot(model.x - expected[0], model.y - expected[1]) < 30.0


@given(x=st.floats(-4000, 4000), y=st.floats(-4000, 4000), rotation=st.floats(-math.pi, math.pi),
       px=st.floats(-9000, 9000), py=st.floats(-6000, 6000))
def test_field_position_and_robot_frame_are_inverse(x: float, y: float, rotation: float, px: float, py: float) -> None:
    pose = RobotPose(valid=True, x=px, y=py, rotation=rotation)
    field_x, field_y = BallModel(valid=True, x=x, y=y).field_position(pose)
    back = pose.to_robot(field_x, field_y)
    assert back == (pytest.approx(x, abs=1e-6), pytest.approx(y, abs=1e-6))
    assert math.hypot(field_x - px, field_y - py) == pytest.approx(math.hypot(x, y), abs=1e-6)


def test_both_modelers_are_alternatives_for_one_representation() -> None:
    manager = ModuleManager(
        [SimpleBallModeler, KalmanBallModeler],
        external=[BallPercept, FrameInfo, Odometry],
        providers={"BallModel": "KalmanBallModeler"},
    )
    assert manager.order == ["KalmanBallModeler"]
    manager.set_provider("BallModel", "SimpleBallModeler")
    assert manager.order == ["SimpleBallModeler"]
