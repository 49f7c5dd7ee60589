"""What live viewers (Foxglove, the web page) get from the loops, without ever holding one up.

After each frame a loop hands over copies of only those representations a viewer needs right now
(nothing when nobody looks), into a short queue that drops when full. The viewer's own thread turns
them into messages. A need may be limited to some contexts (the web view pairs images with cognition's
drawings, and has no use for motion's). With contexts in other processes, the viewer's needs travel to
them as a shared array of flags (one per representation, in a fixed order: a bit per context), and the
copies come back through a multiprocessing queue that a thread of the supervisor forwards.
"""

from __future__ import annotations

import copy
import dataclasses
import multiprocessing
import queue
import time
from collections.abc import Callable, Collection, Iterable, Mapping, Sequence
from typing import Any, NamedTuple

import numpy as np

QUEUE_SIZE = 64  # copies waiting for the viewer's thread; beyond that a frame's data is dropped
#: a context's bit in a feed's flags; a context not named here is served by every flag
CONTEXT_BITS = {"cognition": 1, "motion": 2}
EVERY_CONTEXT = 0x7F  # the flags are signed bytes


def context_bit(context: str) -> int:
    return CONTEXT_BITS.get(context, EVERY_CONTEXT)


class Handed(NamedTuple):
    """One representation of one frame, as a viewer gets it."""

    context: str
    value: Any
    time_ns: int  # the program's clock
    wall_ns: int  # when it was handed over
    frame: int


def snapshot(value: Any) -> Any:
    """A copy of a representation that the loop may go on changing: arrays and lists copied, cheaply."""
    clone = copy.copy(value)
    for item in dataclasses.fields(value):
        field_value = getattr(value, item.name)
        if isinstance(field_value, np.ndarray):
            setattr(clone, item.name, field_value.copy())
        elif isinstance(field_value, list):
            setattr(clone, item.name, list(field_value))
    return clone


def hand_over(context: str, blackboard: Any, time_ns: int, frame: int, reps: Sequence[type],
              wanted: Callable[[int], bool], put: Callable[[Handed], None]) -> int:
    """After a frame: a copy of each wanted representation (by index in ``reps``) to ``put``; returns how
    many did not fit (``put`` raises ``queue.Full``)."""
    wall, dropped = time.time_ns(), 0
    for index, rep in enumerate(reps):
        if wanted(index) and rep in blackboard:
            try:
                put(Handed(context, snapshot(blackboard[rep]), time_ns, wall, frame))
            except queue.Full:
                dropped += 1
    return dropped


def feed_order(reps: Iterable[type]) -> tuple[type, ...]:
    """Representations in the order a feed's flags follow, the same in every process: by name."""
    return tuple(sorted(set(reps), key=lambda rep: rep.__name__))


class LiveFeed:
    """The loops' side of one viewer: which representations it needs, and the queue its copies go to."""

    def __init__(self, reps: Iterable[type], *, flags: Any = None, queue_size: int = QUEUE_SIZE) -> None:
        #: every representation the viewer may ask for, in one fixed order (the flags' order)
        self.reps = feed_order(reps)
        self.index = {rep: i for i, rep in enumerate(self.reps)}
        self.flags = flags  # with contexts in other processes: a shared array, one flag per representation
        self.needed: dict[type, int] = {}  # representation -> the bits of the contexts it is needed from
        self.queue: queue.Queue[Handed | None] = queue.Queue(maxsize=queue_size)
        self.dropped = 0

    def need(self, reps: Iterable[type], only: Mapping[type, Collection[str]] | None = None) -> None:
        """From now on, hand over these (and nothing else); ``only`` limits some of them to the contexts it names."""
        limits = only or {}
        self.needed = {rep: sum(context_bit(c) for c in limits[rep]) if rep in limits else EVERY_CONTEXT
                       for rep in reps if rep in self.index}
        if self.flags is not None:
            for index, rep in enumerate(self.reps):
                self.flags[index] = self.needed.get(rep, 0)

    def after_frame(self, context: str, blackboard: Any, time_ns: int, frame: int = 0) -> None:
        """In the loop, after each frame: copies of what is needed from this context; never waits."""
        needed = self.needed
        if needed:
            bit = context_bit(context)
            self.dropped += hand_over(context, blackboard, time_ns, frame, self.reps, lambda i: needed.get(self.reps[i], 0) & bit,
                                      self.queue.put_nowait)

    def take(self, item: Handed) -> None:
        """What a context process handed over (the supervisor's forwarding thread)."""
        try:
            self.queue.put_nowait(item)
        except queue.Full:
            self.dropped += 1

    def get(self, timeout: float | None = None) -> Handed | None:
        """The viewer's thread: the next copy, or None when the feed is closed; ``queue.Empty`` when
        nothing came within ``timeout`` s."""
        return self.queue.get(timeout=timeout)

    def close(self) -> None:
        try:
            self.queue.put(None, timeout=5)
        except queue.Full:  # the viewer's thread is stuck; it is a daemon and ends with the program
            pass


def shared_feed(count: int) -> tuple[Any, Any]:
    """For contexts in other processes: (flags for ``count`` representations, the queue copies come through)."""
    spawn = multiprocessing.get_context("spawn")
    return spawn.Array("b", count, lock=False), spawn.Queue(maxsize=QUEUE_SIZE)


def worker_feed_setup(runner: Any, args: dict[str, Any]) -> None:
    """Runs in a context process: after each frame, hand over what the viewer's flags ask for.

    ``args`` holds ``names`` (the feed's representations by name, in its order), ``flags`` and ``queue``."""
    from tafel.core.framework.representation import get_representation
    from tafel.debug.values import frame_number

    reps = [get_representation(name) for name in args["names"]]
    flags, out = args["flags"], args["queue"]
    bit = context_bit(runner.name)
    runner.after_step.append(lambda r: hand_over(r.name, r.manager.blackboard, r.time_ns, frame_number(r.manager), reps,
                                                 lambda i: flags[i] & bit, out.put_nowait))


def forward(source: Any, feed: LiveFeed, stop: Any) -> None:
    """Supervisor thread: what the context processes handed over, to the viewer's feed."""
    while not stop.is_set():
        try:
            feed.take(source.get(timeout=0.2))
        except queue.Empty:
            continue
        except (EOFError, OSError):
            return
