"""The concurrent runtime's processes know what the program knows: representations defined by a
user's own module files, and every representation a viewer or a recorder names."""

from __future__ import annotations

import os
import subprocess
import textwrap
from pathlib import Path

import pytest

from tafel.core.logs import read_log
from tests.test_cli_runtime import REPO, TAFEL, frames

USER_MODULE = textwrap.dedent('''
    """A team's own module with a representation of its own, outside the tafel package."""
    from tafel.core import Module, provides, representation, requires
    from tafel.representations.infrastructure import FrameInfo


    @representation
    class HeartbeatCount:
        """Frames counted by the team's own module."""
        count: int = 0


    @requires(FrameInfo)
    @provides(HeartbeatCount)
    class HeartbeatCounter(Module):
        def execute(self) -> None:
            self.heartbeat_count.count = self.frame_info.frame_number
''')


@pytest.mark.slow
def test_a_users_representation_reaches_every_process_with_the_web_view_on(tmp_path: Path) -> None:
    (tmp_path / "team_modules.py").write_text(USER_MODULE)
    log = tmp_path / "run.mcap"
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(REPO), str(tmp_path)])}
    result = subprocess.run(
        [*TAFEL, "run", "--platform", "dummy", "--concurrent", "--frames", "150", "--speed", "max", "--debug-port", "0",
         "--web-port", "0", "--set", 'cognition.modules=["team_modules:HeartbeatCounter", "tests.support.nao_support:LookLeft", '
         '"tests.support.motion_requests:ConstantMotionRequest"]', "--record", str(log),
         "--record-reps", "HeartbeatCount"],
        capture_output=True, text=True, timeout=120, cwd=tmp_path, env=env)
    assert result.returncode == 0, result.stdout + result.stderr
    assert "FAILED" not in result.stdout and "failed to start" not in result.stderr, result.stdout + result.stderr
    assert frames(result.stdout)["motion"] == 150
    counts = [m for m in read_log(log).messages if m.topic.endswith("HeartbeatCount")]
    assert len(counts) > 10


def test_a_final_report_sent_just_before_the_process_ended_is_not_taken_for_a_death() -> None:
    """The supervisor polls the pipes, then the processes: a context that stops cleanly in between has
    its last report unread. It must read it before it calls the context dead (seen once as
    'cognition process died (exit code 0)' on Ctrl-C during start-up)."""
    import multiprocessing

    from tafel.core.runtime.concurrent import ConcurrentRuntime
    from tafel.core.runtime.context import ContextStats

    runtime = ConcurrentRuntime.__new__(ConcurrentRuntime)
    runtime.stats = {"cognition": ContextStats(name="cognition")}
    receiver, sender = multiprocessing.Pipe(duplex=False)
    sender.send(ContextStats(name="cognition", frames=0, finished=True))
    sender.close()
    connections = {"cognition": receiver}
    runtime._read_last_reports("cognition", connections)
    assert runtime.stats["cognition"].finished and not runtime.stats["cognition"].failure
    runtime._read_last_reports("cognition", connections)  # the closed pipe: nothing more, no error
    assert "cognition" not in connections


SLOW_STARTER = textwrap.dedent('''
    """A cognition module that takes its time to be made (a model loading from a robot's slow disk)."""
    import time

    from tafel.core import Module, provides, requires
    from tafel.representations.infrastructure import FrameInfo
    from team_modules import HeartbeatCount


    @requires(FrameInfo)
    @provides(HeartbeatCount)
    class SlowHeartbeatCounter(Module):
        def __init__(self) -> None:
            super().__init__()
            time.sleep(1.5)

        def execute(self) -> None:
            self.heartbeat_count.count = self.frame_info.frame_number
''')


@pytest.mark.slow
def test_the_contexts_start_together_so_a_slow_starter_still_runs_its_frames(tmp_path: Path) -> None:
    """Motion's 20 frames take 0.2 s; a cognition that needs 1.5 s to be made ran no frame at all before
    the contexts waited for each other (seen on a loaded machine as a log without cognition's data)."""
    (tmp_path / "team_modules.py").write_text(USER_MODULE)
    (tmp_path / "slow_modules.py").write_text(SLOW_STARTER)
    log = tmp_path / "run.mcap"
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(REPO), str(tmp_path)])}
    result = subprocess.run(
        [*TAFEL, "run", "--platform", "dummy", "--concurrent", "--frames", "20", "--no-debug",
         "--set", 'cognition.modules=["slow_modules:SlowHeartbeatCounter", "tests.support.nao_support:LookLeft", '
         '"tests.support.motion_requests:ConstantMotionRequest"]', "--record", str(log),
         "--record-reps", "HeartbeatCount"],
        capture_output=True, text=True, timeout=120, cwd=tmp_path, env=env)
    assert result.returncode == 0, result.stdout + result.stderr
    assert frames(result.stdout)["motion"] == 20
    counts = [m for m in read_log(log).messages if m.topic.endswith("HeartbeatCount")]
    assert len(counts) >= 3, result.stdout + result.stderr
