"""Representations that behaviour decides and motion carries out."""

from __future__ import annotations

import math
from dataclasses import field

from tafel.core import bounded, representation

HOLD_SPEED = 0.0  # rad/s: a request at this speed keeps the head where it is (a penalized robot moves nothing)


@representation
class HeadMotionRequest:
    """Where the head should look: joint angles ``yaw``/``pitch`` (rad) reached with at most
    ``max_speed`` (rad/s); ``max_speed`` 0 (``HOLD_SPEED``) holds the head where it is."""

    yaw: float = bounded(-math.pi, math.pi)
    pitch: float = bounded(-math.pi / 2, math.pi / 2)
    max_speed: float = bounded(0.0, 20.0, 2.0)


@representation
class ActiveOption:
    """One option on the active path: its ``name``, the ``state`` it is in, how long it has been active
    (``time_in_option``, s) and in that state (``time_in_state``, s), how deep it is called (the root
    is 0) and the ``parameters`` its caller gave it (``name=value``, space separated)."""

    name: str = ""
    state: str = ""
    time_in_option: float = 0.0
    time_in_state: float = 0.0
    depth: int = 0
    parameters: str = ""


@representation
class ActivationGraph:
    """The behaviour's decisions in this frame: the active options from the root down, each called by
    the nearest option before it with a smaller ``depth``."""

    options: list[ActiveOption] = field(default_factory=list)

    def status_text(self) -> str:
        """The active path on one line: ``PlaySoccer/playing > Play/play > Striker/approach``."""
        return " > ".join(f"{o.name}/{o.state}" for o in self.options) or "no option active"


@representation
class OptionState:
    """One state of an option: its ``name``, what it does (``doc``), whether the option starts
    (``initial``) or is done (``final``) there, and the states it may go to (``to``)."""

    name: str = ""
    doc: str = ""
    initial: bool = False
    final: bool = False
    to: list[str] = field(default_factory=list)


@representation
class OptionInfo:
    """One option as written: its states, the states any state may go to (``common``, checked first),
    and the options its states may call (``calls``)."""

    name: str = ""
    doc: str = ""
    states: list[OptionState] = field(default_factory=list)
    common: list[str] = field(default_factory=list)
    calls: list[str] = field(default_factory=list)


@representation
class OptionGraph:
    """Every option a behaviour may run, from ``root``: the static graph the views draw (the same every
    frame; ``ActivationGraph`` says which part of it is active)."""

    root: str = ""
    options: list[OptionInfo] = field(default_factory=list)
