"""What a context's debug outputs hold while the program runs: one ``DebugState`` per context.

Modules declare their outputs on the class (``tafel.debug.outputs``: ``DebugRequest``, ``Plot``,
``Stopwatch``, ``ModifyValue``, ``ModifyParameters``); the manager that runs a module gives each
declaration this context's entry of its name (``RequestSwitch``, ``PlotSeries``, ...), so two contexts,
two programs or two tests never share one, and a module loaded again (hot reload) keeps its switches
and pins. The debug commands (``ContextDebug``) and the frame hooks reach the state through the manager
(``manager.debug``). Drawings go on the canvases of ``Canvas``.

Everything is cheap when nobody looks: a request is an attribute read and ``__bool__``; drawings are
only made under a request that is on; plots and stopwatches keep short ring buffers.
"""

from __future__ import annotations

import dataclasses
import enum
import math
import threading
import time
from collections import deque
from dataclasses import field
from typing import Any

from tafel.core import representation
from tafel.core.framework.representation import RANGE_META

HISTORY = 300  # values kept per plot and per stopwatch


class Canvas(str, enum.Enum):
    """Where drawings go: the field (mm, field frame), around the robot (mm, robot frame: the views place
    it at the robot's pose), each camera's image (px). A ``str`` enum: ``"field"`` works too."""

    FIELD = "field"
    ROBOT = "robot"
    IMAGE_TOP = "image:top"
    IMAGE_BOTTOM = "image:bottom"

    @classmethod
    def of(cls, name: Canvas | str) -> Canvas:
        """The canvas ``name``; another name is a ``ValueError`` naming the canvases (a typo would draw
        where no view ever looks)."""
        try:
            return cls(name)
        except ValueError:
            raise ValueError(f"no drawing canvas {name!r}; the canvases are {', '.join(CANVASES)}") from None

    @classmethod
    def image(cls, camera: Any) -> Canvas:
        """The image canvas of a camera (``"top"``, ``"bottom"`` or a ``Camera``)."""
        return cls.of(f"image:{getattr(camera, 'value', camera)}")


#: the canvases every viewer knows, as names
CANVASES = tuple(c.value for c in Canvas)


class Painter:
    """Drawing primitives on one canvas of the current frame of a context."""

    __slots__ = ("canvas", "state")

    def __init__(self, canvas: Canvas, state: DebugState) -> None:
        self.canvas, self.state = canvas.value, state

    def _add(self, kind: str, points: list[float], color: str, width: float, text: str = "") -> Painter:
        self.state.drawings_now.append(
            {"canvas": self.canvas, "kind": kind, "points": [float(p) for p in points], "color": color, "width": float(width), "text": text}
        )
        return self

    def line(self, x1: float, y1: float, x2: float, y2: float, *, color: str = "black", width: float = 1.0) -> Painter:
        return self._add("line", [x1, y1, x2, y2], color, width)

    def circle(self, x: float, y: float, radius: float, *, color: str = "black", width: float = 1.0) -> Painter:
        return self._add("circle", [x, y, radius], color, width)

    def rectangle(self, x1: float, y1: float, x2: float, y2: float, *, color: str = "black", width: float = 1.0) -> Painter:
        return self._add("rectangle", [x1, y1, x2, y2], color, width)

    def text(self, x: float, y: float, text: str, *, color: str = "black", size: float = 12.0) -> Painter:
        return self._add("text", [x, y], color, size, text)

    def robot_pose(self, x: float, y: float, rotation: float, *, color: str = "blue", width: float = 1.0) -> Painter:
        """A robot at (x, y) mm looking along ``rotation`` rad."""
        return self._add("robot_pose", [x, y, rotation], color, width)


class _NoPainter(Painter):
    """What a request that is off draws with: nothing."""

    def __init__(self) -> None:
        self.canvas, self.state = "", None  # type: ignore[assignment]

    def _add(self, kind: str, points: list[float], color: str, width: float, text: str = "") -> Painter:
        return self


NO_PAINTER = _NoPainter()


# ----------------------------------------------------------------------- one context's entries
class RequestSwitch:
    """A debug request of a context: ``if self.draw:``; its drawings: ``self.draw.canvas(Canvas.FIELD)``."""

    __slots__ = ("name", "description", "on", "state")

    def __init__(self, name: str, description: str, state: DebugState) -> None:
        self.name, self.description, self.on, self.state = name, description, False, state

    def __bool__(self) -> bool:
        return self.on

    def canvas(self, canvas: Canvas | str) -> Painter:
        """A canvas of this frame to draw on; while the request is off, one that draws nothing."""
        if not self.on:
            return NO_PAINTER
        return self.state.painter(canvas)

    def __repr__(self) -> str:
        return f"RequestSwitch({self.name!r}, on={self.on})"


_KEEP: Any = object()  # ModifyEntry() without a value: the one it has


class ModifyEntry:
    """A value the code publishes; pinned by a debug client, the code gets ``pinned_value`` instead.

    ``self.gain()`` is the declared (or last published) value, or the pinned one; ``self.gain(x)``
    publishes ``x`` and returns it, or the pinned value."""

    __slots__ = ("name", "description", "value", "pinned", "pinned_value", "bounds")

    def __init__(self, name: str, description: str = "", value: Any = None) -> None:
        self.name, self.description, self.value = name, description, value
        self.pinned, self.pinned_value = False, None
        #: (low, high) a pinned number must lie within (a parameter's declared range), or None
        self.bounds: tuple[float, float] | None = None

    def __call__(self, value: Any = _KEEP) -> Any:
        if value is not _KEEP:
            self.value = value
        return self.pinned_value if self.pinned else self.value


class StopwatchTimes:
    """A named timed section of a context: ``with self.segmentation:``."""

    __slots__ = ("name", "description", "times_ns", "_start")

    def __init__(self, name: str, description: str = "") -> None:
        self.name, self.description = name, description
        self.times_ns: deque[int] = deque(maxlen=HISTORY)
        self._start = 0

    def __enter__(self) -> StopwatchTimes:
        self._start = time.perf_counter_ns()
        return self

    def __exit__(self, *exc: Any) -> None:
        self.times_ns.append(time.perf_counter_ns() - self._start)


class PlotSeries:
    """A plot of a context: ``self.radius.add(r)`` once a frame; ``values`` holds (frame, value)."""

    __slots__ = ("name", "description", "values", "frames")

    def __init__(self, name: str, description: str, frames: Any) -> None:
        self.name, self.description = name, description
        self.values: deque[tuple[int, float]] = deque(maxlen=HISTORY)
        self.frames = frames  # what counts the context's frames (its manager)

    def add(self, value: float) -> None:
        self.values.append((self.frames.frame, float(value)))


class TunedParameters:
    """Fields of a module's parameters published as modify values ``PREFIX:NAME`` (all of one context)."""

    __slots__ = ("entries",)

    def __init__(self, entries: dict[str, ModifyEntry]) -> None:
        self.entries = entries

    def apply(self, values: Any) -> Any:
        """``values`` itself while nothing is pinned, else a copy with the pinned values, each clamped into
        the range its field declares (``bounded``), so that a value tried live cannot leave it."""
        pinned: dict[str, Any] = {}
        declared = None
        for name, entry in self.entries.items():
            current = getattr(values, name)
            entry.value = current
            if entry.pinned and entry.pinned_value != current:
                declared = declared or {item.name: item for item in dataclasses.fields(values)}
                low, high = declared[name].metadata.get(RANGE_META, (-math.inf, math.inf))
                pinned[name] = type(current)(min(max(entry.pinned_value, low), high))
        return dataclasses.replace(values, **pinned) if pinned else values


#: the state whose context runs a frame in this thread now (for the deprecated free functions only)
RUNNING = threading.local()


class _Frames:
    frame = 0


class DebugState:
    """The debug outputs of one context: its requests, modify values, stopwatches, plots and drawings.

    Made by ``outputs.debug_state(manager)`` (kept as ``manager.debug``), it follows the manager's
    frames: a frame's drawings go to ``drawings_now`` and are ``drawings_last`` after it."""

    def __init__(self, manager: Any = None) -> None:
        self.manager = manager
        self.frames = manager if manager is not None else _Frames()
        self.requests: dict[str, RequestSwitch] = {}
        self.modifies: dict[str, ModifyEntry] = {}
        self.stopwatches: dict[str, StopwatchTimes] = {}
        self.plots: dict[str, PlotSeries] = {}
        #: full name -> the module class that declared it (for listings)
        self.owners: dict[str, str] = {}
        self.drawings_now: list[dict[str, Any]] = []
        self.drawings_last: list[dict[str, Any]] = []
        self._painters: dict[str, Painter] = {c: Painter(c, self) for c in Canvas}
        if manager is not None:
            manager.before_frame.append(self.begin_frame)
            manager.after_frame.append(self.end_frame)

    @property
    def frame(self) -> int:
        return int(self.frames.frame)

    def begin_frame(self) -> None:
        self.drawings_now = []
        RUNNING.state = self

    def end_frame(self) -> None:
        self.drawings_last = self.drawings_now
        self.drawings_now = []
        RUNNING.state = None

    def painter(self, canvas: Canvas | str) -> Painter:
        found = self._painters.get(canvas)
        return found if found is not None else self._painters[Canvas.of(canvas)]

    # -------------------------------------------------- entries by name (get or make)
    def request(self, name: str, description: str = "", owner: str = "") -> RequestSwitch:
        found = self.requests.get(name)
        if found is None:
            found = self.requests[name] = RequestSwitch(name, description, self)
        elif description and not found.description:
            found.description = description
        self.owners.setdefault(name, owner)
        return found

    def modify(self, name: str, value: Any = None, description: str = "", owner: str = "") -> ModifyEntry:
        found = self.modifies.get(name)
        if found is None:
            found = self.modifies[name] = ModifyEntry(name, description, value)
        elif found.value is None:
            found.value = value
        self.owners.setdefault(name, owner)
        return found

    def stopwatch(self, name: str, description: str = "", owner: str = "") -> StopwatchTimes:
        found = self.stopwatches.get(name)
        if found is None:
            found = self.stopwatches[name] = StopwatchTimes(name, description)
        self.owners.setdefault(name, owner)
        return found

    def plot(self, name: str, description: str = "", owner: str = "") -> PlotSeries:
        found = self.plots.get(name)
        if found is None:
            found = self.plots[name] = PlotSeries(name, description, self.frames)
        self.owners.setdefault(name, owner)
        return found

    # -------------------------------------------------- what tests and tools read
    def drawings(self, canvas: Canvas | str | None = None) -> list[dict[str, Any]]:
        """The last frame's drawings (all, or those on one canvas)."""
        wanted = None if canvas is None else Canvas.of(canvas).value
        return [d for d in self.drawings_last if wanted is None or d["canvas"] == wanted]

    def plot_values(self, name: str) -> list[float]:
        """The recent values of the plot ``name``, oldest first."""
        return [value for _, value in self.plots[name].values]


# --------------------------------------------------------------- debug data as representations (logs)
@representation
class DebugDrawingPrimitive:
    """One drawing primitive: ``points`` are (x1, y1, x2, y2) for lines and rectangles, (x, y, r) for
    circles, (x, y) for text, (x, y, rotation) for robot poses."""

    canvas: str = ""
    kind: str = ""
    points: list[float] = field(default_factory=list)
    color: str = ""
    width: float = 1.0
    text: str = ""


@representation(state=False)
class DebugDrawings:
    """The drawings of one frame of a context (recordable like any representation).

    Debug output, not the robot's state: only there while a debug client can look, so fingerprints and
    ``tafel log compare`` leave it out."""

    primitives: list[DebugDrawingPrimitive] = field(default_factory=list)


@representation(state=False)
class DebugPlots:
    """The plot values of one frame of a context: ``names[i]`` took ``values[i]``.

    Debug output, not the robot's state: only there while a debug client can look, so fingerprints and
    ``tafel log compare`` leave it out."""

    names: list[str] = field(default_factory=list)
    values: list[float] = field(default_factory=list)


@representation(state=False)
class ModuleTimes:
    """How long each module of a context ran in one frame: ``names[i]`` took ``milliseconds[i]``.

    Timing, not state: fingerprints and ``tafel log compare`` leave it out."""

    names: list[str] = field(default_factory=list)
    milliseconds: list[float] = field(default_factory=list)


def frame_debug_data(state: DebugState) -> tuple[DebugDrawings, DebugPlots]:
    """A context's last frame of drawings and plots as representations."""
    drawings = DebugDrawings([DebugDrawingPrimitive(**d) for d in state.drawings_last])
    frame = state.frame
    names, values = [], []
    for series in state.plots.values():
        if series.values and series.values[-1][0] == frame:
            names.append(series.name)
            values.append(series.values[-1][1])
    return drawings, DebugPlots(names, values)
