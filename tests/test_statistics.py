"""Motion statistics stay bounded: a report after an hour costs what it costs after a second."""

from __future__ import annotations

import pickle

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from tafel.core.runtime import ContextStats
from tafel.core.runtime.statistics import PeriodStatistics


def test_a_million_samples_take_no_more_room_than_a_thousand() -> None:
    rng = np.random.default_rng(3)
    samples = rng.gamma(2.0, 0.05, 1_000_000)  # ms: mostly well under a millisecond, a long tail
    samples[::50_000] = 35.0  # a few late frames
    stats = ContextStats(name="motion")
    small = None
    for index, value in enumerate(samples):
        stats.period_errors.add(value)
        if index == 999:
            small = len(pickle.dumps(stats))
    assert stats.period_errors.count == 1_000_000
    assert len(pickle.dumps(stats)) <= small + 16  # what the motion process sends every second: a few bytes of counter more
    p50, p99 = np.percentile(samples, [50, 99])
    report = stats.period_error_percentiles()
    assert report["p50_ms"] == pytest.approx(p50, abs=0.011)
    assert report["p99_ms"] == pytest.approx(p99, abs=0.011)
    assert report["max_ms"] == pytest.approx(samples.max())


@given(st.lists(st.floats(0.0, 5000.0), min_size=1, max_size=200))
def test_percentiles_are_within_a_bin_of_the_exact_ones(values: list[float]) -> None:
    stats = PeriodStatistics()
    for value in values:
        stats.add(value)
    exact = sorted(values)
    for share in (0.5, 0.99):
        rank = exact[max(0, int(np.ceil(share * len(exact))) - 1)]
        tolerance = 0.0101 if rank < 20 else (1.0001 if rank < 2000 else float("inf"))
        got = stats.percentile(share)
        assert got <= max(exact) + 1e-9
        assert rank - 1e-9 <= got <= rank + tolerance or got == max(exact)


def test_empty_and_negative_samples() -> None:
    stats = PeriodStatistics()
    assert not stats and stats.percentiles() == {"p50_ms": 0.0, "p99_ms": 0.0, "max_ms": 0.0}
    stats.add(-0.5)  # woke early: counts as on time
    assert stats.count == 1 and stats.percentile(0.5) == 0.0
    copied = pickle.loads(pickle.dumps(stats))
    assert copied.count == 1 and copied.percentiles() == stats.percentiles()
