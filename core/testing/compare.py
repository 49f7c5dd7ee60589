"""Approximate comparison of representations, field by field: ``differences``, ``assert_close``."""

from __future__ import annotations

import dataclasses
import enum
import math
from typing import Any

import numpy as np


def differences(actual: Any, expected: Any, *, rel: float = 1e-9, abs: float = 0.0, path: str = "") -> list[str]:
    """Every place where ``actual`` and ``expected`` differ beyond the tolerances, with both values."""
    where = path or type(expected).__name__
    if dataclasses.is_dataclass(expected) and not isinstance(expected, type):
        if type(actual) is not type(expected):
            return [f"{where}: a {type(actual).__name__} instead of a {type(expected).__name__}"]
        found: list[str] = []
        for info in dataclasses.fields(expected):
            found += differences(getattr(actual, info.name), getattr(expected, info.name), rel=rel, abs=abs,
                                 path=f"{where}.{info.name}")
        return found
    if isinstance(expected, np.ndarray) or isinstance(actual, np.ndarray):
        a, e = np.asarray(actual), np.asarray(expected)
        if a.shape != e.shape:
            return [f"{where}: shape {a.shape} instead of {e.shape}"]
        if a.dtype.kind in "fiub" and e.dtype.kind in "fiub":
            close = np.isclose(a, e, rtol=rel, atol=abs, equal_nan=True)
        else:
            close = a == e
        bad = np.flatnonzero(~np.asarray(close))
        return [f"{where}[{np.unravel_index(i, e.shape) if e.ndim > 1 else i}]: {a.flat[i].item()!r} instead of {e.flat[i].item()!r}"
                for i in bad[:10]] + ([f"{where}: and {len(bad) - 10} more elements"] if len(bad) > 10 else [])
    if isinstance(expected, (list, tuple)):
        if not isinstance(actual, (list, tuple)) or len(actual) != len(expected):
            return [f"{where}: {actual!r} instead of {expected!r} (lengths differ)"]
        found = []
        for index, (a, e) in enumerate(zip(actual, expected)):
            found += differences(a, e, rel=rel, abs=abs, path=f"{where}[{index}]")
        return found
    if isinstance(expected, (float, int, np.floating, np.integer)) and not isinstance(expected, (bool, enum.Enum)) \
            and isinstance(actual, (float, int, np.floating, np.integer)) and not isinstance(actual, bool):
        if math.isclose(float(actual), float(expected), rel_tol=rel, abs_tol=abs) or (math.isnan(actual) and math.isnan(expected)):
            return []
        return [f"{where}: {actual!r} instead of {expected!r} (off by {float(actual) - float(expected):.6g})"]
    return [] if actual == expected else [f"{where}: {actual!r} instead of {expected!r}"]


def assert_close(actual: Any, expected: Any, *, rel: float = 1e-9, abs: float = 0.0) -> None:
    """Fail with every differing field and both values unless ``actual`` matches ``expected``.

    Works on numbers, numpy arrays, lists, representations and nested dataclasses; numbers and arrays
    may differ by ``abs + rel * |expected|``.
    """
    found = differences(actual, expected, rel=rel, abs=abs)
    if found:
        raise AssertionError(f"{len(found)} difference(s) (rel={rel:g}, abs={abs:g}):\n  " + "\n  ".join(found))


# ---------------------------------------------------------------------------------- recorded situations
