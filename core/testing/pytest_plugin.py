"""The pytest plugin of Tafel (entry point ``pytest11``).

Fixtures: ``run_module``, ``module_harness``, ``replay_module``, ``log_slice``, ``assert_close``. Debug
outputs (requests, modify values, drawings, plots) belong to each manager, so each harness has its own;
process-wide state a package keeps is reset after every test through ``tafel.core.testing.RESET_HOOKS``,
so one test's leftovers cannot leak into the next.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from typing import Any

import pytest

from tafel.core import testing
from tafel.core.testing import ModuleHarness


@pytest.fixture
def run_module() -> Callable[..., Any]:
    """``run_module(Module, *inputs, frames=1, parameters=None)`` -> blackboard after the frames."""
    return testing.run_module


@pytest.fixture
def module_harness() -> type[ModuleHarness]:
    """The ``ModuleHarness`` class: ``h = module_harness(Module, *inputs)``, then ``feed``, ``execute``, ``advance``."""
    return ModuleHarness


@pytest.fixture
def replay_module() -> Callable[..., testing.ReplayResult]:
    """``replay_module(Module, "file.mcap", start_s=..., seconds=...)``: a recorded situation through one module."""
    return testing.replay_module


@pytest.fixture
def log_slice() -> Callable[..., testing.ReplayResult]:
    """The same as ``replay_module``, under the name SPL teams use for a piece of a game's log."""
    return testing.replay_module


@pytest.fixture
def assert_close() -> Callable[..., None]:
    return testing.assert_close


@pytest.fixture(autouse=True)
def _tafel_isolated_debug_state() -> Iterator[None]:
    """Every test starts with the debug state it would have in a fresh process."""
    yield
    for reset in testing.RESET_HOOKS:
        reset()
