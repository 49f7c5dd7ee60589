"""The pytest plugin of Tafel (entry point ``pytest11``): the ``run_module`` and ``module_harness`` fixtures."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import pytest

from tafel.core.testing import ModuleHarness
from tafel.core.testing import run_module as _run_module


@pytest.fixture
def run_module() -> Callable[..., Any]:
    """``run_module(Module, *inputs, frames=1, parameters=None)`` -> blackboard after the frames."""
    return _run_module


@pytest.fixture
def module_harness() -> type[ModuleHarness]:
    """The ``ModuleHarness`` class, for multi-frame tests: ``h = module_harness(Module, *inputs)``."""
    return ModuleHarness
