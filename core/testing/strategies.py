"""Hypothesis strategies for representations: values within each field's type and declared range."""

from __future__ import annotations

import math
from typing import Any, Literal

import numpy as np

from tafel.core.framework.representation import FieldInfo, fields_of

#: the largest magnitude drawn for a number whose field declares no range
DEFAULT_MAGNITUDE = 1e6


def strategy_for(rep: type, *, max_list: int = 4, max_axis: int = 4, **overrides: Any) -> Any:
    """A hypothesis strategy of valid instances of a representation (or any supported dataclass).

    Numbers respect the range a field declares (``bounded(low, high)`` or ``metadata={"range": ...}``);
    without one they are finite and of sensible magnitude (at most ``DEFAULT_MAGNITUDE``, 1e6), never
    NaN or infinite. Arrays keep the dtype and fixed axes of their declaration and draw free axes
    (``None``) from 0 to ``max_axis``. ``strategy_for(BallPercept, x=st.just(0.0))`` overrides a field.
    """
    from hypothesis import strategies as st

    infos = {info.name: info for info in fields_of(rep)}
    unknown = set(overrides) - set(infos)
    if unknown:
        from tafel.core.framework.naming import did_you_mean

        name = sorted(unknown)[0]
        raise TypeError(f"strategy_for({rep.__name__}): no field {name!r}; {did_you_mean(name, infos)}")
    kwargs = {name: overrides[name] if name in overrides else _field_strategy(info, max_list, max_axis)
              for name, info in infos.items()}
    return st.builds(rep, **kwargs)


def _number_bounds(info: FieldInfo, kind: str) -> tuple[float, float]:
    if info.range is not None:
        return info.range
    return (-DEFAULT_MAGNITUDE, DEFAULT_MAGNITUDE)


def _field_strategy(info: FieldInfo, max_list: int, max_axis: int) -> Any:
    from hypothesis import strategies as st
    from hypothesis.extra import numpy as hnp

    kind = info.kind
    if kind == "bool":
        return st.booleans()
    if kind == "int":
        low, high = _number_bounds(info, kind)
        return st.integers(min_value=math.ceil(low), max_value=math.floor(high))
    if kind == "float":
        low, high = _number_bounds(info, kind)
        return st.floats(min_value=low, max_value=high, allow_nan=False, allow_infinity=False)
    if kind == "str":
        return st.text(max_size=20)
    if kind == "bytes":
        return st.binary(max_size=20)
    if kind == "enum":
        return st.sampled_from(list(info.type))
    if kind == "nested":
        return st.deferred(lambda: strategy_for(info.type, max_list=max_list, max_axis=max_axis))
    if kind == "list":
        assert info.element is not None
        return st.lists(_field_strategy(info.element, max_list, max_axis), max_size=max_list)
    assert info.array is not None
    spec = info.array
    shape = st.tuples(*(st.just(n) if n is not None else st.integers(0, max_axis) for n in spec.shape))
    elements = None
    low, high = _number_bounds(info, "float")
    if spec.dtype.kind == "f":
        width: Literal[16, 32, 64] = 16 if spec.dtype.itemsize == 2 else 32 if spec.dtype.itemsize == 4 else 64
        if width < 64:  # the bounds must be representable at the array's width
            low, high = float(np.float32(low)), float(np.float32(high))
        elements = st.floats(min_value=low, max_value=high, allow_nan=False, allow_infinity=False, width=width)
    elif spec.dtype.kind in "iu":
        limits = np.iinfo(spec.dtype)
        elements = st.integers(max(int(limits.min), math.ceil(low) if info.range else int(limits.min)),
                               min(int(limits.max), math.floor(high) if info.range else int(limits.max)))
    return shape.flatmap(lambda s: hnp.arrays(spec.dtype, s, elements=elements)).map(np.ascontiguousarray)
