"""The simulator platforms and the first pipeline: standing, seeing the ball, tracking it with the head.

Every behaviour test runs on both engines with the same thresholds: the proof that the platform
interface holds is that the same program passes the same tests on both.
"""

from __future__ import annotations

import math
import os
import re
import subprocess
import sys

import numpy as np
import pytest

from tafel.core.runtime.platform import PlatformOptionError
from tafel.core.testing import ModuleHarness
from tafel.modules.motion.camera_matrix_provider import CameraMatrixProvider
from tafel.modules.perception.ball_detector import BallDetector
from tafel.modules.perception.ball_locator import BallLocator
from tafel.representations.modeling import BallModel
from tafel.representations.motion import (
    HEAD_YAW,
    CameraMatrixBottom,
    CameraMatrixBuffer,
    CameraMatrixTop,
    InertialModel,
    InertialSensorData,
    JointSensorData,
)
from tafel.representations.perception import BallCandidate, BallImagePercept, BallPercept, CameraImageBottom, CameraImageTop
from tests.support.simulation import Simulation
from tests.test_cli_runtime import REPO, frames, tafel

NO_GLANCES = ["parameters.LookAtBallBehavior.glance_interval=1000", "parameters.LookAtBallBehavior.glance_interval_lost=1000"]
STANDING_TORSO_HEIGHT = 250.0  # mm: a fallen robot's torso is below 150
ENGINES = ["mujoco", "pybullet"]


@pytest.fixture(params=ENGINES)
def engine(request) -> str:
    return request.param


@pytest.fixture
def sim(engine: str):
    """The default scene on one engine."""
    simulation = Simulation(engine)
    yield simulation
    simulation.close()


def simulation(engine: str, **options: str) -> Simulation:
    return Simulation(engine, **options)


@pytest.mark.slow
def test_the_robot_stands_for_20_seconds(engine: str) -> None:
    sim = simulation(engine, cameras="off")
    try:
        _stands(sim)
    finally:
        sim.close()


def _stands(sim: Simulation) -> None:
    heights: list[float] = []
    sim.run(20.0, lambda s: heights.append(s.platform.torso_height()))
    assert min(heights) > STANDING_TORSO_HEIGHT, min(heights)
    assert heights[-1] == pytest.approx(heights[-500], abs=1.0)  # settled, not sinking
    roll, pitch = sim.platform.torso_angles()
    assert abs(roll) < 0.05 and abs(pitch) < 0.1


def head_yaw_error(sim: Simulation) -> float:
    """Degrees between where the head points and where the ball is (seen from the robot)."""
    yaw = sim.blackboard("motion")[JointSensorData].position[HEAD_YAW]
    x, y = sim.platform.ball_in_robot_frame()
    return abs(math.degrees(yaw - math.atan2(y, x)))


def model_distance_error(sim: Simulation) -> float:
    """Relative error of the ball model's distance against the true distance."""
    model = sim.blackboard("cognition")[BallModel]
    x, y = sim.platform.ball_in_robot_frame()
    return abs(math.hypot(model.x, model.y) - math.hypot(x, y)) / math.hypot(x, y)


@pytest.mark.slow
def test_the_head_tracks_the_ball_and_follows_when_it_moves(engine: str) -> None:
    # tracking alone: no glances round for the localization (tests/test_behavior_glances.py has those)
    sim = Simulation(engine, overrides=NO_GLANCES, ball="1500,500")
    try:
        _tracks(sim)
    finally:
        sim.close()


def _tracks(sim: Simulation) -> None:
    sim.run(3.0)
    assert sim.blackboard("cognition")[BallModel].valid
    assert head_yaw_error(sim) < 5.0
    assert model_distance_error(sim) < 0.10
    sim.platform.move_ball(1500, -500)
    sim.run(2.0)
    assert head_yaw_error(sim) < 5.0
    assert sim.blackboard("cognition")[BallModel].y < 0
    assert sim.platform.torso_height() > STANDING_TORSO_HEIGHT


@pytest.mark.parametrize(
    ("ball", "camera"),
    [((700.0, 0.0), "top"), ((1500.0, 400.0), "top"), ((2500.0, -500.0), "top"), ((250.0, 60.0), "bottom")],
)
@pytest.mark.slow
def test_detector_finds_the_ball_in_rendered_images(engine: str, ball: tuple[float, float], camera: str) -> None:
    sim = simulation(engine, ball=f"{ball[0]},{ball[1]}", ball_color="orange")
    try:
        sim.run(1.5)  # stand up first, so the cameras are where the stand puts them
        sim.platform.move_ball(*ball)
        sim.run(0.1)
        motion, cognition = sim.blackboard("motion"), sim.blackboard("cognition")
        # the detector alone, on what the platform rendered and the kinematics computed
        matrices = ModuleHarness(CameraMatrixProvider, motion[JointSensorData], InertialModel(roll=motion[InertialSensorData].angles[0],
                                                                                                 pitch=motion[InertialSensorData].angles[1])).execute()
        candidates = ModuleHarness(BallDetector, cognition[CameraImageTop], cognition[CameraImageBottom]).execute()[BallImagePercept]
        buffer = CameraMatrixBuffer.of(matrices[CameraMatrixTop], matrices[CameraMatrixBottom])
        percept = ModuleHarness(BallLocator, candidates, buffer).execute()[BallPercept]
        truth = sim.platform.ball_in_robot_frame()
        assert percept.seen and percept.camera == camera
        distance = math.hypot(*truth)
        assert math.hypot(percept.x - truth[0], percept.y - truth[1]) < max(40.0, 0.05 * distance)
        assert percept.radius > 1.0
    finally:
        sim.close()


@pytest.mark.slow
def test_no_ball_in_view_no_percept(sim: Simulation) -> None:
    sim.platform.move_ball(-2000, 0)  # behind the robot
    sim.run(0.5)
    assert not sim.blackboard("cognition")[BallPercept].seen


def test_detector_rejects_orange_that_is_not_a_ball() -> None:
    image = CameraImageTop(horizontal_fov=math.radians(56.3), vertical_fov=math.radians(43.7))
    image.image = np.zeros((240, 320, 3), np.uint8)
    image.image[:, :] = (40, 140, 50)
    image.image[100:104, 20:300] = (255, 107, 0)  # an orange stripe: not round
    bb = ModuleHarness(BallDetector, image, CameraImageBottom(image=np.zeros((0, 0, 3), np.uint8))).execute()
    assert bb[BallImagePercept].candidates == []


def test_locator_rejects_a_ball_whose_size_does_not_fit_its_distance() -> None:
    matrix = CameraMatrixTop(valid=True, translation=np.array([0.0, 0.0, 500.0]))
    matrix.rotation = np.array([[math.cos(0.3), 0, math.sin(0.3)], [0, 1, 0], [-math.sin(0.3), 0, math.cos(0.3)]])
    fov = (math.radians(56.3), math.radians(43.7))
    huge = BallCandidate("top", 160.0, 150.0, 60.0, 0.9, 320, 240, *fov)  # at about 1.4 m a ball is ~17 px
    assert not ModuleHarness(BallLocator, BallImagePercept([huge]), CameraMatrixBuffer.of(matrix, matrix)).execute()[BallPercept].seen
    fitting = BallCandidate("top", 160.0, 150.0, 17.0, 0.9, 320, 240, *fov)
    assert ModuleHarness(BallLocator, BallImagePercept([fitting]), CameraMatrixBuffer.of(matrix, matrix)).execute()[BallPercept].seen


@pytest.mark.slow
def test_images_have_the_published_field_of_view(sim: Simulation) -> None:
    sim.run(0.1)
    image = sim.blackboard("cognition")[CameraImageTop]
    assert image.image.shape == (240, 320, 3) and image.image.dtype == np.uint8
    assert math.degrees(image.vertical_fov) == pytest.approx(43.7)
    assert math.degrees(image.horizontal_fov) == pytest.approx(56.3, abs=0.2)
    assert image.image.std() > 5  # something was rendered


@pytest.mark.slow
def test_sensors_have_the_projects_units(sim: Simulation) -> None:
    sim.run(2.0)
    motion = sim.blackboard("motion")
    assert motion[InertialSensorData].accelerometer[2] == pytest.approx(9.81, abs=0.5)  # upright
    from tafel.representations.motion import FsrData

    total_kg = motion[FsrData].pressure.sum()
    assert total_kg == pytest.approx(5.36, rel=0.15)  # the robot's weight on its soles


@pytest.mark.slow
def test_debug_commands_move_things_and_pause_physics(sim: Simulation) -> None:
    commands = sim.platform.commands()
    assert commands["sim:move_ball"][1]({"x": "2000", "y": "-300"}) == "ball at x=2000 y=-300 mm"
    assert sim.platform.ball_position() == pytest.approx((2000.0, -300.0))
    commands["sim:pause"][1]({})
    sim.run(0.2)
    assert sim.platform.last_steps == 0
    commands["sim:resume"][1]({})
    sim.run(0.2)
    assert sim.platform.last_steps == 5
    commands["sim:move_robot"][1]({"x": "500", "y": "0", "rotation": "1.0"})
    assert sim.platform.robot_pose()[2] == pytest.approx(1.0, abs=1e-6)
    assert "ball x=2000" in commands["sim:status"][1]({})


@pytest.mark.slow
def test_runs_are_deterministic(engine: str) -> None:
    runs = [tafel("run", "--platform", engine, "--no-debug", "--frames", "150", "--speed", "max") for _ in range(2)]
    assert runs[0].returncode == 0, runs[0].stderr
    fingerprints = [re.findall(r"^fingerprint \w+", run.stdout, re.MULTILINE) for run in runs]
    assert fingerprints[0] == fingerprints[1] and len(fingerprints[0]) == 1
    assert frames(runs[0].stdout) == {"cognition": 45, "motion": 150}


@pytest.mark.slow
def test_tafel_run_without_arguments_runs_the_simulator_with_the_debug_server() -> None:
    process = subprocess.Popen([sys.executable, "-m", "tafel.tools.cli", "run", "--seconds", "3", "--status-interval", "1"],
                               cwd=REPO, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                               env={**os.environ, "PYTHONPATH": str(REPO)})
    out, err = process.communicate(timeout=120)
    assert process.returncode == 0, err
    assert re.search(r"debug server listening on 127\.0\.0\.1:\d+", out) or "running without the debug server" in err
    assert "platform mujoco (lockstep)" in out
    assert re.search(r"ball seen at x=\d+ y=\d+ mm", err), err


@pytest.mark.slow
def test_viewer_without_a_display_says_so_and_runs_headless(engine: str) -> None:
    env = {k: v for k, v in os.environ.items() if k not in ("DISPLAY", "WAYLAND_DISPLAY")}
    result = subprocess.run([sys.executable, "-m", "tafel.tools.cli", "run", "--platform", engine, "--viewer", "--frames", "20", "--speed", "max", "--no-debug"],
                            cwd=REPO, capture_output=True, text=True, timeout=120, env={**env, "PYTHONPATH": str(REPO)})
    assert result.returncode == 0, result.stderr
    assert "--viewer needs a display" in result.stderr


@pytest.mark.slow
def test_concurrent_is_refused_with_a_reason(engine: str) -> None:
    result = tafel("run", "--platform", engine, "--concurrent", "--frames", "10", "--no-debug")
    assert result.returncode == 1 and "run it without --concurrent" in result.stderr


@pytest.mark.slow
def test_debug_commands_reach_the_platform_through_the_server(engine: str) -> None:
    from tests.test_debug_server import Program

    program = Program("--platform", engine, "--cameras", "off")
    try:
        assert program.ask("sim:move_ball -x 2000 -y -300") == "ball at x=2000 y=-300 mm"
        assert "ball x=2000 y=-300 mm" in program.ask("sim:status")
        assert program.ask("sim:move_ball -x far").startswith("error: sim:move_ball failed")
    finally:
        program.stop()


@pytest.mark.slow
@pytest.mark.parametrize("engine", ["mujoco", "pybullet"])
def test_a_ball_can_start_rolling_and_the_sensor_noise_can_be_scaled(engine: str) -> None:
    sim = Simulation(engine, cameras="off", ball="-2000,2000", ball_velocity="1000,-500", sensor_noise="0")
    try:
        sim.run(0.5)
        x, y = sim.platform.ball_position()
        dx, dy = x + 2000.0, y - 2000.0
        assert abs(math.degrees(math.atan2(dy, dx) - math.atan2(-500.0, 1000.0))) < 5.0  # the way it was sent
        assert 0.5 * 1118.0 * 0.5 < math.hypot(dx, dy) < 1118.0 * 0.5  # rolling and slowing down (1118 mm/s at the start)
        joints = sim.blackboard("motion")[JointSensorData].position
        np.testing.assert_array_equal(joints, sim.platform.joint_angles())  # no noise at all with factor 0
    finally:
        sim.close()


@pytest.mark.parametrize(("option", "value", "message"), [
    ("ball_velocity", "fast", "--ball-velocity takes VX,VY in mm/s, at most 10000 mm/s fast, e.g. 500,0, got 'fast'"),
    ("ball_velocity", "20000,0", "--ball-velocity takes VX,VY in mm/s, at most 10000 mm/s fast, e.g. 500,0, got '20000,0'"),
    ("sensor_noise", "nan", "--sensor-noise takes a factor from 0 to 100 (1: the NAO's noise, 0: none), got 'nan'"),
    ("sensor_noise", "-1", "--sensor-noise takes a factor from 0 to 100"),
])
def test_bad_ball_velocities_and_noise_factors_say_what_would_be_right(option: str, value: str, message: str) -> None:
    from tafel.core.runtime.platform import PlatformOptionError, load_platform

    with pytest.raises(PlatformOptionError) as error:
        load_platform("mujoco")({option: value})
    assert message in str(error.value)


# ------------------------------------------------------------------------- the first minutes (issue 28)
class World:
    """A bare simulated world (no program): put the ball, let the physics run, ask where the ball is."""

    def __init__(self, engine: str) -> None:
        self.match = engine == "match"
        if self.match:
            from tafel.platforms.match_world import MatchWorld

            self.world = MatchWorld([(-1500.0, 0.0)])
        else:
            from tafel.core.runtime.platform import load_platform

            self.world = load_platform(engine)({"cameras": "off", "start": "-1500,0,0"})
            self.world.start(frozenset({"motion"}))

    def shoot(self, x: float, y: float, velocity: tuple[float, float]) -> None:
        if self.match:
            self.world.ball.place(self.world.data, x, y, velocity)
        else:
            self.world.move_ball(x, y, velocity)

    def run(self, seconds: float) -> None:
        if self.match:
            self.world.step_to(self.world.time_ns + int(seconds * 1e9))
        else:
            self.world.step_physics(int(round(seconds / 0.002)))

    def ball(self) -> tuple[float, float]:
        return self.world.ball_position()

    def close(self) -> None:
        if not self.match:
            self.world.stop()


@pytest.mark.slow
@pytest.mark.parametrize("engine", [*ENGINES, "match"])
def test_a_ball_shot_into_either_goal_stops_in_its_net(engine: str) -> None:
    from tafel.representations.field import BALL_RADIUS, GOAL_DEPTH, GOAL_INNER_WIDTH, LENGTH

    world = World(engine)
    try:
        # straight at the back net, and slanted into each side net, as fast as a strong kick and faster
        for sign in (1.0, -1.0):
            for angle, speed in ((0.0, 8000.0), (40.0, 5000.0), (-40.0, 5000.0), (0.0, 10000.0)):
                velocity = (sign * speed * math.cos(math.radians(angle)), speed * math.sin(math.radians(angle)))
                world.shoot(sign * 3800.0, 0.0, velocity)
                deepest = 0.0
                for _ in range(60):  # 3 s
                    world.run(0.05)
                    deepest = max(deepest, sign * world.ball()[0])
                end = world.ball()
                shot = f"{engine}: shot at {velocity} mm/s from ({sign * 3800:.0f}, 0) ended at {end}, deepest {deepest:.0f}"
                assert deepest < LENGTH / 2 + GOAL_DEPTH, shot  # never through the net
                assert LENGTH / 2 + BALL_RADIUS < sign * end[0] and abs(end[1]) < GOAL_INNER_WIDTH / 2, shot  # in the goal
                world.run(0.2)
                assert math.dist(end, world.ball()) < 5.0, shot + ": still rolling"
    finally:
        world.close()


@pytest.mark.slow
def test_importing_pybullet_prints_nothing() -> None:
    result = subprocess.run([sys.executable, "-c", "import tafel.platforms.pybullet_sim; print('imported')"],
                            cwd=REPO, capture_output=True, text=True, timeout=120, env={**os.environ, "PYTHONPATH": str(REPO)})
    assert result.returncode == 0, result.stderr
    assert result.stdout == "imported\n"
    assert "build time" not in result.stderr


@pytest.mark.slow
@pytest.mark.parametrize(("engine", "ball", "velocity", "goal"), [
    ("mujoco", "3800,200", "3000,0", r"GOAL for the robot's team \(the ball is in the opponent goal\): score 1:0"),
    ("pybullet", "-3800,-200", "-3000,0", r"GOAL against the robot's team \(the ball is in its own goal\): score 0:1"),
])
def test_tafel_run_says_goal_with_the_score(engine: str, ball: str, velocity: str, goal: str) -> None:
    result = tafel("run", "--platform", engine, "--no-debug", "--cameras", "off", "--seconds", "3", "--speed", "max",
                   "--ball", ball, "--ball-velocity", velocity)
    assert result.returncode == 0, result.stderr
    lines = [line for line in result.stderr.splitlines() if "GOAL" in line]
    assert len(lines) == 1 and re.search(goal, lines[0]) and lines[0].startswith(f"[tafel] {engine} t="), result.stderr


@pytest.mark.slow
def test_move_robot_explains_the_mirrored_pose_and_resets_the_localization_when_asked() -> None:
    from tafel.debug.protocol import parse
    from tafel.representations.modeling import RobotPose

    sim = Simulation("mujoco", start="-1500,0,0")
    try:
        sim.run(1.0)
        move = sim.platform.commands()["sim:move_robot"][1]
        answer = move(parse("sim:move_robot -x 2000 -y 500 -rotation 0.5").args)
        assert "(x=-2000 y=-500 mm, rotation -2.642 rad looks alike)" in answer and "-reset on" in answer, answer
        assert "starts anew" in move(parse("sim:move_robot -x 2000 -y 500 -rotation 0.5 -reset on").args)

        def error() -> tuple[float, float]:
            pose, (x, y, heading) = sim.blackboard("cognition")[RobotPose], sim.platform.robot_pose()
            return math.hypot(pose.x - x, pose.y - y), abs(math.remainder(pose.rotation - heading, math.tau))

        sim.run(0.1)  # three cognition frames
        assert sim.blackboard("cognition")[RobotPose].valid
        distance, angle = error()
        assert distance < 100.0 and angle < 0.1, (distance, angle)
        sim.run(3.0)  # and it stays there: continuity, not the own half
        distance, angle = error()
        assert distance < 300.0 and angle < 0.2, (distance, angle)
        with pytest.raises(PlatformOptionError, match="-reset takes on/off or true/false, got 'maybe'"):
            move({"x": "0", "reset": "maybe"})
    finally:
        sim.close()
