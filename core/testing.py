"""Testing support: run one module on a mocked blackboard, and hypothesis strategies for representations.

    def test_copies_the_percept(run_module):
        bb = run_module(SimpleBallModeler, BallPercept(seen=True, x=1000.0), frames=1)
        assert bb[BallModel].x == 1000.0

``run_module`` is a pytest fixture (registered through the ``pytest11`` entry point, so every project
with Tafel installed has it); ``ModuleHarness`` is the multi-frame form. Both run strict: an exception
in the module fails the test with its own traceback.
"""

from __future__ import annotations

import copy
from collections.abc import Mapping
from typing import Any, TypeVar

import numpy as np

from tafel.core.manager import Blackboard, ModuleManager
from tafel.core.representation import FieldInfo, fields_of, is_representation

R = TypeVar("R")


class ModuleHarness:
    """One module on its own blackboard: set inputs, execute, read outputs, repeat.

    Requirements that are not set keep their defaults. Inputs persist between frames until set again.
    """

    def __init__(self, module: type, *inputs: Any, parameters: Mapping[str, Any] | None = None) -> None:
        declared = module.requirements()
        self.module_class = module
        self.manager = ModuleManager(
            [module],
            name=f"test:{module.__name__}",
            external=declared.reads(),
            strict=True,
            parameters={module.__name__: dict(parameters)} if parameters else None,
        )
        self.set(*inputs)

    @property
    def blackboard(self) -> Blackboard:
        return self.manager.blackboard

    @property
    def module(self) -> Any:
        """The module instance under test (to inspect its internal state)."""
        return self.manager.module(self.module_class.__name__)

    def set(self, *inputs: Any) -> ModuleHarness:
        """Put representation values on the blackboard (copied, so the test's objects stay its own)."""
        declared = self.module_class.requirements()
        allowed = {*declared.reads(), *declared.provides}
        for value in inputs:
            if not is_representation(type(value)):
                raise TypeError(f"inputs are representation instances, got {value!r}")
            if type(value) not in allowed:
                names = ", ".join(sorted(r.__name__ for r in allowed)) or "nothing"
                raise TypeError(
                    f"{self.module_class.__name__} does not require, use or provide "
                    f"{type(value).__name__}; it declares {names}"
                )
            target = self.blackboard[type(value)]
            target.__dict__.update(copy.deepcopy(value).__dict__)  # deep: arrays and lists too
        return self

    def execute(self, frames: int = 1) -> Blackboard:
        """Run ``frames`` frames and return the blackboard."""
        if frames < 1:
            raise ValueError(f"frames must be at least 1, got {frames}")
        for _ in range(frames):
            self.manager.execute()
        return self.blackboard

    def __getitem__(self, rep: type[R]) -> R:
        return self.blackboard[rep]


def run_module(module: type, *inputs: Any, frames: int = 1, parameters: Mapping[str, Any] | None = None) -> Blackboard:
    """Run ``module`` alone for ``frames`` frames on a blackboard holding ``inputs``; return it."""
    return ModuleHarness(module, *inputs, parameters=parameters).execute(frames)


# ---------------------------------------------------------------------------- hypothesis strategies
def strategy_for(rep: type, *, max_list: int = 4, max_axis: int = 4) -> Any:
    """A hypothesis strategy of valid instances of a representation (or any supported dataclass).

    Floats are finite; arrays keep the dtype and fixed axes of their ``array(...)`` declaration and
    draw free axes (``None``) from 0 to ``max_axis``.
    """
    from hypothesis import strategies as st

    kwargs = {info.name: _field_strategy(info, max_list, max_axis) for info in fields_of(rep)}
    return st.builds(rep, **kwargs)


def _field_strategy(info: FieldInfo, max_list: int, max_axis: int) -> Any:
    from hypothesis import strategies as st
    from hypothesis.extra import numpy as hnp

    kind = info.kind
    if kind == "bool":
        return st.booleans()
    if kind == "int":
        return st.integers(min_value=-(2**63), max_value=2**63 - 1)
    if kind == "float":
        return st.floats(allow_nan=False, allow_infinity=False)
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
    if spec.dtype.kind == "f":
        elements = st.floats(allow_nan=False, allow_infinity=False, width=min(64, spec.dtype.itemsize * 8))
    return shape.flatmap(lambda s: hnp.arrays(spec.dtype, s, elements=elements)).map(np.ascontiguousarray)
