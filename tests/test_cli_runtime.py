"""``tafel`` as a user runs it: subprocesses, real signals, the concurrent runtime's processes."""

from __future__ import annotations

import os
import re
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parent.parent
TAFEL = [sys.executable, "-m", "tafel.tools.cli"]


def tafel(*args: str, timeout: float = 120) -> subprocess.CompletedProcess:
    env = {**os.environ, "PYTHONPATH": str(REPO)}
    return subprocess.run([*TAFEL, *args], capture_output=True, text=True, timeout=timeout, cwd=REPO, env=env)


def dummy(*args: str, timeout: float = 120) -> subprocess.CompletedProcess:
    """``tafel run`` on the dummy platform, without the debug server: the runtime alone."""
    return tafel("run", "--platform", "dummy", "--no-debug", *args, timeout=timeout)


def frames(output: str) -> dict[str, int]:
    return {name: int(n) for name, n in re.findall(r"^  (\w+): (\d+) frames", output, re.MULTILINE)}


@pytest.mark.slow
def test_dummy_run_gives_frame_counts_matching_the_rates() -> None:
    result = dummy("--frames", "1000", "--speed", "max")
    assert result.returncode == 0, result.stderr
    assert frames(result.stdout) == {"cognition": 300, "motion": 1000}
    assert "platform dummy (lockstep): ran 10.000 s of platform time" in result.stdout


@pytest.mark.slow
def test_dummy_runs_are_deterministic() -> None:
    first = dummy("--frames", "500", "--speed", "max", "--seed", "3")
    second = dummy("--frames", "500", "--speed", "max", "--seed", "3")
    other_seed = dummy("--frames", "500", "--speed", "max", "--seed", "4")
    assert first.returncode == second.returncode == 0

    def without_wall_time(text: str) -> str:
        return "\n".join(line for line in text.splitlines() if not line.startswith("wall time"))

    assert without_wall_time(first.stdout) == without_wall_time(second.stdout)
    assert "fingerprint " in first.stdout
    assert without_wall_time(other_seed.stdout) != without_wall_time(first.stdout)  # the digest depends on the data


@pytest.mark.slow
def test_rates_come_from_configuration() -> None:
    result = dummy("--frames", "200", "--speed", "max", "--set", "runtime.cognition_hz=10", "--set", "runtime.motion_hz=50")
    assert result.returncode == 0, result.stderr
    assert frames(result.stdout) == {"cognition": 40, "motion": 200}


@pytest.mark.slow
def test_seconds_limit_uses_platform_time() -> None:
    result = dummy("--seconds", "2", "--speed", "max")
    assert result.returncode == 0, result.stderr
    assert frames(result.stdout) == {"cognition": 60, "motion": 200}


@pytest.mark.slow
@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["run", "--platform", "dumy"], "unknown platform 'dumy': did you mean 'dummy'"),
        (["run", "--set", 'cognition.modules=["KalmanBallModeller"]'], "did you mean 'KalmanBallModeler'"),
        (["run", "--speed", "fast"], "--speed takes a factor from 0.001 to 1000 or 'max'"),
        (["run", "--frames", "0"], "argument --frames: takes a whole number above 0, got '0'"),
        (["run", "--frames", "3", "--seconds", "2"], "not allowed with argument"),
        (["run", "--platform", "dummy", "--bogus"], "unrecognized arguments: --bogus; options of platform dummy: --seed"),
        (["run", "--set", "nonsense"], "--set takes KEY=VALUE"),
        (["run", "--config", "/nonexistent"], "configuration folder /nonexistent does not exist"),
        (["modules", "--set", 'cognition.providers.BallModel="Nope"'], "unknown module 'Nope'"),
        (["launch"], "invalid choice: 'launch'"),
    ],
)
def test_wrong_names_and_arguments_exit_2_with_advice(args: list[str], message: str) -> None:
    result = tafel(*args)
    assert result.returncode == 2, result.stdout + result.stderr
    assert message in result.stderr
    assert "Traceback" not in result.stderr


@pytest.mark.slow
def test_platforms_lists_what_each_provides_and_consumes() -> None:
    result = tafel("platforms")
    assert result.returncode == 0
    assert "dummy: deterministic clock" in result.stdout
    assert "motion: provides JointSensorData, InertialSensorData, FsrData, TouchSensorData; consumes JointCommand" in result.stdout
    assert "consumes GameControllerReturn, OutgoingTeamMessage" in result.stdout
    verbose = tafel("platforms", "--verbose")
    assert "option --seed: dummy: seed of the synthetic sensor noise" in verbose.stdout
    assert "option --lola: nao: LoLA's Unix socket" in verbose.stdout


def test_modules_shows_order_providers_and_hand_overs() -> None:
    result = tafel("modules", "--platform", "dummy")
    assert result.returncode == 0, result.stderr
    out = result.stdout
    assert ("order: InertialFilter -> ChestButtonProvider -> CameraMatrixProvider -> CameraMatrixBufferProvider -> FallDetector -> MotionSelector -> "
            "StandMotion -> WalkingEngine -> KeyframePlayer -> HeadMotion -> MotionCombinator -> StatusLeds") in out
    assert "provider BallModel: KalmanBallModeler (alternatives: SimpleBallModeler)" in out
    assert "hand-over in: HeadMotionRequest from cognition" in out
    assert "hand-over out: HeadMotionRequest to motion" in out
    assert "from runtime: FrameInfo, CognitionStatus\n" in out and "from runtime: FrameInfo\n" in out  # motion's, cognition's
    assert "from platform: JointSensorData, InertialSensorData" in out


def test_modules_dot_has_both_contexts_and_the_hand_over() -> None:
    result = tafel("modules", "--platform", "dummy", "--dot")
    assert result.returncode == 0, result.stderr
    assert 'subgraph "cluster_cognition"' in result.stdout and 'subgraph "cluster_motion"' in result.stdout
    assert '"cognition:HeadMotionRequest" -> "motion:HeadMotionRequest"' in result.stdout


@pytest.mark.slow
def test_module_exceptions_are_counted_and_the_loop_goes_on() -> None:
    result = dummy("--frames", "100", "--speed", "max", "--set",
                   'cognition.modules=["KalmanBallModeler", "LookAtBallBehavior", "Striker", "tests.support.runtime_faults:RaiseEveryFrame"]')
    assert result.returncode == 0, result.stderr
    assert frames(result.stdout) == {"cognition": 30, "motion": 100}
    assert "module errors: RaiseEveryFrame 30" in result.stdout
    assert "deliberate failure in frame 1" in result.stderr and "Traceback" in result.stderr


@pytest.mark.slow
@pytest.mark.parametrize("concurrent", [False, True])
def test_sigint_and_sigterm_shut_down_cleanly(concurrent: bool) -> None:
    args = [*TAFEL, "run", "--platform", "dummy", "--no-debug", "--status-interval", "0.3"] + (["--concurrent"] if concurrent else [])
    for sig in (signal.SIGINT, signal.SIGTERM):
        process = subprocess.Popen(args, cwd=REPO, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                                   env={**os.environ, "PYTHONPATH": str(REPO)})
        try:
            deadline = time.monotonic() + 60
            line = ""
            while "[tafel]" not in line and time.monotonic() < deadline:
                line = process.stderr.readline()
            assert "[tafel]" in line, "no status line before the signal"
            process.send_signal(sig)
            out, err = process.communicate(timeout=30)
        finally:
            process.kill()
        assert process.returncode == 0, err
        counts = frames(out)
        assert counts.get("motion", 0) > 0 and counts.get("cognition", 0) > 0, out
        assert "Traceback" not in err


def run_concurrent_fault(module: str, seconds: str, motion_frames: int) -> subprocess.CompletedProcess:
    return dummy(
        "--concurrent", "--frames", str(motion_frames),
        "--set", f'cognition.modules=["KalmanBallModeler", "LookAtBallBehavior", "Striker", "tests.support.runtime_faults:{module}"]',
        "--set", f"parameters.{module}.after_frames=20",
        *(["--set", f"parameters.{module}.stall={seconds}"] if module == "StallCognition" else []),
        timeout=120,
    )


def summary_value(output: str, name: str) -> int:
    match = re.search(rf"{name}=(\d+)", output)
    assert match, output
    return int(match.group(1))


@pytest.mark.slow
def test_motion_keeps_running_when_cognition_crashes() -> None:
    result = run_concurrent_fault("CrashCognitionProcess", "0", 400)
    assert result.returncode == 1, result.stderr  # a context that died is a failure of the program
    assert "cognition process died (exit code 3)" in result.stderr
    assert re.search(r"cognition: \d+ frames, .*FAILED: process died \(exit code 3\)", result.stdout), result.stdout
    assert frames(result.stdout)["motion"] == 400
    assert summary_value(result.stdout, "frames_without_cognition") > 0


@pytest.mark.slow
def test_motion_sees_a_stalled_cognition_and_its_return() -> None:
    result = run_concurrent_fault("StallCognition", "2.0", 500)
    assert result.returncode == 0, result.stderr
    assert frames(result.stdout)["motion"] == 500
    without = summary_value(result.stdout, "frames_without_cognition")
    assert without > 0  # a 2 s stall outlasts the 1 s timeout: motion saw cognition as gone
    assert frames(result.stdout)["cognition"] > 20  # and then back
    # the baseline in the same test: a stall shorter than the timeout is never taken for a loss
    short = run_concurrent_fault("StallCognition", "0.3", 300)
    assert short.returncode == 0 and summary_value(short.stdout, "frames_without_cognition") == 0, short.stdout


@pytest.mark.slow
def test_a_stuck_module_cannot_keep_the_program_from_stopping() -> None:
    process = subprocess.Popen(
        [*TAFEL, "run", "--platform", "dummy", "--no-debug", "--set", "runtime.shutdown_grace_s=1",
         "--set", 'cognition.modules=["KalmanBallModeler", "LookAtBallBehavior", "Striker", "tests.support.runtime_faults:StuckForever"]'],
        cwd=REPO, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env={**os.environ, "PYTHONPATH": str(REPO)},
    )
    time.sleep(3)  # well inside the stuck frame
    process.send_signal(signal.SIGTERM)
    out, err = process.communicate(timeout=30)
    assert process.returncode != 0
    assert "every thread's stack is dumped" in err
    assert "StuckForever" not in out and "runtime_faults.py" in err  # the dump shows where it was stuck


def child_pids(pid: int) -> list[int]:
    """Processes whose parent is ``pid`` (from /proc)."""
    found = []
    for entry in Path("/proc").iterdir():
        if entry.name.isdigit():
            try:
                fields = (entry / "stat").read_text().rsplit(")", 1)[1].split()
            except OSError:
                continue
            if int(fields[1]) == pid:
                found.append(int(entry.name))
    return found


def cmdline(pid: int) -> str:
    try:
        return Path(f"/proc/{pid}/cmdline").read_text()
    except OSError:
        return ""


def alive(pid: int) -> bool:
    try:
        state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except OSError:
        return False
    return state != "Z"


@pytest.mark.slow
def test_concurrent_stop_with_a_stuck_cognition_ends_every_process_after_the_grace_period() -> None:
    process = subprocess.Popen(
        [*TAFEL, "run", "--platform", "dummy", "--concurrent", "--frames", "150", "--no-debug", "--set", "runtime.shutdown_grace_s=2",
         "--set", 'cognition.modules=["KalmanBallModeler", "LookAtBallBehavior", "Striker", "tests.support.runtime_faults:StuckForever"]'],
        cwd=REPO, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env={**os.environ, "PYTHONPATH": str(REPO)},
    )
    children: list[int] = []
    deadline = time.monotonic() + 20.0  # a loaded machine may take seconds to start the context processes
    while len(children) < 3 and process.poll() is None and time.monotonic() < deadline:  # the resource tracker and two contexts
        time.sleep(0.05)
        children = child_pids(process.pid)
    out, err = process.communicate(timeout=40)  # before the fix: a hang until killed
    assert process.returncode == 1, err
    assert "cognition process did not stop within 2 s" in err
    assert "runtime_faults.py" in err  # the stuck process's stacks were dumped
    assert "motion: 150 frames" in out
    assert children
    # multiprocessing's resource tracker ends on its own once the pipe from its parent closes: give it
    # a moment; a context process left behind would still be running after it
    deadline = time.monotonic() + 5.0
    while [pid for pid in children if alive(pid)] and time.monotonic() < deadline:
        time.sleep(0.05)
    assert not [(pid, cmdline(pid)) for pid in children if alive(pid)]


@pytest.mark.slow
@pytest.mark.parametrize("recording_s", [0.0, 1.0], ids=["while-starting", "while-recording"])
def test_context_processes_stop_when_the_supervisor_is_killed(tmp_path: Path, recording_s: float) -> None:
    """Killed at once, the supervisor dies while its context processes still import: they must not mistake whoever
    adopted them for their supervisor (they did, and ran on for ever)."""
    process = subprocess.Popen(
        [*TAFEL, "run", "--platform", "dummy", "--concurrent", "--no-debug", "--record", str(tmp_path / "orphan.mcap")],
        cwd=REPO, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env={**os.environ, "PYTHONPATH": str(REPO)},
    )
    deadline = time.monotonic() + 20
    children: list[int] = []
    while time.monotonic() < deadline and len(children) < 2:
        time.sleep(0.2)
        children = [pid for pid in child_pids(process.pid) if "spawn_main" in cmdline(pid)]
    assert len(children) == 2, children
    time.sleep(recording_s)
    process.kill()
    process.wait(timeout=5)
    gone = time.monotonic() + 10.0  # they notice within 2 s; then they close the recording (slow on a loaded machine)
    while time.monotonic() < gone and any(alive(pid) for pid in children):
        time.sleep(0.1)
    left = [pid for pid in children if alive(pid)]
    for pid in left:
        os.kill(pid, signal.SIGKILL)
    assert not left, "context processes outlived their supervisor"


@pytest.mark.slow
def test_a_taken_debug_port_is_an_error_not_a_silent_run_without_the_server() -> None:
    import socket

    holder = socket.socket()
    holder.bind(("127.0.0.1", 0))
    holder.listen(1)
    port = holder.getsockname()[1]
    try:
        result = tafel("run", "--platform", "dummy", "--frames", "10", "--speed", "max", "--debug-port", str(port))
    finally:
        holder.close()
    assert result.returncode == 2
    assert f"debug port 127.0.0.1:{port} is taken" in result.stderr and "--debug-port 0" in result.stderr
    assert "Traceback" not in result.stderr


@pytest.mark.parametrize("port", ["70000", "-1", "http"])
def test_a_debug_port_out_of_range_is_an_error(port: str) -> None:
    result = tafel("run", "--platform", "dummy", "--frames", "10", "--debug-port", port)
    assert result.returncode == 2 and f"argument --debug-port: takes a port number from 0 to 65535 (0: any free one), got '{port}'" in result.stderr


@pytest.mark.slow
def test_a_requirement_nobody_provides_is_a_missing_provider_not_a_platform_gap() -> None:
    result = dummy("--frames", "10", "--set", 'cognition.modules=["LookAtBallBehavior"]', "--set", "cognition.providers={}")
    assert result.returncode == 2
    assert ("cognition: LookAtBallBehavior requires BallModel, but no module in the configuration provides it and no "
            "platform does") in result.stderr
    assert "on this platform" not in result.stderr
    # what only some platforms provide is still a gap of this platform: pruned, and said so
    gap = dummy("--frames", "10", "--set", 'cognition.modules=["KalmanBallModeler", "LookAtBallBehavior", "Striker", "BallDetector"]',
                "--set", "cognition.disabled=[]")
    assert gap.returncode == 0, gap.stderr
    assert "BallDetector disabled: nothing provides CameraImageBottom, CameraImageTop on this platform" in gap.stderr \
        or "BallDetector disabled: nothing provides CameraImageTop, CameraImageBottom on this platform" in gap.stderr


@pytest.mark.slow
@pytest.mark.parametrize(("setting", "message"), [
    ("runtime.motion_hz=abc", "runtime.motion_hz takes a finite number of Hz above 0 and at most 1000, got 'abc'"),
    ("runtime.motion_hz=nan", "runtime.motion_hz takes a finite number of Hz above 0 and at most 1000, got nan"),
    ("runtime.cognition_hz=inf", "runtime.cognition_hz takes a finite number of Hz above 0 and at most 1000, got inf"),
    ("runtime.motion_hz=10000", "runtime.motion_hz takes a finite number of Hz above 0 and at most 1000, got 10000"),
    ("runtime=5", "runtime takes a table of settings (runtime.motion_hz=100 and the like), got 5"),
    ("runtime.shutdown_grace_s=abc", "runtime.shutdown_grace_s takes a finite number of seconds above 0, got 'abc'"),
    ("runtime.motion_hzz=100", "runtime.motion_hzz is not a setting; did you mean 'motion_hz'"),
    ("parameters.KalmanBallModler.friction=0.3", "unknown module 'KalmanBallModler': did you mean 'KalmanBallModeler'"),
    ("parameters.KalmanBallModeler.fricton=0.3", "KalmanBallModeler has no parameter 'fricton'; did you mean 'friction'"),
    ("parameters.KalmanBallModeler.friction=abc", "parameter KalmanBallModeler.friction takes a finite number of at most 1e+12 in size, got 'abc'"),
])
def test_set_is_validated_with_advice(setting: str, message: str) -> None:
    result = dummy("--frames", "5", "--set", setting)
    assert result.returncode == 2, result.stdout
    assert message in result.stderr and "Traceback" not in result.stderr


@pytest.mark.slow
def test_add_and_remove_module_edit_the_lists_without_restating_them() -> None:
    result = tafel("modules", "--platform", "dummy", "--remove-module", "cognition:LookAtBallBehavior",
                   "--add-module", "cognition:SimpleBallModeler")
    assert result.returncode == 2  # without the behaviour, nothing requests the head: HeadMotion needs it
    assert "HeadMotionRequest" in result.stderr
    result = tafel("modules", "--platform", "dummy", "--add-module", "motion:CameraMatrixProvider")
    assert result.returncode == 0 and "CameraMatrixProvider" in result.stdout
    wrong = tafel("modules", "--platform", "dummy", "--remove-module", "cognition:LookAtBehavior")
    assert wrong.returncode == 2 and "did you mean 'LookAtBallBehavior'" in wrong.stderr
    malformed = tafel("modules", "--platform", "dummy", "--add-module", "LookAtBallBehavior")
    assert malformed.returncode == 2 and "takes CONTEXT:MODULE" in malformed.stderr


def test_status_line_rates_are_over_the_last_interval_and_shown_from_configuration() -> None:
    from tafel.core.runtime import ContextStats
    from tafel.tools.launch.status import StatusLine

    line = StatusLine("dummy", {"status": {"show": []}})
    first = line.format(10.0, {"motion": ContextStats("motion", frames=1000, wall_s=10.0)}, now=110.0)
    assert "motion 100.0 Hz 1000 frames" in first
    stalled = line.format(12.0, {"motion": ContextStats("motion", frames=1010, wall_s=12.0)}, now=112.0)
    assert "motion 5.0 Hz 1010 frames" in stalled  # since start it would still say 84 Hz


def test_the_tools_package_knows_no_representation_by_name() -> None:
    from tafel.core.framework.representation import registered_representations
    from tafel.tools.launch.program import discover_modules

    discover_modules()
    names = set(registered_representations()) - {"DebugDrawings", "DebugPlots", "ModuleTimes"}  # the debug data tools record
    offenders = []
    for path in (REPO / "tools").rglob("*.py"):
        # the tools whose job is to know them: Foxglove's schema for each, the scenes that feed perception
        # modules the images and camera matrices they read, the simulated GameController (and the state its
        # parts share), whose packets are the protocol's GameState, the scenario predicates that judge a belief (BallModel)
        # against ground truth, TeamControl (the team's messages and the game), the robot's links for the
        # 3D view (from the joints and the torso's pose), and the ball classifier's trainer (the images)
        if path.name in ("foxglove_channels.py", "scene_frames.py", "referee.py", "officiating.py", "scenario_predicates.py", "team.py",
                         "robot_links.py", "view.py", "train_ball_classifier.py"):
            continue
        text = path.read_text()
        offenders += [f"{path.name}: {name}" for name in names if re.search(rf"\b{name}\b", text)]
    assert not offenders, offenders


SLOWER = "slower than real time"


@pytest.mark.alone
@pytest.mark.slow
def test_a_run_slower_than_real_time_says_so_once_with_its_real_time_factor() -> None:
    # 30 cognition frames a second of 60 ms each: 1.8 s of work for every second
    result = dummy("--seconds", "5", "--status-interval", "1", "--add-module", "cognition:tests.support.runtime_faults:SlowEveryFrame")
    assert result.returncode == 0, result.stderr
    assert result.stderr.count(SLOWER) == 1, result.stderr
    factor = float(re.search(rf"{SLOWER}: (\d+\.\d+)x", result.stderr).group(1))
    assert 0.3 < factor < 0.8, result.stderr  # about 1 / 1.8


@pytest.mark.alone
@pytest.mark.slow
def test_a_run_that_keeps_up_says_nothing_about_its_pace() -> None:
    result = dummy("--seconds", "4", "--speed", "1", "--status-interval", "1")
    assert result.returncode == 0, result.stderr
    assert SLOWER not in result.stderr and "[tafel] dummy" in result.stderr


def test_the_pace_notice_needs_a_growing_lag_not_one_stall_made_up() -> None:
    from tafel.tools.launch.status import StatusLine

    line = StatusLine("dummy", {})
    # (wall s, platform s, s behind): a 1.5 s stall, made up at 1.25x, then on time
    for now, platform, behind in ((10.0, 8.5, 1.5), (12.0, 11.0, 1.0), (12.5, 12.0, 0.5), (14.0, 13.5, 0.5)):
        assert line.pace(now, platform, behind, 1.0) is None
    # then too slow for good: 0.4x real time
    assert line.pace(20.0, 18.8, 1.2, 1.0) is None
    said = line.pace(22.5, 19.8, 2.7, 1.0)
    assert said is not None and "slower than real time: 0.40x real time" in said
    assert line.pace(30.0, 22.8, 7.2, 1.0) is None  # once
    assert StatusLine("dummy", {}).pace(22.5, 19.8, 2.7, None) is None  # --speed max asks no pace
