"""One module on a mocked blackboard, with a clock and input sequences: ``ModuleHarness``, ``run_module``."""

from __future__ import annotations

import builtins
import copy
import math
from collections.abc import Callable, Mapping, Sequence
from typing import Any, TypeVar

from tafel.core.framework.contexts import Context
from tafel.core.framework.frame_info import FrameInfo
from tafel.core.framework.manager import Blackboard, ModuleManager
from tafel.core.framework.module import Module
from tafel.core.framework.representation import get_representation, is_representation
from tafel.core.runtime.handover import private_copy

R = TypeVar("R")

#: frames per second of each context (the defaults of ``runtime.cognition_hz`` and ``runtime.motion_hz``)
CONTEXT_RATES_HZ = {"cognition": 30.0, "motion": 100.0}

#: called after every test by the pytest plugin; packages that keep process-wide state register a reset
RESET_HOOKS: list[Callable[[], None]] = []


def context_of(module: type) -> str:
    """The context a module runs in by the project's layout: ``motion`` for modules in a ``motion``
    package, ``cognition`` otherwise. Pass ``context=`` to the harness where that guess is wrong."""
    return "motion" if "motion" in module.__module__.split(".") else "cognition"


class ModuleHarness:
    """One module on its own blackboard: set or feed inputs, execute, read outputs, repeat.

    The harness owns the clock: every frame it writes ``FrameInfo`` (frame number, and the time
    advancing by the context's period from ``start_ns``), so a module that integrates over time sees
    time pass as it would in the program. Requirements that are not set keep their defaults; inputs
    persist between frames until set again or fed.
    """

    def __init__(self, module: type[Module], *inputs: Any, parameters: Mapping[str, Any] | None = None,
                 context: str | None = None, rate_hz: float | None = None, start_ns: int = 0) -> None:
        declared = module.requirements()
        self.module_class = module
        self.context = Context.of(context, "context").value if context is not None else context_of(module)
        self.rate_hz = float(rate_hz or CONTEXT_RATES_HZ.get(self.context, 30.0))
        if not (math.isfinite(self.rate_hz) and self.rate_hz > 0):
            raise ValueError(f"rate_hz must be a positive number, got {rate_hz!r}")
        self.period_ns = int(round(1e9 / self.rate_hz))
        self.manager = ModuleManager(
            [module],
            name=f"test:{module.__name__}",
            external=declared.reads(),
            strict=True,
            parameters={module.__name__: dict(parameters)} if parameters else None,
        )
        self.frame_number = 0
        self.time_ns = int(start_ns)
        self._fed: dict[type, list[Any]] = {}
        self._fed_position = 0
        self._history: dict[type, list[Any]] = {rep: [] for rep in declared.provides}
        self._clock_given = False
        self.set(*inputs)

    @property
    def blackboard(self) -> Blackboard:
        return self.manager.blackboard

    @property
    def module(self) -> Any:
        """The module instance under test (to inspect its internal state)."""
        return self.manager.module(self.module_class.__name__)

    @property
    def debug(self) -> Any:
        """The module's debug outputs in this harness (``tafel.debug.DebugState``; None when it declares
        none): ``drawings(canvas)`` of the last frame, ``plot_values(name)``, ``requests[name].on = True``,
        ``modifies[name]``, ``stopwatches[name]``. Each harness has its own: nothing leaks between tests."""
        return self.manager.debug

    @property
    def time_s(self) -> float:
        """The time of the last frame executed (s)."""
        return self.time_ns * 1e-9

    def _check_input(self, rep: type) -> None:
        declared = self.module_class.requirements()
        allowed = {*declared.reads(), *declared.provides}
        if not is_representation(rep):
            raise TypeError(f"inputs are representations, got {rep!r}")
        if rep not in allowed:
            names = ", ".join(sorted(r.__name__ for r in allowed)) or "nothing"
            raise TypeError(f"{self.module_class.__name__} does not require, use or provide {rep.__name__}; it declares {names}")

    def set(self, *inputs: Any) -> ModuleHarness:
        """Put representation values on the blackboard (copied, so the test's objects stay its own). A value for a
        representation being fed (``feed``) ends that feed: from now on the test's value holds."""
        for value in inputs:
            self._fed.pop(type(value), None)
        return self._put(*inputs)

    def _put(self, *inputs: Any) -> ModuleHarness:
        for value in inputs:
            if not is_representation(type(value)):
                raise TypeError(f"inputs are representation instances, got {value!r}")
            self._check_input(type(value))
            if type(value) is FrameInfo:
                self._clock_given = True  # the test sets the time of the next frame itself
            target = self.blackboard[type(value)]
            target.__dict__.update(copy.deepcopy(value).__dict__)  # deep: arrays and lists too
        return self

    def feed(self, sequences: Mapping[type, Sequence[Any]]) -> ModuleHarness:
        """One input per frame for each representation: ``feed({BallPercept: [p0, p1, ...]})``.

        All sequences must be equally long; the next ``execute`` frames take one element each.
        """
        lengths = {}
        for rep, values in sequences.items():
            self._check_input(rep)
            values = list(values)
            for index, value in enumerate(values):
                if type(value) is not rep:
                    raise TypeError(f"feed: element {index} for {rep.__name__} is a {type(value).__name__}")
            lengths[rep.__name__] = len(values)
        if len(set(lengths.values())) > 1:
            raise ValueError(f"feed: the sequences differ in length ({', '.join(f'{k}: {v}' for k, v in lengths.items())}); "
                             "give every representation one value per frame")
        self._fed = {rep: list(values) for rep, values in sequences.items()}
        self._fed_position = 0
        return self

    @property
    def fed_frames_left(self) -> int:
        return max(0, max((len(v) for v in self._fed.values()), default=0) - self._fed_position)

    def execute(self, frames: int | None = None) -> Blackboard:
        """Run ``frames`` frames (default: what is left of a ``feed``, else one) and return the blackboard."""
        if frames is None:
            frames = self.fed_frames_left or 1
        if frames < 1:
            raise ValueError(f"frames must be at least 1, got {frames}")
        for _ in range(frames):
            self._step()
        return self.blackboard

    def advance(self, seconds: float) -> Blackboard:
        """Run the frames that fit into ``seconds`` of the context's time (at least one)."""
        if not (math.isfinite(seconds) and seconds > 0):
            raise ValueError(f"advance takes a positive number of seconds, got {seconds!r}")
        return self.execute(max(1, int(round(seconds * 1e9 / self.period_ns))))

    def _step(self, recorded_clock: tuple[int, int] | None = None) -> None:
        if self._fed:
            if self._fed_position >= max(len(v) for v in self._fed.values()):
                names = ", ".join(rep.__name__ for rep in self._fed)
                raise IndexError(f"the fed sequence of {names} ran out after {self._fed_position} frames; "
                                 "feed more values or execute fewer frames")
            self._put(*(values[self._fed_position] for values in self._fed.values()))
            self._fed_position += 1
        self.frame_number += 1
        if recorded_clock is not None:  # a replayed frame keeps its recorded number and time
            self.frame_number, self.time_ns = recorded_clock
        elif self._clock_given and FrameInfo in self.blackboard:  # the test set FrameInfo: it is the clock
            info = self.blackboard[FrameInfo]
            self.frame_number, self.time_ns = info.frame_number, info.time_ns
        elif self.frame_number > 1:
            self.time_ns += self.period_ns
        if FrameInfo in self.blackboard and not self._clock_given:
            info = self.blackboard[FrameInfo]
            info.frame_number, info.time_ns = self.frame_number, self.time_ns
        self._clock_given = False
        self.manager.execute()
        for rep, values in self._history.items():
            values.append(private_copy(self.blackboard[rep]))  # a pickle round trip: deepcopy's result, faster

    def history(self, rep: type[R]) -> list[R]:
        """A copy of ``rep`` after each frame executed so far (provided representations only)."""
        if rep not in self._history:
            raise KeyError(f"{self.module_class.__name__} does not provide {rep.__name__}; the history holds "
                           f"{', '.join(r.__name__ for r in self._history) or 'nothing'}")
        return list(self._history[rep])

    def reads(self, module: type | None = None) -> builtins.set[type]:  # builtins: the class has a method set
        """The representations the module read in the last frame (any field of them)."""
        return self._accessed(module, "readers")

    def writes(self, module: type | None = None) -> builtins.set[type]:
        """The representations the module wrote in the last frame."""
        return self._accessed(module, "writers")

    def _accessed(self, module: type | None, kind: str) -> builtins.set[type]:
        name = (module or self.module_class).__name__
        if name != self.module_class.__name__:
            raise ValueError(f"this harness runs {self.module_class.__name__}, not {name}")
        if self.frame_number == 0:
            raise RuntimeError("nothing ran yet: execute a frame first")
        return {get_representation(rep) for rep, who in self.manager.access().items() if name in who[kind]}

    def __getitem__(self, rep: type[R]) -> R:
        return self.blackboard[rep]


def run_module(module: type[Module], *inputs: Any, frames: int = 1, parameters: Mapping[str, Any] | None = None) -> Blackboard:
    """Run ``module`` alone for ``frames`` frames on a blackboard holding ``inputs``; return it."""
    return ModuleHarness(module, *inputs, parameters=parameters).execute(frames)


# ---------------------------------------------------------------------------- approximate comparison
