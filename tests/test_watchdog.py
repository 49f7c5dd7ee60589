"""The watchdog: a module that never returns is named within seconds and ends its context, in both
runtimes, and any context that ends that way (or dies) is a failure in the exit status."""

from __future__ import annotations

import re
import threading
import time
from types import SimpleNamespace

import pytest

from tafel.core.runtime.watchdog import ContextStuck, Watchdog
from tests.test_cli_runtime import dummy, frames

STUCK = "tests.support.runtime_faults:StuckAfter"
COGNITION = ["KalmanBallModeler", "LookAtBallBehavior", "Striker"]


def modules(names: list[str]) -> str:
    return "[" + ", ".join(f'"{name}"' for name in names) + "]"


def test_a_module_that_never_returns_is_named_and_interrupted() -> None:
    manager = SimpleNamespace(frame=7, running="")
    outcome: dict[str, object] = {}
    ready = threading.Event()

    def loop() -> None:
        manager.running = "EndlessModule"
        ready.set()
        try:
            while True:
                pass
        except ContextStuck:
            outcome["interrupted"] = True

    thread = threading.Thread(target=loop, daemon=True)
    thread.start()
    ready.wait(5)
    calls: list[tuple[str, str]] = []
    watchdog = Watchdog({"cognition": manager}, 0.3, thread_id=thread.ident, on_stuck=lambda *a: calls.append(a)).start()
    thread.join(timeout=20)
    watchdog.stop()
    assert outcome == {"interrupted": True}
    assert calls and calls[0][0] == "cognition"
    assert re.fullmatch(r"stuck: module EndlessModule ran \d+\.\d s without returning \(frame 7\)", calls[0][1]), calls
    assert watchdog.stuck == calls[0][1]


def test_a_loop_that_makes_frames_or_waits_outside_modules_is_never_stuck() -> None:
    """Frames that advance, and time between modules (a platform waiting, a paused log), are no stall."""
    busy = SimpleNamespace(frame=0, running="WalkingEngine")
    waiting = SimpleNamespace(frame=3, running="")
    calls: list[tuple[str, str]] = []
    watchdog = Watchdog({"motion": busy, "cognition": waiting}, 0.2, thread_id=threading.get_ident(),
                        on_stuck=lambda *a: calls.append(a)).start()
    until = time.monotonic() + 1.0
    while time.monotonic() < until:
        busy.frame += 1  # the same module name, but a new frame each time: progress
        time.sleep(0.01)
    watchdog.stop()
    assert calls == [] and watchdog.stuck == ""


@pytest.mark.parametrize("timeout", [0.0, -1.0, float("nan")])
def test_the_timeout_must_be_positive(timeout: float) -> None:
    with pytest.raises(ValueError, match="positive number of seconds"):
        Watchdog({}, timeout)


@pytest.mark.slow
def test_lockstep_ends_with_a_failure_naming_the_stuck_module() -> None:
    """Before: the program went silent for ever (only a signal ended it)."""
    result = dummy("--speed", "max", "--set", "runtime.stuck_timeout_s=1", "--set", f"cognition.modules={modules([*COGNITION, STUCK])}",
                   timeout=60)
    assert result.returncode == 1, result.stdout + result.stderr
    assert re.search(r"cognition: \d+ frames, .*FAILED: stuck: module StuckAfter ran \d+\.\d s without returning \(frame 20\)",
                     result.stdout), result.stdout
    assert "stopped after stuck: module StuckAfter" in result.stdout


@pytest.mark.slow
def test_a_stuck_motion_process_is_noticed_and_ends_the_program() -> None:
    """Before: motion at 0 Hz for as long as one cared to wait, no message, no exit."""
    motion = '["InertialFilter", "FallDetector", "MotionSelector", "StandMotion", "WalkingEngine", "KeyframePlayer", ' \
             f'"HeadMotion", "MotionCombinator", "{STUCK}"]'
    result = dummy("--concurrent", "--seconds", "60", "--set", "runtime.stuck_timeout_s=1", "--set", f"motion.modules={motion}",
                   "--set", "parameters.StuckAfter.after_frames=50", timeout=60)
    assert result.returncode == 1, result.stdout + result.stderr
    assert re.search(r"motion stuck: module StuckAfter ran \d+\.\d s without returning \(frame 50\); the program ends", result.stderr)
    assert frames(result.stdout)["motion"] == 50  # the 50th frame began and never ended


@pytest.mark.slow
def test_a_stuck_cognition_process_fails_the_run_while_motion_goes_on() -> None:
    result = dummy("--concurrent", "--frames", "600", "--set", "runtime.stuck_timeout_s=1",
                   "--set", f"cognition.modules={modules([*COGNITION, STUCK])}", timeout=60)
    assert result.returncode == 1, result.stdout + result.stderr
    assert re.search(r"cognition stuck: module StuckAfter ran \d+\.\d s .*; the other context keeps running", result.stderr)
    assert frames(result.stdout)["motion"] == 600  # motion kept its beat to the end
    assert re.search(r"cognition: \d+ frames, .*FAILED: stuck: module StuckAfter", result.stdout), result.stdout
