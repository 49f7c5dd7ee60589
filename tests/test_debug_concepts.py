"""The debug concepts module authors use, through the mocked blackboard and the runtime's frame hooks."""

from __future__ import annotations

import re
import select
import subprocess
import sys
import time

import pytest

from tafel.core import ModuleManager
from tafel.core.testing import ModuleHarness
from tafel.debug.commands import ContextDebug
from tafel.debug.concepts import frame_debug_data
from tafel.debug.executors import RateMeter, instrument
from tafel.debug.protocol import parse
from tafel.debug.values import pretty
from tafel.representations.infrastructure import FrameInfo
from tafel.tools.viewers.console import Completer
from tests.support.debug_user import DebugUser, DebugUserOutput
from tests.test_debug_server import Program


@pytest.fixture
def instrumented() -> ModuleManager:
    manager = ModuleManager([DebugUser], name="cognition", external=[FrameInfo], strict=True)
    instrument("cognition", manager, RateMeter())
    return manager


def run_frames(manager: ModuleManager, frames: int) -> None:
    for i in range(1, frames + 1):
        manager.blackboard.set(FrameInfo(frame_number=i, time_ns=i * 33_000_000))
        manager.execute()


def test_requests_are_off_until_switched_on(instrumented: ModuleManager) -> None:
    state = instrumented.debug
    run_frames(instrumented, 2)
    assert state.drawings_last == []
    state.requests["DebugUser:draw"].on = True
    run_frames(instrumented, 1)
    kinds = [(d["canvas"], d["kind"]) for d in state.drawings_last]
    assert kinds == [("field", "circle"), ("image:top", "text")]
    drawings, _ = frame_debug_data(state)
    assert drawings.primitives[0].points == [100.0, 200.0, 50.0]


def test_modify_publishes_and_can_be_pinned(instrumented: ModuleManager) -> None:
    run_frames(instrumented, 3)
    assert instrumented.blackboard[DebugUserOutput].value == 3.0
    debug = ContextDebug("cognition", instrumented)
    assert debug.execute(parse("modify:set -name DebugUser:gain -value 2.5")) == ("ok", "DebugUser:gain pinned to 2.5")
    run_frames(instrumented, 2)
    assert instrumented.blackboard[DebugUserOutput].value == 5.0  # 2.5 * frame 2
    debug.execute(parse("modify:release -name DebugUser:gain"))
    run_frames(instrumented, 2)
    assert instrumented.blackboard[DebugUserOutput].value == 2.0


def test_plots_and_stopwatches_collect_per_frame(instrumented: ModuleManager) -> None:
    run_frames(instrumented, 4)
    state = instrumented.debug
    assert list(state.plots["DebugUser:frame"].values)[-4:] == [(1, 1.0), (2, 2.0), (3, 3.0), (4, 4.0)]
    assert len(state.stopwatches["DebugUser:work"].times_ns) >= 4
    _, plots = frame_debug_data(state)
    assert "DebugUser:frame" in plots.names and plots.values[plots.names.index("DebugUser:frame")] == 4.0


def test_the_module_works_on_the_mocked_blackboard_without_a_debug_server() -> None:
    bb = ModuleHarness(DebugUser, FrameInfo(frame_number=7)).execute()
    assert bb[DebugUserOutput].value == 7.0


def test_unknown_names_are_reported_for_the_router(instrumented: ModuleManager) -> None:
    debug = ContextDebug("cognition", instrumented)
    status, payload = debug.execute(parse("modify:set -name DebugUser:gian -value 1"))
    assert status == "missing" and "DebugUser:gain" in payload
    status, payload = debug.execute(parse("debug_request:set -name DebugUser:draw -value sometimes"))
    assert status == "error" and "takes on/off" in payload


def test_pretty_prints_nested_values() -> None:
    text = pretty(DebugUserOutput(value=1.5))
    assert text == "value: 1.5"


@pytest.mark.slow
def test_console_completion_and_an_interactive_session() -> None:
    program = Program()
    try:
        from tafel.debug.client import DebugClient

        with DebugClient(program.host, program.port) as client:
            completer = Completer(client)
            assert completer.candidates("modules:l", "modules:l") == ["modules:list"]
            assert "KalmanBallModeler" in completer.candidates("Kal", "modules:set -module Kal")
            assert "BallModel" in completer.candidates("BallM", "representation:print BallM")
            # contextual: representations after representation:print, modules after -module
            assert completer.candidates("Ball", "representation:print Ball") == ["BallModel", "BallPercept"]
            assert completer.candidates("Ball", "modules:set -module Ball") == ["BallDetector", "BallLocator"]
            assert completer.candidates("mo", "representation:print BallModel -context mo") == ["motion"]
            assert completer.candidates("", "ping ") == []
        session = subprocess.run([sys.executable, "-m", "tafel.tools.cli", "console", "--port", str(program.port)],
                                 input="ping\nrepresentation:print BallModel\nquit\n", capture_output=True, text=True, timeout=30)
        assert session.returncode == 0, session.stderr
        assert "connected to" in session.stdout and "pong" in session.stdout and "BallModel (cognition" in session.stdout
        assert re.search(r"connected to 127.0.0.1:\d+: tafel [\d.]+: platform dummy, pid \d+, started \d{4}-", session.stdout)
    finally:
        program.stop()


@pytest.mark.slow
def test_console_ctrl_c_clears_the_line_and_ctrl_d_leaves() -> None:
    import os
    import pty

    program = Program()
    try:
        pid, fd = pty.fork()
        if pid == 0:  # the child: the console on a terminal
            os.execv(sys.executable, [sys.executable, "-m", "tafel.tools.cli", "console", "--port", str(program.port)])
        output = b""

        def read_until(marker: bytes, seconds: float = 20.0) -> None:
            nonlocal output
            deadline = time.monotonic() + seconds
            while marker not in output and time.monotonic() < deadline:
                ready, _, _ = select.select([fd], [], [], 0.2)
                if ready:
                    try:
                        output += os.read(fd, 4096)
                    except OSError:
                        return

        def prompts(count: int) -> None:  # wait until the console has shown ``count`` prompts
            deadline = time.monotonic() + 20
            while output.count(b"tafel> ") < count and time.monotonic() < deadline:
                read_until(b"tafel> " * 0 + b"\x00", 0.2)  # read whatever arrives
            time.sleep(0.3)  # readline switches the terminal to its own mode after printing the prompt

        prompts(1)
        os.write(fd, b"representation:print Nonsense")
        time.sleep(0.2)
        os.write(fd, b"\x03")  # Ctrl-C: the line is dropped, the console stays
        prompts(2)
        for _ in range(3):  # a terminal may deliver the interrupt late and take the next line with it
            os.write(fd, b"ping\r")
            read_until(b"pong", 4.0)
            if b"pong" in output:
                break
        prompts(output.count(b"tafel> ") + 1 if not output.endswith(b"tafel> ") else output.count(b"tafel> "))
        os.write(fd, b"\x04")  # Ctrl-D: leave
        deadline, status = time.monotonic() + 15, None
        while time.monotonic() < deadline:
            done, status = os.waitpid(pid, os.WNOHANG)
            if done:
                break
            read_until(b"\x00", 0.2)
        else:
            os.kill(pid, 9)
            os.waitpid(pid, 0)
            raise AssertionError("the console did not leave on Ctrl-D:\n" + output.decode(errors="replace"))
        assert b"pong" in output
        assert os.WIFEXITED(status) and os.WEXITSTATUS(status) == 0, output.decode(errors="replace")
        assert b"not on this blackboard" not in output  # the dropped line never ran
    finally:
        program.stop()


@pytest.mark.slow
def test_debug_data_is_recorded_like_representations(tmp_path) -> None:
    from tafel.core.logs import read_log
    from tafel.core.logs.serialization import deserialize
    from tafel.debug.concepts import DebugPlots
    from tests.test_cli_runtime import tafel

    path = tmp_path / "debug.mcap"
    result = tafel("run", "--platform", "dummy", "--frames", "30", "--speed", "max", "--debug-port", "0", "--record", str(path),
                   "--record-reps", "DebugPlots,DebugDrawings",
                   "--set", 'cognition.modules=["KalmanBallModeler", "LookAtBallBehavior", "Striker", "tests.support.debug_user:DebugUser"]')
    assert result.returncode == 0, result.stderr
    contents = read_log(path)
    plots = [deserialize(DebugPlots, m.data) for m in contents.messages if m.topic == "cognition/DebugPlots"]
    assert len(plots) == 9
    assert [p.values[p.names.index("DebugUser:frame")] for p in plots] == [float(i) for i in range(1, 10)]
    assert contents.channels["cognition/DebugPlots"].metadata == {"source": "debug", "state": "false"}  # debug output, no state


def test_a_wrong_canvas_or_camera_name_is_an_error_not_a_silent_fallback() -> None:
    """``SegmentedImage.hsv("Top")`` once returned the bottom camera's image; a typo in a canvas drew where
    no view looks."""
    import numpy as np

    from tafel.debug import Canvas
    from tafel.representations.perception import Camera, SegmentedImage

    with pytest.raises(ValueError, match="no drawing canvas 'feild'; the canvases are field, robot, image:top, image:bottom"):
        Canvas.of("feild")
    with pytest.raises(ValueError, match="no drawing canvas 'image:Top'"):
        Canvas.image("Top")
    assert Canvas.image(Camera.bottom) is Canvas.IMAGE_BOTTOM and Canvas.of("robot") is Canvas.ROBOT
    image = SegmentedImage(top_hsv=np.ones((2, 2, 3), np.uint8), bottom_hsv=np.zeros((2, 2, 3), np.uint8))
    with pytest.raises(ValueError, match="no camera 'Top': the cameras are 'top' and 'bottom'"):
        image.hsv("Top")
    assert image.hsv("top").max() == 1 and image.hsv(Camera.bottom).max() == 0
    from tafel.representations.perception import FieldBoundary

    boundary = FieldBoundary(top=np.full(4, 10.0, np.float32), bottom=np.full(4, 20.0, np.float32))
    with pytest.raises(ValueError, match="no camera 'Top'"):  # the bottom camera's rows before
        boundary.rows("Top")
    assert boundary.rows("top")[0] == 10.0 and boundary.inside(Camera.bottom, 1, 25)
