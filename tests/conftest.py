"""Test-suite settings.

Hypothesis runs without deadlines, because these machines are noisy and timing belongs in benchmarks,
not in tests.

The suite runs on two workers (``pytest -n 2``, pytest-xdist). A few end-to-end tests judge a program's
rates or pace against what it does without load (``@pytest.mark.alone``): another worker's simulator
starting beside them would be load they did not ask for. They take an exclusive lock that every other
test takes shared, so each runs alone; without xdist the locks are never contended. They run first, in
modules that run first (``pytest_collection_modifyitems``): an ``alone`` test waits for the other worker's
running test to end, and early on that is not a ten-minute match.
"""

from __future__ import annotations

import fcntl
from collections.abc import Iterator
from pathlib import Path

import pytest
from hypothesis import HealthCheck, settings

settings.register_profile("tafel", deadline=None, suppress_health_check=[HealthCheck.too_slow])
settings.load_profile("tafel")


def pytest_configure(config: pytest.Config) -> None:
    config.addinivalue_line("markers", "alone: runs while no other test runs (it judges rates or pace; see tests/conftest.py)")


def pytest_collection_modifyitems(items: list[pytest.Item]) -> None:
    """``alone`` tests first, and their modules before the others (``--dist loadscope`` hands out whole
    modules in this order); everything else keeps its order. Every worker sorts the same way."""
    def alone(item: pytest.Item) -> bool:
        return item.get_closest_marker("alone") is not None

    def module(item: pytest.Item) -> str:
        return item.nodeid.split("::")[0]

    modules_with_alone = {module(item) for item in items if alone(item)}
    first_place = {name: place for place, name in reversed(list(enumerate(map(module, items))))}
    items.sort(key=lambda item: (module(item) not in modules_with_alone, first_place[module(item)], not alone(item)))


def _lock_folder(factory: pytest.TempPathFactory) -> Path:
    """A folder every xdist worker of this run shares: the parent of the workers' own temporary folders."""
    base = factory.getbasetemp()
    return base.parent if base.name.startswith("popen-gw") else base


@pytest.fixture(autouse=True)
def _one_alone_test_at_a_time(request: pytest.FixtureRequest, tmp_path_factory: pytest.TempPathFactory) -> Iterator[None]:
    """Readers-writer lock across workers: the gate keeps new tests out while an ``alone`` test waits
    for the running ones to end, so it cannot starve."""
    folder = _lock_folder(tmp_path_factory)
    alone = request.node.get_closest_marker("alone") is not None
    with open(folder / "tafel-alone.gate", "a") as gate, open(folder / "tafel-alone.lock", "a") as lock:
        fcntl.flock(gate, fcntl.LOCK_EX)
        try:
            fcntl.flock(lock, fcntl.LOCK_EX if alone else fcntl.LOCK_SH)
        finally:
            if not alone:
                fcntl.flock(gate, fcntl.LOCK_UN)
        try:
            yield
        finally:
            fcntl.flock(lock, fcntl.LOCK_UN)
            if alone:
                fcntl.flock(gate, fcntl.LOCK_UN)
