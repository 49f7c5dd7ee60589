"""Debug concepts for module authors: Pythonic counterparts of the NaoTH debug macros.

    from tafel.debug import drawing, modify, plot, request, stopwatch

    DRAW_PERCEPT = request("BallDetector:draw_percept", "circle around the ball in the image")

    def execute(self) -> None:
        threshold = modify("BallDetector:min_radius", 3.0)      # can be pinned over telnet
        with stopwatch("BallDetector:segmentation"):
            mask = ...
        plot("BallDetector:radius", radius)
        if DRAW_PERCEPT:                                         # off by default, toggled at run time
            drawing("image:top").circle(x, y, radius, color="orange")

Everything is cheap when switched off: a request is one attribute check; an unpinned ``modify``
returns its argument after noting it; plots and stopwatches keep short ring buffers. The state is per
process (the debug server reads it between frames); each entry remembers the context it was used in.
"""

from __future__ import annotations

import dataclasses
import math
import sys
import time
from collections import deque
from dataclasses import dataclass, field
from typing import Any

from tafel.core import representation
from tafel.core.framework.representation import RANGE_META
from tafel.core.testing import RESET_HOOKS

HISTORY = 300  # values kept per plot and per stopwatch


class DebugRequest:
    """A named switch for a code path; ``if DRAW:`` or ``if DRAW.on:``."""

    __slots__ = ("name", "description", "on", "context", "origin")

    def __init__(self, name: str, description: str = "", context: str = "", origin: str = "") -> None:
        self.name, self.description, self.on, self.context = name, description, False, context
        #: the Python module that declared it, when no context was running yet (declared at import)
        self.origin = origin

    def __bool__(self) -> bool:
        return self.on

    def __repr__(self) -> str:
        return f"DebugRequest({self.name!r}, on={self.on})"


@dataclass
class Modify:
    """A value the code publishes; pinned, the code gets ``pinned_value`` instead."""

    name: str
    value: Any = None
    pinned: bool = False
    pinned_value: Any = None
    context: str = ""


@dataclass
class Stopwatch:
    """A named timed section; ``with stopwatch("name"):``."""

    name: str
    context: str = ""
    times_ns: deque = field(default_factory=lambda: deque(maxlen=HISTORY))
    _start: int = 0

    def __enter__(self) -> Stopwatch:
        self._start = time.perf_counter_ns()
        return self

    def __exit__(self, *exc: Any) -> None:
        self.times_ns.append(time.perf_counter_ns() - self._start)
        self.context = STATE.context or self.context


@dataclass
class Plot:
    name: str
    context: str = ""
    values: deque = field(default_factory=lambda: deque(maxlen=HISTORY))  # (frame, value)


class Canvas:
    """Drawing primitives for one canvas of the current frame (``field`` in mm, ``image:<camera>`` in px)."""

    __slots__ = ("name",)

    def __init__(self, name: str) -> None:
        if name not in CANVASES:  # a typo would draw where no view ever looks
            raise ValueError(f"no drawing canvas {name!r}; the canvases are {', '.join(CANVASES)}")
        self.name = name

    def _add(self, kind: str, points: list[float], color: str, width: float, text: str = "") -> Canvas:
        STATE.drawings_now.setdefault(STATE.context, []).append(
            {"canvas": self.name, "kind": kind, "points": [float(p) for p in points], "color": color, "width": float(width), "text": text}
        )
        return self

    def line(self, x1: float, y1: float, x2: float, y2: float, *, color: str = "black", width: float = 1.0) -> Canvas:
        return self._add("line", [x1, y1, x2, y2], color, width)

    def circle(self, x: float, y: float, radius: float, *, color: str = "black", width: float = 1.0) -> Canvas:
        return self._add("circle", [x, y, radius], color, width)

    def rectangle(self, x1: float, y1: float, x2: float, y2: float, *, color: str = "black", width: float = 1.0) -> Canvas:
        return self._add("rectangle", [x1, y1, x2, y2], color, width)

    def text(self, x: float, y: float, text: str, *, color: str = "black", size: float = 12.0) -> Canvas:
        return self._add("text", [x, y], color, size, text)

    def robot_pose(self, x: float, y: float, rotation: float, *, color: str = "blue", width: float = 1.0) -> Canvas:
        """A robot at (x, y) mm looking along ``rotation`` rad."""
        return self._add("robot_pose", [x, y, rotation], color, width)


class DebugState:
    """Everything the debug concepts collect in this process."""

    def __init__(self) -> None:
        self.context = ""
        self.frame: dict[str, int] = {}
        self.requests: dict[str, DebugRequest] = {}
        self.modifies: dict[str, Modify] = {}
        self.stopwatches: dict[str, Stopwatch] = {}
        self.plots: dict[str, Plot] = {}
        self.drawings_now: dict[str, list[dict[str, Any]]] = {}
        self.drawings_last: dict[str, list[dict[str, Any]]] = {}

    def begin_frame(self, context: str, frame: int) -> None:
        """Called before each frame of ``context`` (the runtime's frame hooks)."""
        self.context = context
        self.frame[context] = frame
        self.drawings_now[context] = []

    def end_frame(self, context: str) -> None:
        self.drawings_last[context] = self.drawings_now.get(context, [])
        self.drawings_now[context] = []


    def reset(self) -> None:
        """As in a fresh process, for tests: requests off, pins released, no times, values or drawings.

        Requests and modify values stay registered (modules hold them from import time); only their
        state goes back to the start.
        """
        for found in self.requests.values():
            found.on = False
        for pinned in self.modifies.values():
            pinned.pinned, pinned.pinned_value = False, None
        for watch in self.stopwatches.values():
            watch.times_ns.clear()
        for series in self.plots.values():
            series.values.clear()
        self.context = ""
        self.frame.clear()
        self.drawings_now.clear()
        self.drawings_last.clear()


STATE = DebugState()
RESET_HOOKS.append(STATE.reset)  # the pytest plugin resets it after every test; core never imports debug


def request(name: str, description: str = "") -> DebugRequest:
    """The debug request ``name`` (created switched off on first use)."""
    found = STATE.requests.get(name)
    if found is None:
        origin = "" if STATE.context else sys._getframe(1).f_globals.get("__name__", "")
        found = STATE.requests[name] = DebugRequest(name, description, STATE.context, origin)
    elif description and not found.description:
        found.description = description
    return found


def modify(name: str, value: Any) -> Any:
    """Publish ``value`` under ``name``; returns the pinned value instead while one is set."""
    found = STATE.modifies.get(name)
    if found is None:
        found = STATE.modifies[name] = Modify(name, context=STATE.context)
    found.context = STATE.context or found.context  # first used outside a frame (a test): the context it runs in
    found.value = value
    return found.pinned_value if found.pinned else value


def modify_fields(prefix: str, values: Any, names: tuple[str, ...]) -> Any:
    """Publish fields of a dataclass (a module's parameters) as ``modify`` values ``prefix:name``.

    Returns ``values`` itself while nothing is pinned, else a copy with the pinned values, each clamped
    into the range its field declares (``bounded``), so that a value tried live cannot leave it."""
    pinned: dict[str, Any] = {}
    declared = {item.name: item for item in dataclasses.fields(values)}
    for name in names:
        current = getattr(values, name)
        wanted = modify(f"{prefix}:{name}", current)
        if wanted != current:
            low, high = declared[name].metadata.get(RANGE_META, (-math.inf, math.inf))
            pinned[name] = type(current)(min(max(wanted, low), high))
    return dataclasses.replace(values, **pinned) if pinned else values


def stopwatch(name: str) -> Stopwatch:
    """The stopwatch ``name``, for ``with stopwatch(name):``."""
    found = STATE.stopwatches.get(name)
    if found is None:
        found = STATE.stopwatches[name] = Stopwatch(name, STATE.context)
    return found


def plot(name: str, value: float) -> None:
    """Add this frame's value to the series ``name``."""
    found = STATE.plots.get(name)
    if found is None:
        found = STATE.plots[name] = Plot(name, STATE.context)
    found.values.append((STATE.frame.get(STATE.context, 0), float(value)))


#: the canvases every viewer knows: the field (mm, field frame) and both images (px)
#: where drawings go: the field (mm, field frame), around the robot (mm, robot frame: the view places it at
#: the robot's pose), each camera's image (px)
CANVASES = ("field", "robot", "image:top", "image:bottom")


def drawing(canvas: str = "field") -> Canvas:
    """A canvas of the current frame: ``field`` (mm, field frame), ``robot`` (mm, robot frame) or
    ``image:top`` / ``image:bottom`` (px); another name is a ``ValueError`` naming the canvases."""
    return Canvas(canvas)


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


def frame_debug_data(context: str) -> tuple[DebugDrawings, DebugPlots]:
    """This context's last frame of drawings and plots as representations."""
    drawings = DebugDrawings([DebugDrawingPrimitive(**d) for d in STATE.drawings_last.get(context, [])])
    frame = STATE.frame.get(context, 0)
    names, values = [], []
    for plot_ in STATE.plots.values():
        if plot_.context == context and plot_.values and plot_.values[-1][0] == frame:
            names.append(plot_.name)
            values.append(plot_.values[-1][1])
    return drawings, DebugPlots(names, values)
