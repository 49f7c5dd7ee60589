"""Timing statistics in bounded memory: a histogram of period errors, the same size after an hour as
after a second, so that reporting it costs the same at any uptime."""

from __future__ import annotations

import numpy as np

#: fine bins of 0.01 ms up to 20 ms, then bins of 1 ms up to 2 s; beyond that only the maximum is exact
FINE_MS, FINE_LIMIT_MS, COARSE_MS, COARSE_LIMIT_MS = 0.01, 20.0, 1.0, 2000.0
_FINE_BINS = int(round(FINE_LIMIT_MS / FINE_MS))
_BINS = _FINE_BINS + int(round((COARSE_LIMIT_MS - FINE_LIMIT_MS) / COARSE_MS)) + 1  # the last bin: beyond


class PeriodStatistics:
    """Period errors (ms) of a loop: count, maximum and percentiles to 0.01 ms below 20 ms."""

    __slots__ = ("counts", "count", "max_ms")

    def __init__(self) -> None:
        self.counts = np.zeros(_BINS, np.uint32)
        self.count = 0
        self.max_ms = 0.0

    def add(self, error_ms: float) -> None:
        value = max(0.0, float(error_ms))
        if value < FINE_LIMIT_MS:
            index = int(value / FINE_MS)
        elif value < COARSE_LIMIT_MS:
            index = _FINE_BINS + int((value - FINE_LIMIT_MS) / COARSE_MS)
        else:
            index = _BINS - 1
        self.counts[index] += 1
        self.count += 1
        if value > self.max_ms:
            self.max_ms = value

    def __bool__(self) -> bool:
        return self.count > 0

    def __len__(self) -> int:
        return self.count

    def percentile(self, share: float) -> float:
        """The error (ms) below which ``share`` (0..1) of the samples lie: the upper edge of its bin,
        never more than the maximum."""
        if not self.count:
            return 0.0
        rank = max(1, int(np.ceil(share * self.count)))
        index = int(np.searchsorted(np.cumsum(self.counts, dtype=np.int64), rank))
        if index >= _BINS - 1:
            return self.max_ms
        edge = (index + 1) * FINE_MS if index < _FINE_BINS else FINE_LIMIT_MS + (index - _FINE_BINS + 1) * COARSE_MS
        return min(edge, self.max_ms)

    def percentiles(self) -> dict[str, float]:
        return {"p50_ms": self.percentile(0.5), "p99_ms": self.percentile(0.99), "max_ms": self.max_ms}

    def copy(self) -> PeriodStatistics:
        other = PeriodStatistics()
        other.counts, other.count, other.max_ms = self.counts.copy(), self.count, self.max_ms
        return other

    def __getstate__(self) -> tuple:
        return self.counts, self.count, self.max_ms

    def __setstate__(self, state: tuple) -> None:
        self.counts, self.count, self.max_ms = state
