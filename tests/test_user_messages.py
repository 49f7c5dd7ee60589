"""What a user reads in the first minutes: the words on Ctrl-C, and the motion on the status line."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parent.parent
TAFEL = [sys.executable, "-m", "tafel.tools.cli"]


def interrupted(sig: signal.Signals, *extra: str) -> tuple[str, str, int]:
    """``tafel run`` on the dummy platform, sent ``sig`` once its first status line is out."""
    process = subprocess.Popen([*TAFEL, "run", "--platform", "dummy", "--no-debug", "--status-interval", "0.3", *extra],
                               cwd=REPO, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                               env={**os.environ, "PYTHONPATH": str(REPO)})
    try:
        first = ""
        deadline = time.monotonic() + 60
        while "[tafel]" not in first and time.monotonic() < deadline:
            first = process.stderr.readline()
        assert "[tafel]" in first, "no status line before the signal"
        process.send_signal(sig)
        out, err = process.communicate(timeout=30)
    finally:
        process.kill()
    return out, first + err, process.returncode


@pytest.mark.slow
@pytest.mark.parametrize("concurrent", [False, True])
@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM])
def test_a_signal_says_stopping_once_and_the_summary_names_it(sig: signal.Signals, concurrent: bool) -> None:
    out, err, status = interrupted(sig, *(["--concurrent"] if concurrent else []))
    assert status == 0, err
    stopping = [line for line in err.splitlines() if "stopping" in line]
    assert len(stopping) == 1, err
    if sig == signal.SIGINT:
        assert "Ctrl-C again to force" in stopping[0]
    assert f"stopped by {sig.name}" in out, out
    assert "stopped after stopped" not in out


def test_the_motion_status_says_what_was_asked_and_why_it_is_not_done() -> None:
    from tafel.representations import MotionInfo, MotionType

    waiting = MotionInfo(motion=MotionType.stand, requested=MotionType.walk, executing_request=False, waiting_for="start-up standing")
    assert waiting.status_text() == "motion stand (asked walk: start-up standing)"
    assert MotionInfo(motion=MotionType.walk, requested=MotionType.walk, executing_request=True).status_text() == "motion walk"


@pytest.mark.parametrize(("situation", "reason"), [
    ("start", "start-up standing"),
    ("lying", "getting up first"),
    ("kicking", "the kick plays to its end"),
    ("walking", "the walk stops with its feet together first"),
])
def test_the_motion_selector_says_why_the_request_waits(situation: str, reason: str) -> None:
    from tafel.core.testing import ModuleHarness
    from tafel.modules.motion.motion_selector import MotionSelector
    from tafel.representations import FallPhase, FallState, KeyframeOutput, MotionRequest, MotionSelection, MotionType, WalkingEngineOutput

    harness = ModuleHarness(MotionSelector, MotionRequest(motion=MotionType.walk), context="motion")
    if situation != "start":
        harness.advance(2.0)  # the start-up standing is over
        assert harness[MotionSelection].active is MotionType.walk and harness[MotionSelection].waiting_for == ""
    if situation == "lying":
        harness.set(FallState(phase=FallPhase.lying_back))
    elif situation == "kicking":
        harness.set(MotionRequest(motion=MotionType.kick))
        harness.execute(frames=1)
        harness.set(KeyframeOutput(done=False), MotionRequest(motion=MotionType.walk))
    elif situation == "walking":
        harness.set(WalkingEngineOutput(standing=False), MotionRequest(motion=MotionType.stand))
    harness.execute(frames=1)
    selection = harness[MotionSelection]
    assert selection.active is not selection.requested
    assert selection.waiting_for == reason
