"""The nao platform against a fake LoLA: packets, answers, sensor mapping, safety, errors."""

from __future__ import annotations

import math
import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from tafel.core.logs import read_log
from tafel.core.logs.serialization import deserialize
from tafel.platforms.nao import CROUCH, LolaProtocolError, battery_data, convert_inertial, crouch_pose, parse_sensors, sonar_data
from tafel.representations.motion import JOINT_INDEX, BatteryData, FsrData, InertialSensorData, TouchSensorData
from tafel.representations.obstacles import Obstacles
from tafel.representations.sonar import SONAR_ANGLE, SonarData
from tests.support.fake_lola import KEY_ORDER, PACKET_SIZE, FakeLola, sensor_packet
from tests.test_cli_runtime import REPO

LOOK_LEFT = "tests.support.nao_support:LookLeft"
STAND = "tests.support.motion_requests:ConstantMotionRequest"


def run_nao(socket_path: Path, *args: str, modules: str | None = f'["{LOOK_LEFT}", "{STAND}"]') -> subprocess.CompletedProcess:
    """``tafel run --platform nao`` with what a user gets by default: the debug server and the web view
    (on free ports, so that tests may run side by side); ``modules=None`` keeps the default cognition."""
    chosen = ["--set", f"cognition.modules={modules}"] if modules is not None else []
    command = [sys.executable, "-m", "tafel.tools.cli", "run", "--platform", "nao", "--lola", str(socket_path), "--cameras", "off",
               "--debug-port", "0", "--web-port", "0", *chosen, *args]
    return subprocess.run(command, capture_output=True, text=True, timeout=120, cwd=REPO, env={**os.environ, "PYTHONPATH": str(REPO)})


@pytest.fixture
def lola(tmp_path: Path):
    fake = FakeLola(tmp_path / "robocup")
    yield fake
    fake.close()


def finished(fake: FakeLola) -> None:
    time.sleep(0.2)
    fake.close()


@pytest.mark.slow
def test_the_default_program_runs_both_contexts_with_web_view_debug_server_and_recording(lola: FakeLola, tmp_path: Path) -> None:
    """A user's first command on a robot: the default cognition, web view and debug server on, recording.
    The motion process must not die at start (it once did: the web view's feed named a representation
    that motion's process had never imported)."""
    log = tmp_path / "robot.mcap"
    result = run_nao(lola.path, "--seconds", "3", "--record", str(log), modules=None)
    finished(lola)
    assert result.returncode == 0, result.stderr
    assert "FAILED" not in result.stdout and "failed to start" not in result.stderr, result.stdout + result.stderr
    motion = next(line for line in result.stdout.splitlines() if line.strip().startswith("motion:") and "frames" in line)
    assert int(motion.split("frames")[0].split()[-1]) > 100, motion
    assert {"JointSensorData", "BallModel"} <= {channel.schema_name.split(".")[-1] for channel in read_log(log).channels.values()}


@pytest.mark.slow
def test_every_packet_gets_exactly_one_well_formed_answer(lola: FakeLola, tmp_path: Path) -> None:
    log = tmp_path / "nao.mcap"
    lola.sonar = (0.6, 2.4)  # something 0.6 m away on the left
    result = run_nao(lola.path, "--frames", "200", "--record", str(log),
                     "--record-reps", "InertialSensorData,FsrData,TouchSensorData,BatteryData,SonarData,Obstacles",
                     modules=f'["{LOOK_LEFT}", "{STAND}", "ObstacleModeler"]')
    finished(lola)
    assert result.returncode == 0, result.stderr
    assert "motion: 200 frames" in result.stdout
    assert lola.sizes == {PACKET_SIZE}
    # one answer per packet, through the shutdown too (LoLA may send one more while the client lets go)
    assert lola.sent - len(lola.answers) in (0, 1)
    for answer in lola.answers[:200]:
        assert len(answer["Position"]) == 25 and len(answer["Stiffness"]) == 25
        assert len(answer["Chest"]) == 3 and len(answer["LEye"]) == 24 and len(answer["LEar"]) == 10 and len(answer["Skull"]) == 12
    # sensors arrive in the project's frame and units
    contents = read_log(log)
    inertial = deserialize(InertialSensorData, next(m.data for m in contents.messages if m.topic == "motion/InertialSensorData"))
    assert inertial.accelerometer.tolist() == pytest.approx([-0.1, 0.0, 9.81], abs=1e-5)  # upright: +9.81 on z
    assert inertial.gyroscope[2] == pytest.approx(0.01, abs=1e-6)  # LoLA's sign kept
    assert deserialize(FsrData, next(m.data for m in contents.messages if m.topic == "motion/FsrData")).pressure.tolist() == pytest.approx([0.6] * 8)
    assert deserialize(TouchSensorData, next(m.data for m in contents.messages if m.topic == "motion/TouchSensorData")).pressed.shape == (14,)
    battery = deserialize(BatteryData, next(m.data for m in contents.messages if m.topic == "motion/BatteryData"))
    assert battery.charge == pytest.approx(0.99) and battery.current == pytest.approx(0.016) and battery.charging
    # the sonars: read in motion, filtered there (SonarFilter), walked round in cognition (ObstacleModeler)
    sonar = deserialize(SonarData, next(m.data for m in contents.messages if m.topic == "motion/SonarData"))
    assert sonar.valid and (sonar.left, sonar.right) == pytest.approx((0.6, 2.4), abs=1e-5)
    seen = [deserialize(Obstacles, m.data).obstacles for m in contents.messages if m.topic == "cognition/Obstacles"]
    assert seen and seen[-1], "the echo on the left is no obstacle in cognition"
    ahead = seen[-1][0]
    assert math.hypot(ahead.x, ahead.y) == pytest.approx(600.0, abs=5.0) and math.atan2(ahead.y, ahead.x) == pytest.approx(SONAR_ANGLE)


@pytest.mark.slow
def test_motion_falls_back_to_a_safe_motion_when_cognition_dies(lola: FakeLola) -> None:
    result = run_nao(lola.path, "--frames", "400", "--set", "parameters.CrashCognitionProcess.after_frames=60",
                     modules=f'["{LOOK_LEFT}", "{STAND}", "tests.support.runtime_faults:CrashCognitionProcess"]')
    finished(lola)
    assert result.returncode == 1, result.stderr  # cognition died: the robot stayed safe, and the run failed
    assert "cognition process died (exit code 3)" in result.stderr
    running = [answer for answer in lola.answers if "LEye" in answer]  # the program's answers (not the last crouch's)
    yaws = [answer["Position"][JOINT_INDEX["HeadYaw"]] for answer in running]
    # cognition's health is on the eyes (the chest is the referee's: the game state): blue while it runs, red without
    eyes = ["red" if max(answer["LEye"][:8]) > 0 else "blue" if max(answer["LEye"][16:]) > 0 else "off" for answer in running]
    # Anchored on the frame where motion noticed the loss (the eyes turn red), not on wall-clock timing.
    red_at = eyes.index("red")
    blue = [i for i in range(red_at) if eyes[i] == "blue"]
    assert blue and blue[-1] == red_at - 1  # blue while cognition ran, up to the loss
    assert max(yaws[:red_at]) == pytest.approx(0.5, abs=0.01)  # cognition's request, while it ran
    assert all(e == "red" for e in eyes[red_at:])  # red from then on
    after = [abs(y) for y in yaws[red_at:]]
    assert all(b <= a + 1e-6 for a, b in zip(after, after[1:]))  # the head only moves towards the safe position
    assert len(after) >= 100, "cognition died too late in this run to watch the head come back"
    assert after[-1] < 0.05  # back to the safe position without cognition
    assert lola.sent - len(lola.answers) in (0, 1)


@pytest.mark.slow
def test_the_program_ends_with_a_crouch_that_goes_limp(lola: FakeLola) -> None:
    result = run_nao(lola.path, "--frames", "100")
    finished(lola)
    assert result.returncode == 0, result.stderr
    tail = lola.answers[100:]
    assert len(tail) >= 100  # a second more of answers after the program's last frame
    assert tail[-1]["Stiffness"] == pytest.approx([0.0] * 25)
    assert np.allclose(tail[-1]["Position"], crouch_pose(), atol=1e-5)
    stiffness = [answer["Stiffness"][JOINT_INDEX["LKneePitch"]] for answer in tail]
    assert stiffness[0] > 0.5 and all(a >= b - 1e-6 for a, b in zip(stiffness[len(stiffness) // 2 :], stiffness[len(stiffness) // 2 + 1 :]))


@pytest.mark.slow
def test_malformed_packets_give_a_clear_error_and_a_safe_stop(tmp_path: Path) -> None:
    fake = FakeLola(tmp_path / "robocup", garbage_after=50)
    try:
        result = run_nao(fake.path, "--seconds", "30")
    finally:
        finished(fake)
    assert result.returncode == 1
    assert "malformed LoLA packet" in result.stderr and "Traceback" not in result.stderr
    assert fake.answers[-1]["Stiffness"] == pytest.approx([0.0] * 25)  # it let go limp, once
    assert len(fake.answers) <= 52


@pytest.mark.slow
def test_a_missing_socket_is_a_clear_error(tmp_path: Path) -> None:
    result = run_nao(tmp_path / "nothing-here")
    assert result.returncode == 1
    assert f"LoLA's socket {tmp_path / 'nothing-here'} does not exist: is lola running" in result.stderr
    assert "Traceback" not in result.stderr


@pytest.mark.slow
def test_missing_cameras_are_a_clear_error(lola: FakeLola) -> None:
    command = [sys.executable, "-m", "tafel.tools.cli", "run", "--platform", "nao", "--lola", str(lola.path), "--no-debug",
               "--camera-top", "/dev/no-such-camera"]
    result = subprocess.run(command, capture_output=True, text=True, timeout=60, cwd=REPO, env={**os.environ, "PYTHONPATH": str(REPO)})
    assert result.returncode == 1 and "the top camera /dev/no-such-camera does not exist" in result.stderr


def test_sensor_packets_are_checked() -> None:
    import msgpack

    good = msgpack.unpackb(sensor_packet([0.0] * 25, [0.0] * 25, 0))
    assert parse_sensors(good)["Position"].shape == (25,)
    with pytest.raises(LolaProtocolError, match="expected a map"):
        parse_sensors([1, 2, 3])
    broken = dict(good, Position=[0.0] * 24)
    with pytest.raises(LolaProtocolError, match="Position should hold 25 numbers, found 24 values"):
        parse_sensors(broken)
    with pytest.raises(LolaProtocolError, match="FSR holds something that is not a number"):
        parse_sensors(dict(good, FSR=["x"] * 8))
    assert set(CROUCH) <= set(JOINT_INDEX)


# Two real LoLA packets (shared/reference/robocup.md): nao_lola's parser test, and NaoTH's LolaData.h
# (a robot sitting and leaning forward). Accelerometer as LoLA sends it, and LoLA's own Angles.
REAL_PACKETS = [((-3.0656, -0.3928, -9.3214), (0.03758, -0.35991)), ((8.66997, 0.287402, -5.48939), (-0.0239685, 0.990951))]


@pytest.mark.parametrize(("accelerometer", "angles"), REAL_PACKETS)
def test_accelerometer_roll_and_pitch_have_the_signs_of_lolas_own_angles(accelerometer, angles) -> None:
    inertial = convert_inertial(np.array(accelerometer), np.zeros(3), np.array(angles))
    ax, ay, az = inertial.accelerometer
    roll, pitch = math.atan2(ay, az), math.atan2(-ax, math.hypot(ay, az))
    assert math.copysign(1, roll) == math.copysign(1, angles[0])
    assert math.copysign(1, pitch) == math.copysign(1, angles[1])
    assert pitch == pytest.approx(angles[1], abs=0.1)


def test_upright_reads_plus_g_on_z_and_the_gyroscope_keeps_lolas_signs() -> None:
    inertial = convert_inertial(np.array([0.0, 0.0, -9.81]), np.array([0.1, -0.2, 0.3]), np.zeros(2))
    assert inertial.accelerometer[2] == pytest.approx(9.81)
    assert list(inertial.gyroscope) == pytest.approx([0.1, -0.2, 0.3])


def test_the_fake_lola_sends_real_packets() -> None:
    import msgpack

    data = sensor_packet([0.0] * 25, [0.0] * 25, 3)
    assert len(data) == 896
    packet = msgpack.unpackb(data)
    assert tuple(packet) == KEY_ORDER  # the real key order
    assert [len(packet["RobotConfig"][0]), len(packet["RobotConfig"][2])] == [20, 20]
    assert parse_sensors(packet)["Accelerometer"][2] == pytest.approx(-9.81)


@pytest.mark.slow
def test_answers_carry_sonar_on_and_every_led(lola: FakeLola) -> None:
    result = run_nao(lola.path, "--frames", "50")
    finished(lola)
    assert result.returncode == 0, result.stderr
    normal = [a for a in lola.answers if "LEye" in a]
    assert normal and all(a["Sonar"] == [True, True] for a in normal)


def test_the_battery_reads_a_real_packet_in_the_order_the_teams_read_it() -> None:
    """NaoTH's LolaData.h quotes a real robot's packet: ``"Battery":[0.99,-32552,0.016,3.6]``. B-Human,
    HULKs and NaoTH read it as charge, status, current, temperature; the status is the board's flags
    (0x80D8 as a 16-bit value: bit 0x80, charging, is set) and the temperature stays near 3 on robots."""
    battery = battery_data([0.99, -32552.0, 0.016, 3.6])
    assert battery.charge == pytest.approx(0.99)
    assert battery.status == -32552 and battery.charging
    assert battery.current == pytest.approx(0.016)
    assert battery.temperature == pytest.approx(3.6)
    assert not battery_data([0.5, 0.0, -1.2, 3.0]).charging


def test_the_sonars_are_read_where_a_packet_holds_them_and_only_then() -> None:
    """LoLA's ``Sonar`` (left, right in m) as ``SonarData``; a packet without it (or with something else
    there) still drives the robot, with no sonar reading."""
    import msgpack

    good = msgpack.unpackb(sensor_packet([0.0] * 25, [0.0] * 25, 0, sonar=(0.45, 5.0)))
    sonar = sonar_data(parse_sensors(good))
    assert sonar.valid and (sonar.left, sonar.right) == pytest.approx((0.45, 5.0), abs=1e-6)
    for broken in ({k: v for k, v in good.items() if k != "Sonar"}, dict(good, Sonar=[0.4]), dict(good, Sonar=["x", 1.0])):
        assert not sonar_data(parse_sensors(broken)).valid
