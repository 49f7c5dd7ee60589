"""The platform interface: everything a robot program knows about where it runs.

A platform declares, per context, the representations it provides (sensors) and consumes (actuators).
The runtime registers them as external inputs of the managers; modules never see the platform itself.
Each frame the runtime calls ``sense`` before the context's modules run and ``act`` after them, as in
NaoTH: cognition runs after sensing, motion before acting. The frame clock, ``FrameInfo``, is the
runtime's: it writes it after ``sense`` with its own frame count and the time the platform gives
(``frame_time_ns``, else the runtime's clock); a platform neither writes nor provides it.

Two kinds of clock:
- ``clock = "simulated"``: the runtime owns time (lockstep, deterministic). ``advance(time_ns)`` moves
  the world to the given time before the frames of that tick run.
- ``clock = "own"``: the platform's data arrives at its own pace (a robot, a webcam). ``sense`` blocks
  until the next frame's data is there; both contexts run at once (the concurrent runtime).

Platforms register under the entry point group ``tafel.platforms``: one class, one line in the
distribution's metadata, so other packages can add platforms too.
"""

from __future__ import annotations

import argparse
from collections.abc import Mapping
from importlib.metadata import entry_points
from typing import Any, ClassVar

from tafel.core.framework.errors import TafelError, UnknownModuleError
from tafel.core.framework.manager import Blackboard
from tafel.core.framework.naming import did_you_mean
from tafel.core.framework.values import convert

ENTRY_POINT_GROUP = "tafel.platforms"


class PlatformError(TafelError, RuntimeError):
    """A platform cannot start or cannot go on (missing device, unreadable file, lost connection)."""


class PlatformOptionError(PlatformError):
    """A platform option that is missing or wrong (exit status 2 on the command line)."""


class EndOfData(TafelError):
    """The platform has no more data (end of a video or log without --loop): stop cleanly."""


def seed_number(text: str) -> int:
    """``--seed``: a whole number from 0 to 2**32 - 1 (what numpy's generators accept)."""
    return convert(text, int, where="--seed", bounds=(0, 2**32 - 1), text=True, error=argparse.ArgumentTypeError)


class Platform:
    """Base class of all platforms. Subclasses fill ``provides`` and ``consumes`` and the methods."""

    #: the name used with ``tafel run --platform NAME``
    name: ClassVar[str] = ""
    #: one line for ``tafel platforms``
    description: ClassVar[str] = ""
    #: "simulated" (lockstep, runtime-owned time) or "own" (data arrives at its own pace)
    clock: ClassVar[str] = "simulated"
    #: context -> representation classes the platform writes (sensors)
    provides: ClassVar[Mapping[str, tuple[type, ...]]] = {}
    #: context -> representation classes the platform reads (actuators)
    consumes: ClassVar[Mapping[str, tuple[type, ...]]] = {}
    #: True when ``next_step`` decides which contexts run when (log replay); else rates decide
    drives_schedule: ClassVar[bool] = False
    #: False when the contexts cannot run in separate processes (one simulated world feeds both)
    #: top-level configuration tables of this platform's own (``[video] camera_pose``), besides the general ones
    config_sections: ClassVar[tuple[str, ...]] = ()
    concurrent: ClassVar[bool] = True

    def __init__(self, options: Mapping[str, Any] | None = None) -> None:
        self.options = dict(options or {})

    @classmethod
    def add_arguments(cls, parser: argparse.ArgumentParser) -> None:
        """Command-line options of this platform (for ``tafel run``); values arrive in ``options``."""

    def config_layers(self) -> list[str]:
        """The platform layers of the configuration, in order (``config/platform/NAME.toml``)."""
        return [self.name]

    def rates(self) -> Mapping[str, float] | None:
        """Frame rates (Hz) the platform imposes per context, or None to use the configured ones."""
        return None

    def configure(self, config: Mapping[str, Any]) -> None:
        """Take what the platform needs of the merged configuration (called once, before ``start``).

        What it keeps must go into ``options``: a context process makes its platform anew from them."""

    def start(self, contexts: frozenset[str]) -> None:
        """Open devices and files for ``contexts`` (called in the process that runs them)."""

    def advance(self, time_ns: int) -> None:
        """Simulated clock only: move the world forward to ``time_ns`` (physics, synthetic data)."""

    def sense(self, context: str, blackboard: Blackboard, frame_number: int, time_ns: int) -> None:
        """Write this frame's sensor representations of ``context`` into ``blackboard`` (the runtime
        writes ``FrameInfo`` afterwards, with ``frame_number`` and ``time_ns`` or the platform's own).

        With an own clock this blocks until the data is there and may update the time it was taken
        (see ``frame_time_ns``); it raises ``EndOfData`` when the source is exhausted.
        """

    def act(self, context: str, blackboard: Blackboard) -> None:
        """Read the actuator representations of ``context`` from ``blackboard`` and apply them."""

    def next_step(self) -> tuple[int, frozenset[str]] | None:
        """With ``drives_schedule``: the time and the contexts of the next step, None while paused.

        Raises ``EndOfData`` when there is nothing more to run.
        """
        raise NotImplementedError

    def frame_time_ns(self, context: str) -> int | None:
        """The platform's time of the last ``sense`` of ``context`` (an own clock's, a log's recorded
        one); None to use the runtime's clock. It becomes ``FrameInfo.time_ns``."""
        return None

    def frame_number_of(self, context: str) -> int | None:
        """The number the platform's data gives the last ``sense``'s frame of ``context`` (a replayed
        log's recorded one); None, as almost always, for the runtime's count. It becomes
        ``FrameInfo.frame_number``."""
        return None

    def stop(self) -> None:
        """Release everything (also called after errors); must not raise."""

    def take_events(self) -> list[str]:
        """What happened in the world since the last call that a user watching the run is told at once,
        in a few words each (a simulated goal with the score); ``tafel run`` prints each on a status line."""
        return []

    # Debug hooks: name -> (description, handler(args) -> answer text). Filled by platforms with
    # commands such as moving the ball; the debug server exposes them.
    def commands(self) -> Mapping[str, tuple[str, Any]]:
        return {}


def available_platforms() -> dict[str, Any]:
    """Name -> entry point of every registered platform (not yet imported)."""
    return {ep.name: ep for ep in entry_points(group=ENTRY_POINT_GROUP)}


def load_platform(name: str) -> type[Platform]:
    """The platform class registered as ``name``; ``UnknownModuleError`` with suggestions otherwise."""
    known = available_platforms()
    if name not in known:
        raise UnknownModuleError(f"unknown platform {name!r}: {did_you_mean(name, known)}")
    cls = known[name].load()
    if not (isinstance(cls, type) and issubclass(cls, Platform)):
        raise PlatformError(f"entry point {name!r} of group {ENTRY_POINT_GROUP} is {cls!r}, not a Platform subclass")
    return cls
