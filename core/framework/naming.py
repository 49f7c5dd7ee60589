"""Name helpers shared by the whole framework: attribute names and "did you mean" hints."""

from __future__ import annotations

import difflib
import re
from collections.abc import Iterable

_BOUNDARY = re.compile(r"(?<=[a-z0-9])(?=[A-Z])|(?<=[A-Z])(?=[A-Z][a-z])")


def snake_case(name: str) -> str:
    """Attribute name of a representation class: ``CameraMatrixTop`` -> ``camera_matrix_top``.

    Runs of capitals stay together (``IMUData`` -> ``imu_data``).
    """
    return _BOUNDARY.sub("_", name).lower()


def closest(name: str, known: Iterable[str], n: int = 3) -> list[str]:
    """The known names most similar to ``name``, best first (case-insensitive)."""
    known = list(known)
    by_lower = {k.lower(): k for k in known}
    matches = difflib.get_close_matches(name.lower(), list(by_lower), n=n, cutoff=0.5)
    return [by_lower[m] for m in matches]


def did_you_mean(name: str, known: Iterable[str]) -> str:
    """A sentence suggesting the closest known names, or listing what is known."""
    known = sorted(set(known))
    matches = closest(name, known)
    if matches:
        return "did you mean " + " or ".join(repr(m) for m in matches) + "?"
    if not known:
        return "none are known"
    shown = ", ".join(known[:12]) + (", ..." if len(known) > 12 else "")
    return f"known names: {shown}"
