"""The field boundary's outlier filter: each found column against the median of its neighbours."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from tafel.modules.perception.field_boundary_detector import highest_field_rows, local_medians


def reference(tops: np.ndarray, found: np.ndarray, reach: int) -> np.ndarray:
    """The definition, one column at a time: the median of the found columns within reach."""
    indices = np.nonzero(found)[0]
    return np.array([np.median(tops[indices[(indices >= i - reach) & (indices <= i + reach)]]) for i in indices])


@settings(max_examples=300, deadline=None)
@given(st.lists(st.tuples(st.integers(0, 120), st.booleans()), min_size=1, max_size=200), st.integers(1, 40))
def test_local_medians_are_the_medians_of_the_found_neighbours(columns: list[tuple[int, bool]], reach: int) -> None:
    tops = np.array([4.0 * top for top, _ in columns], np.float32)  # cell rows times the cell size, as the detector has them
    found = np.array([is_found for _, is_found in columns])
    np.testing.assert_array_equal(local_medians(tops, found, reach), reference(tops, found, reach))


def test_a_lone_column_high_in_the_hall_stands_out_from_its_neighbours() -> None:
    tops = np.full(80, 200.0, np.float32)
    tops[40] = 20.0  # green high up in the hall
    found = np.ones(80, bool)
    found[10:20] = False
    local = local_medians(tops, found, 16)
    assert local.shape == (70,) and np.all(local == 200.0)


def scan_reference(field: np.ndarray, lines: np.ndarray, max_gap: int) -> np.ndarray:
    """The definition, one row at a time from the bottom: the highest field row each column reaches."""
    n_rows, n_cols = field.shape
    started, alive = np.zeros(n_cols, bool), np.ones(n_cols, bool)
    gap, top = np.zeros(n_cols, int), np.full(n_cols, n_rows)
    for row in range(n_rows - 1, -1, -1):
        here = field[row]
        started |= here
        gap = np.where(here, 0, np.where(lines[row], gap, gap + 1))
        alive &= ~started | (gap <= max_gap)
        top = np.where(alive & here, row, top)
    return top


@settings(max_examples=300, deadline=None)
@given(st.integers(1, 40), st.integers(1, 30), st.integers(0, 8), st.floats(0.0, 1.0), st.floats(0.0, 0.5), st.integers(0, 2**32 - 1))
def test_highest_field_rows_follow_each_column_up_across_short_gaps(n_rows: int, n_cols: int, max_gap: int, green: float, white: float,
                                                                   seed: int) -> None:
    rng = np.random.default_rng(seed)
    field = rng.random((n_rows, n_cols)) < green
    lines = rng.random((n_rows, n_cols)) < white
    np.testing.assert_array_equal(highest_field_rows(field, lines, max_gap), scan_reference(field, lines, max_gap))


def test_a_gap_longer_than_allowed_stops_the_column_but_lines_do_not() -> None:
    field = np.zeros((10, 2), bool)
    field[[9, 8, 3], :] = True  # carpet at the bottom, green again five cells higher
    lines = np.zeros((10, 2), bool)
    lines[4:8, 1] = True  # the second column crosses a painted line there
    assert highest_field_rows(field, lines, 3).tolist() == [8, 3]
