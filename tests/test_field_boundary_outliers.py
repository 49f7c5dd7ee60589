"""The field boundary's outlier filter: each found column against the median of its neighbours."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from tafel.modules.perception.field_boundary_detector import local_medians


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
