"""``benchmarks/walking.py --set`` reaches the simulations, and a wrong key is said before minutes of
simulation; the in-process program (``SteppedProgram``) checks its configuration as ``tafel run`` does."""

from __future__ import annotations

import subprocess
import sys

import pytest

from tafel.core.framework.config import ConfigError
from tests.support.benchmarks import BENCHMARKS
from tests.support.simulation import Simulation


def walking(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, str(BENCHMARKS / "walking.py"), "--engines", "mujoco", "--parts", "speeds", *args],
                          capture_output=True, text=True, timeout=120)


@pytest.mark.slow
@pytest.mark.parametrize(("setting", "message"), [
    ("parameters.WalkingEngine.foot_lfit=25", "WalkingEngine has no parameter 'foot_lfit'; did you mean 'foot_lift'?"),
    ("WalkingEngine.foot_lift=25", "[WalkingEngine] is not a section of the configuration"),
])
def test_a_wrong_setting_is_an_error_before_anything_is_measured(setting: str, message: str) -> None:
    result = walking("--set", setting)
    assert result.returncode == 2 and result.stdout == ""
    assert f"walking.py: error: --set: {message}" in result.stderr


def test_the_in_process_program_refuses_what_tafel_run_refuses() -> None:
    with pytest.raises(ConfigError, match=r"\[recording\] representation is not a setting"):
        Simulation("dummy", overrides=["recording.representation=[]"], scene="default")
