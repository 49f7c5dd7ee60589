"""Every shipped module tested as a team tests it: over time with the harness clock or fed sequences,
and with properties over bounded inputs where an invariant exists."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tafel.core.runtime.status import CognitionStatus
from tafel.core.testing import ModuleHarness, assert_close, replay_module, strategy_for
from tafel.modules.behavior.look_at_ball_behavior import LookAtBallBehavior
from tafel.modules.modeling.kalman_ball_modeler import KalmanBallModeler
from tafel.modules.modeling.simple_ball_modeler import SimpleBallModeler
from tafel.modules.motion.camera_matrix_buffer_provider import CameraMatrixBufferProvider
from tafel.modules.motion.camera_matrix_provider import CameraMatrixProvider
from tafel.modules.motion.head_motion import HeadMotion
from tafel.modules.motion.inertial_filter import InertialFilter
from tafel.modules.motion.motion_combinator import MotionCombinator
from tafel.modules.motion.stand_motion import StandMotion, stand_pose
from tafel.modules.motion.status_leds import BLUE_EYE, RED_EYE, StatusLeds
from tafel.modules.perception.ball_detector import BallDetector
from tafel.modules.perception.ball_locator import BallLocator
from tafel.platforms.actuators import JOINT_LIMITS
from tafel.representations.behavior import HeadMotionRequest
from tafel.representations.modeling import BallModel
from tafel.representations.motion import (
    CAMERA_MATRIX_HISTORY,
    HEAD_PITCH,
    HEAD_YAW,
    JOINT_COUNT,
    BodyJointTargets,
    CameraMatrixBottom,
    CameraMatrixBuffer,
    CameraMatrixTop,
    HeadJointTargets,
    InertialModel,
    InertialSensorData,
    JointCommand,
    JointSensorData,
    LedRequest,
)
from tafel.representations.perception import BallImagePercept, BallPercept, CameraImageBottom, CameraImageTop
from tests.test_cli_runtime import REPO

SITUATION = REPO / "tests" / "data" / "ball_situation.mcap"
JOINTS_WITHIN_LIMITS = st.tuples(*(st.floats(float(low), float(high)) for low, high in JOINT_LIMITS)).map(np.array)


# ----------------------------------------------------------------------------------- ball modelling
def test_the_kalman_model_estimates_a_rolling_balls_velocity_from_a_sequence() -> None:
    harness = ModuleHarness(KalmanBallModeler, parameters={"friction": 0.0})  # a ball that keeps its speed
    speed = 600.0  # mm/s towards the left
    harness.feed({BallPercept: [BallPercept(seen=True, x=2000.0, y=speed * i / 30.0) for i in range(60)]})
    harness.execute()  # two seconds at 30 Hz
    model = harness[BallModel]
    assert model.valid and model.seen
    assert_close(model.vy, speed, rel=0.1)
    assert_close(model.y, speed * 59 / 30.0, abs=60.0)
    stds = [m.position_std for m in harness.history(BallModel)]
    assert stds[-1] < stds[0]  # each percept makes it surer


def test_the_kalman_model_forgets_the_ball_after_its_time() -> None:
    harness = ModuleHarness(KalmanBallModeler, BallPercept(seen=True, x=1000.0))
    harness.execute(frames=5)
    harness.set(BallPercept(seen=False))
    harness.advance(2.9)
    assert harness[BallModel].valid
    harness.advance(0.2)
    assert not harness[BallModel].valid and harness[BallModel].time_since_seen > 3.0


@settings(max_examples=40)
@given(st.lists(strategy_for(BallPercept), min_size=1, max_size=40))
def test_the_kalman_model_stays_finite_and_sure_of_nothing_negative(percepts: list[BallPercept]) -> None:
    harness = ModuleHarness(KalmanBallModeler)
    harness.feed({BallPercept: percepts})
    harness.execute()
    for model in harness.history(BallModel):
        assert all(math.isfinite(v) for v in (model.x, model.y, model.vx, model.vy, model.position_std))
        assert model.position_std >= 0.0 and model.time_since_seen >= 0.0


def test_the_simple_model_holds_the_last_percept_until_it_forgets() -> None:
    harness = ModuleHarness(SimpleBallModeler, BallPercept(seen=True, x=800.0, y=-200.0))
    harness.execute()
    harness.set(BallPercept(seen=False, x=0.0, y=0.0))
    harness.advance(1.9)
    assert harness[BallModel].valid and (harness[BallModel].x, harness[BallModel].y) == (800.0, -200.0)
    harness.advance(0.2)
    assert not harness[BallModel].valid


@given(strategy_for(BallPercept, seen=st.just(True)))
def test_the_simple_model_copies_every_seen_percept(percept: BallPercept) -> None:
    harness = ModuleHarness(SimpleBallModeler, percept)
    model = harness.execute()[BallModel]
    assert (model.x, model.y, model.vx, model.vy) == (percept.x, percept.y, 0.0, 0.0) and model.valid


# ------------------------------------------------------------------------------------------ behaviour
def test_the_behaviour_looks_at_the_ball_then_searches_after_losing_it() -> None:
    harness = ModuleHarness(LookAtBallBehavior, BallModel(valid=True, seen=True, x=1000.0, y=1000.0))
    harness.execute(frames=3)
    assert_close(harness[HeadMotionRequest].yaw, math.pi / 4, rel=1e-9)
    lost = [BallModel(valid=True, seen=False, x=1000.0, y=1000.0, time_since_seen=0.6 + i / 30.0) for i in range(60)]
    harness.feed({BallModel: lost})
    harness.execute()
    yaws = [r.yaw for r in harness.history(HeadMotionRequest)[3:]]
    assert yaws[0] <= math.pi / 4 + 1e-9 and yaws[5] < yaws[0]  # sweeps towards the other side first
    assert min(yaws) < 0.0 < max(yaws)


@given(strategy_for(BallModel), st.integers(1, 10))
def test_whatever_the_ball_model_says_the_head_request_is_finite_and_reachable(model: BallModel, frames: int) -> None:
    harness = ModuleHarness(LookAtBallBehavior, model)
    request = harness.execute(frames=frames)[HeadMotionRequest]
    assert math.isfinite(request.yaw) and math.isfinite(request.pitch) and request.max_speed > 0
    assert abs(request.yaw) <= math.pi and abs(request.pitch) <= math.pi / 2


# ----------------------------------------------------------------------------------------- perception
def _frame_with_ball(x: float, y: float, radius: float = 12.0) -> CameraImageTop:
    import cv2

    image = np.zeros((240, 320, 3), np.uint8)
    image[:] = (40, 140, 40)
    cv2.circle(image, (int(round(x)), int(round(y))), int(radius), (255, 120, 0), -1)
    return CameraImageTop(image=image, horizontal_fov=1.06, vertical_fov=0.83)


def test_the_detector_follows_a_ball_across_a_sequence_of_images() -> None:
    path = [(40.0 + 12.0 * i, 120.0 + 4.0 * math.sin(i / 3)) for i in range(20)]
    harness = ModuleHarness(BallDetector, CameraImageBottom(image=np.zeros((0, 0, 3), np.uint8)))
    harness.feed({CameraImageTop: [_frame_with_ball(x, y) for x, y in path]})
    harness.execute()
    for (x, y), percept in zip(path, harness.history(BallImagePercept)):
        (best,) = percept.candidates
        assert abs(best.x - x) <= 1.0 and abs(best.y - y) <= 1.0 and best.camera == "top"


@settings(max_examples=25)
@given(st.integers(0, 2**32 - 1))
def test_candidates_lie_inside_the_image_whatever_it_shows(seed: int) -> None:
    rng = np.random.default_rng(seed)
    noise = rng.integers(0, 256, (60, 80, 3), dtype=np.uint8)  # random pixels, orange ones among them
    harness = ModuleHarness(BallDetector, CameraImageTop(image=noise), CameraImageBottom(image=noise))
    percept = harness.execute()[BallImagePercept]
    assert len(percept.candidates) <= 5
    for candidate in percept.candidates:
        assert 0.0 <= candidate.x <= 80.0 and 0.0 <= candidate.y <= 60.0 and candidate.radius >= 2.0


def test_the_locator_replays_a_recorded_situation_exactly() -> None:
    result = replay_module(BallLocator, SITUATION, start_s=0.5, seconds=2.0)
    assert len(result.frames) == 60
    assert result.differences() == []  # the recorded BallPercept, frame by frame, bit for bit
    assert all(p.seen for p in result.outputs(BallPercept))
    xs = [p.x for p in result.outputs(BallPercept)]
    assert 1300.0 < float(np.median(xs)) < 1800.0  # the ball lay 1.5 m ahead in that game


@given(strategy_for(BallImagePercept, candidates=st.just([])))
def test_no_candidate_means_no_ball(percept: BallImagePercept) -> None:
    harness = ModuleHarness(BallLocator, percept)
    assert harness.execute()[BallPercept].seen is False


# ------------------------------------------------------------------------------------------- motion
def test_the_inertial_filter_settles_on_a_constant_tilt() -> None:
    tilted = InertialSensorData(accelerometer=np.array([0.0, 1.7, 9.66]), angles=np.array([0.17, 0.0]))
    harness = ModuleHarness(InertialFilter, InertialSensorData())
    harness.execute()
    harness.feed({InertialSensorData: [tilted] * 20})
    harness.execute()
    rolls = [m.roll for m in harness.history(InertialModel)]
    assert rolls[0] == 0.0 and all(a <= b for a, b in zip(rolls, rolls[1:]))
    assert_close(rolls[-1], 0.17, abs=1e-4)


@given(st.lists(strategy_for(InertialSensorData), min_size=1, max_size=20))
def test_the_filtered_angles_stay_within_what_the_sensor_said(samples: list[InertialSensorData]) -> None:
    harness = ModuleHarness(InertialFilter)
    harness.feed({InertialSensorData: samples})
    harness.execute()
    rolls = [float(s.angles[0]) for s in samples]
    for model in harness.history(InertialModel):
        assert min(rolls) - 1e-9 <= model.roll <= max(rolls) + 1e-9  # a filter never overshoots its inputs
        assert np.isfinite(model.gyroscope).all() and np.isfinite(model.accelerometer).all()


def test_the_camera_matrices_follow_the_head_through_a_sequence() -> None:
    joints = []
    for i in range(10):
        position = stand_pose()
        position[HEAD_YAW] = 0.1 * i
        joints.append(JointSensorData(position=position))
    harness = ModuleHarness(CameraMatrixProvider, InertialModel())
    harness.feed({JointSensorData: joints})
    harness.execute()
    headings = [math.atan2(m.rotation[1, 0], m.rotation[0, 0]) for m in harness.history(CameraMatrixTop)]
    assert_close(headings, [0.1 * i for i in range(10)], abs=1e-9)


@given(JOINTS_WITHIN_LIMITS, strategy_for(InertialModel, roll=st.floats(-0.5, 0.5), pitch=st.floats(-0.5, 0.5)))
def test_camera_rotations_are_proper_rotations_for_any_posture(position: np.ndarray, inertial: InertialModel) -> None:
    harness = ModuleHarness(CameraMatrixProvider, JointSensorData(position=position), inertial)
    harness.execute()
    for matrix in (harness[CameraMatrixTop], harness[CameraMatrixBottom]):
        assert np.allclose(matrix.rotation @ matrix.rotation.T, np.eye(3), atol=1e-9)
        assert math.isclose(np.linalg.det(matrix.rotation), 1.0, abs_tol=1e-9) and matrix.valid


def test_the_buffer_keeps_the_newest_matrices_in_time_order() -> None:
    harness = ModuleHarness(CameraMatrixBufferProvider)  # motion: frames 10 ms apart
    tops = [CameraMatrixTop(translation=np.array([float(i), 0.0, 0.0]), valid=True) for i in range(60)]
    bottoms = [CameraMatrixBottom(translation=np.array([0.0, float(i), 0.0]), valid=True) for i in range(60)]
    harness.feed({CameraMatrixTop: tops, CameraMatrixBottom: bottoms})
    harness.execute()
    buffer = harness[CameraMatrixBuffer]
    assert buffer.count == CAMERA_MATRIX_HISTORY
    assert list(np.diff(buffer.time_ns)) == [10_000_000] * (CAMERA_MATRIX_HISTORY - 1)
    assert buffer.top_translation[-1][0] == 59.0 and buffer.time_ns[-1] == harness.time_ns


@given(st.lists(st.booleans(), min_size=1, max_size=60))
def test_the_buffer_never_holds_more_than_its_history_nor_an_invalid_matrix(valid: list[bool]) -> None:
    harness = ModuleHarness(CameraMatrixBufferProvider)
    harness.feed({CameraMatrixTop: [CameraMatrixTop(valid=v) for v in valid],
                  CameraMatrixBottom: [CameraMatrixBottom(valid=v) for v in valid]})
    harness.execute()
    counts = [b.count for b in harness.history(CameraMatrixBuffer)]
    assert all(0 <= c <= CAMERA_MATRIX_HISTORY for c in counts)
    assert counts[-1] <= sum(valid)


def test_the_stand_ramps_from_where_the_robot_is_to_the_stand_in_its_duration() -> None:
    harness = ModuleHarness(StandMotion, JointSensorData(position=np.zeros(JOINT_COUNT)))
    harness.execute()
    assert_close(harness[BodyJointTargets].position, np.zeros(JOINT_COUNT), abs=1e-12)
    harness.advance(0.75)  # half way in time: half way by the cosine ramp
    assert_close(harness[BodyJointTargets].position, stand_pose() / 2, abs=1e-9)
    harness.advance(0.75)
    assert_close(harness[BodyJointTargets].position, stand_pose(), abs=1e-12)


@given(JOINTS_WITHIN_LIMITS, st.floats(0.0, 3.0))
def test_the_stand_never_leaves_the_segment_between_start_and_stand(start: np.ndarray, seconds: float) -> None:
    harness = ModuleHarness(StandMotion, JointSensorData(position=start))
    harness.execute()
    harness.advance(max(seconds, 0.01))
    target = harness[BodyJointTargets].position
    low, high = np.minimum(start, stand_pose()), np.maximum(start, stand_pose())
    assert np.all(target >= low - 1e-9) and np.all(target <= high + 1e-9)


def test_the_head_moves_at_most_at_its_speed_and_arrives() -> None:
    harness = ModuleHarness(HeadMotion, HeadMotionRequest(yaw=1.0, pitch=0.0, max_speed=2.0),
                            CognitionStatus(alive=True))
    harness.advance(1.0)
    yaws = [t.yaw for t in harness.history(HeadJointTargets)]
    steps = np.diff(yaws)
    assert np.all(steps <= 2.0 * 0.01 + 1e-9)  # never faster than requested
    assert_close(yaws[-1], 1.0, abs=1e-9)  # and there after half a second of travel


@given(strategy_for(HeadMotionRequest), strategy_for(JointSensorData), st.booleans())
def test_head_targets_stay_within_the_joint_limits_whatever_is_requested(request: HeadMotionRequest, joints: JointSensorData,
                                                                         alive: bool) -> None:
    harness = ModuleHarness(HeadMotion, request, joints, CognitionStatus(alive=alive))
    harness.execute(frames=5)
    for targets in harness.history(HeadJointTargets):
        assert abs(targets.yaw) <= math.radians(119.5) + 1e-9
        assert math.radians(-38.5) - 1e-9 <= targets.pitch <= math.radians(29.5) + 1e-9


def test_the_combinator_takes_the_head_from_the_head_motion_every_frame() -> None:
    body = BodyJointTargets(position=stand_pose(), stiffness=np.full(JOINT_COUNT, 0.9))
    harness = ModuleHarness(MotionCombinator, body)
    harness.feed({HeadJointTargets: [HeadJointTargets(yaw=0.1 * i, pitch=-0.1, stiffness=0.7) for i in range(5)]})
    harness.execute()
    commands = harness.history(JointCommand)
    assert [c.position[HEAD_YAW] for c in commands] == pytest.approx([0.1 * i for i in range(5)])
    assert all(c.stiffness[HEAD_PITCH] == c.stiffness[HEAD_YAW] == 0.7 for c in commands)


@given(strategy_for(BodyJointTargets), strategy_for(HeadJointTargets))
def test_the_command_keeps_every_body_joint_and_stiffness_within_0_and_1(body: BodyJointTargets, head: HeadJointTargets) -> None:
    command = ModuleHarness(MotionCombinator, body, head).execute()[JointCommand]
    others = [i for i in range(JOINT_COUNT) if i not in (HEAD_YAW, HEAD_PITCH)]
    assert np.array_equal(command.position[others], body.position[others])
    assert np.all((command.stiffness >= 0.0) & (command.stiffness <= 1.0))


def test_the_eyes_turn_red_and_the_ears_dark_in_the_frame_cognition_is_lost_and_back_when_it_returns() -> None:
    alive = [True] * 5 + [False] * 5 + [True] * 3
    harness = ModuleHarness(StatusLeds)
    harness.feed({CognitionStatus: [CognitionStatus(alive=a) for a in alive]})
    harness.execute()
    leds = harness.history(LedRequest)
    assert all(np.array_equal(led.left_eye, BLUE_EYE if a else RED_EYE) and led.right_ear.all() == a for led, a in zip(leds, alive))
    assert all(np.array_equal(led.chest, leds[0].chest) for led in leds)  # the chest is the game state's, not cognition's


@given(strategy_for(CognitionStatus))
def test_every_led_value_is_a_brightness_from_0_to_1(status: CognitionStatus) -> None:
    leds = ModuleHarness(StatusLeds, status).execute()[LedRequest]
    for name in ("chest", "left_eye", "right_eye", "left_ear", "right_ear"):
        values = getattr(leds, name)
        assert np.all((values >= 0.0) & (values <= 1.0)), name
