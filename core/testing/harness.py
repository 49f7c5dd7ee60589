"""Testing support: one module on a mocked blackboard, with a clock, input sequences, approximate
comparison, access assertions, recorded situations, and hypothesis strategies.

    def test_the_ball_model_follows_a_rolling_ball(module_harness):
        harness = module_harness(KalmanBallModeler)
        harness.feed({BallPercept: [BallPercept(seen=True, x=1000.0 + 10 * i) for i in range(30)]})
        harness.execute()                      # 30 frames, FrameInfo advancing by 1/30 s each
        assert_close(harness[BallModel].x, 1290.0, abs=30.0)

The pytest plugin (registered through the ``pytest11`` entry point, so every project with Tafel
installed has it) offers ``run_module``, ``module_harness``, ``replay_module`` and ``log_slice``
fixtures, and resets process-wide debug state (requests, pins, drawings, plots) after every test.
Everything runs strict: an exception in the module fails the test with its own traceback.
"""

from __future__ import annotations

import copy
import dataclasses
import enum
import math
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, TypeVar

import numpy as np

from tafel.core.manager import Blackboard, ModuleManager
from tafel.core.representation import FieldInfo, fields_of, get_representation, is_representation

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

    def __init__(self, module: type, *inputs: Any, parameters: Mapping[str, Any] | None = None,
                 context: str | None = None, rate_hz: float | None = None, start_ns: int = 0) -> None:
        declared = module.requirements()
        self.module_class = module
        self.context = context or context_of(module)
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
        """Put representation values on the blackboard (copied, so the test's objects stay its own)."""
        for value in inputs:
            if not is_representation(type(value)):
                raise TypeError(f"inputs are representation instances, got {value!r}")
            self._check_input(type(value))
            if type(value) is _frame_info_class():
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
        return max((len(v) for v in self._fed.values()), default=0) - self._fed_position

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
            self.set(*(values[self._fed_position] for values in self._fed.values()))
            self._fed_position += 1
        self.frame_number += 1
        frame_info = _frame_info_class()
        if recorded_clock is not None:  # a replayed frame keeps its recorded number and time
            self.frame_number, self.time_ns = recorded_clock
        elif self._clock_given and frame_info in self.blackboard:  # the test set FrameInfo: it is the clock
            info = self.blackboard[frame_info]
            self.frame_number, self.time_ns = info.frame_number, info.time_ns
        elif self.frame_number > 1:
            self.time_ns += self.period_ns
        if frame_info in self.blackboard and not self._clock_given:
            info = self.blackboard[frame_info]
            info.frame_number, info.time_ns = self.frame_number, self.time_ns
        self._clock_given = False
        self.manager.execute()
        for rep, values in self._history.items():
            values.append(copy.deepcopy(self.blackboard[rep]))

    def history(self, rep: type[R]) -> list[R]:
        """A copy of ``rep`` after each frame executed so far (provided representations only)."""
        if rep not in self._history:
            raise KeyError(f"{self.module_class.__name__} does not provide {rep.__name__}; the history holds "
                           f"{', '.join(r.__name__ for r in self._history) or 'nothing'}")
        return list(self._history[rep])

    def reads(self, module: type | None = None) -> set[type]:
        """The representations the module read in the last frame (any field of them)."""
        return self._accessed(module, "readers")

    def writes(self, module: type | None = None) -> set[type]:
        """The representations the module wrote in the last frame."""
        return self._accessed(module, "writers")

    def _accessed(self, module: type | None, kind: str) -> set[type]:
        name = (module or self.module_class).__name__
        if name != self.module_class.__name__:
            raise ValueError(f"this harness runs {self.module_class.__name__}, not {name}")
        if self.frame_number == 0:
            raise RuntimeError("nothing ran yet: execute a frame first")
        return {get_representation(rep) for rep, who in self.manager.access().items() if name in who[kind]}

    def __getitem__(self, rep: type[R]) -> R:
        return self.blackboard[rep]


def _frame_info_class() -> type | None:
    try:
        return get_representation("FrameInfo")
    except KeyError:
        return None


def run_module(module: type, *inputs: Any, frames: int = 1, parameters: Mapping[str, Any] | None = None) -> Blackboard:
    """Run ``module`` alone for ``frames`` frames on a blackboard holding ``inputs``; return it."""
    return ModuleHarness(module, *inputs, parameters=parameters).execute(frames)


# ---------------------------------------------------------------------------- approximate comparison
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
@dataclass
class ReplayFrame:
    """One frame of a module replayed on recorded inputs: its outputs next to the recorded ones."""

    frame_number: int
    time_ns: int
    outputs: dict[type, Any]
    recorded: dict[type, Any] = field(default_factory=dict)


@dataclass
class ReplayResult:
    module: type
    path: Path
    context: str
    frames: list[ReplayFrame]

    def outputs(self, rep: type[R]) -> list[R]:
        return [frame.outputs[rep] for frame in self.frames]

    def recorded(self, rep: type[R]) -> list[R | None]:
        """The recorded value in each frame (None where the log has none for that frame)."""
        return [frame.recorded.get(rep) for frame in self.frames]

    def differences(self, *, rel: float = 1e-9, abs: float = 0.0) -> list[str]:
        """Where the module's outputs differ from the recorded ones, frame by frame."""
        found = []
        for frame in self.frames:
            for rep, recorded in frame.recorded.items():
                found += [f"frame {frame.frame_number}: {text}"
                          for text in differences(frame.outputs[rep], recorded, rel=rel, abs=abs)]
        return found


def replay_module(module: type, path: str | Path, *, start_s: float = 0.0, seconds: float | None = None,
                  context: str | None = None, parameters: Mapping[str, Any] | None = None,
                  allow_missing: Iterable[type] = ()) -> ReplayResult:
    """Feed ``module`` its recorded inputs from a log, frame by frame with the recorded frame times.

    The frames are those of the module's context in the log, from ``start_s`` (log time) for
    ``seconds``. Each input is taken from the module's context in that frame, or, for a
    representation handed over from the other context, its newest recorded value at the frame's time,
    as the program would have seen it. Inputs the log lacks are an error naming them, unless listed
    in ``allow_missing`` (they keep their defaults). Returns the module's outputs next to what the
    log recorded of them.
    """
    from tafel.core.logfile import LogReader
    from tafel.core.serialization import deserialize

    declared = module.requirements()
    context = context or context_of(module)
    harness = ModuleHarness(module, parameters=parameters, context=context)
    frame_info = _frame_info_class()
    if frame_info is None:
        raise ValueError("replay_module needs the FrameInfo representation (import tafel.representations)")
    with LogReader(path) as reader:
        topics = set(reader.channels)
        frame_topic = f"{context}/FrameInfo"
        if frame_topic not in topics:
            raise ValueError(f"{path} has no {frame_topic}: was {context} running when it was recorded? "
                             f"contexts in the log: {sorted({t.split('/')[0] for t in topics})}")
        sources: dict[type, str] = {}
        missing = []
        for rep in declared.reads():
            if rep is frame_info:
                continue
            own, other = f"{context}/{rep.__name__}", f"{'motion' if context == 'cognition' else 'cognition'}/{rep.__name__}"
            if own in topics:
                sources[rep] = own
            elif other in topics:
                sources[rep] = other
            elif rep not in set(allow_missing):
                missing.append(rep.__name__)
        if missing:
            raise ValueError(f"{path} does not hold {', '.join(missing)}, which {module.__name__} reads; record them "
                             f"(--record-reps) or pass allow_missing=[...] to keep their defaults")
        outputs = {rep: f"{context}/{rep.__name__}" for rep in declared.provides if f"{context}/{rep.__name__}" in topics}
        wanted = {frame_topic, *sources.values(), *outputs.values()}
        first_ns = None
        by_time: dict[int, dict[str, Any]] = {}
        order: list[int] = []
        for message in reader.messages(wanted):
            first_ns = message.time_ns if first_ns is None else min(first_ns, message.time_ns)
            if message.time_ns not in by_time:
                by_time[message.time_ns] = {}
                order.append(message.time_ns)
            by_time[message.time_ns][message.topic] = message
    if first_ns is None:
        raise ValueError(f"{path} holds no messages")
    begin = first_ns + int(start_s * 1e9)
    end = None if seconds is None else begin + int(seconds * 1e9)
    latest: dict[str, Any] = {}
    decoded: dict[int, Any] = {}
    frames = []

    def value(rep: type, message: Any) -> Any:
        key = id(message)
        if key not in decoded:
            decoded[key] = deserialize(rep, message.data)
        return decoded[key]

    for time_ns in sorted(order):
        messages = by_time[time_ns]
        for topic, message in messages.items():
            latest[topic] = message
        frame_message = messages.get(frame_topic)
        if frame_message is None or time_ns < begin or (end is not None and time_ns >= end):
            continue
        inputs = [value(rep, latest[topic]) for rep, topic in sources.items() if topic in latest]
        harness.set(*inputs)
        recorded_frame = deserialize(frame_info, frame_message.data)
        harness._step((recorded_frame.frame_number, recorded_frame.time_ns))
        frames.append(ReplayFrame(
            frame_number=recorded_frame.frame_number,
            time_ns=time_ns,
            outputs={rep: copy.deepcopy(harness[rep]) for rep in declared.provides},
            recorded={rep: value(rep, messages[topic]) for rep, topic in outputs.items() if topic in messages},
        ))
    if not frames:
        raise ValueError(f"{path}: no {context} frame between {start_s} s and "
                         f"{'the end' if seconds is None else f'{start_s + seconds} s'} of the log")
    return ReplayResult(module, Path(path), context, frames)


# ---------------------------------------------------------------------------- hypothesis strategies
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
        from tafel.core.naming import did_you_mean

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
        width = min(64, spec.dtype.itemsize * 8)
        if width < 64:  # the bounds must be representable at the array's width
            low, high = float(np.float32(low)), float(np.float32(high))
        elements = st.floats(min_value=low, max_value=high, allow_nan=False, allow_infinity=False, width=width)
    elif spec.dtype.kind in "iu":
        limits = np.iinfo(spec.dtype)
        elements = st.integers(max(int(limits.min), math.ceil(low) if info.range else int(limits.min)),
                               min(int(limits.max), math.floor(high) if info.range else int(limits.max)))
    return shape.flatmap(lambda s: hnp.arrays(spec.dtype, s, elements=elements)).map(np.ascontiguousarray)
