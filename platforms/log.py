"""The log platform: replays a recorded MCAP log frame by frame, so modules run again on recorded data.

Recorded sensor data (what the recording platform provided) is fed to both contexts in the recorded
order; every processing module runs again. Each frame keeps its recorded number and time: the platform
gives them to the runtime (``frame_number_of``, ``frame_time_ns``), which writes ``FrameInfo``. ``--replace`` feeds
further recorded representations in place of the modules that computed them, so the modules
downstream can be tested alone. Replay can be paused, stepped forward and backward, and sent to a
frame; the debug server exposes these as ``log:*`` commands.
"""

from __future__ import annotations

import argparse
import logging
import threading
from array import array
from collections import OrderedDict
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from tafel.core.framework.contexts import Context
from tafel.core.framework.errors import TafelError
from tafel.core.framework.frame_info import FrameInfo
from tafel.core.framework.manager import Blackboard
from tafel.core.framework.naming import did_you_mean
from tafel.core.framework.representation import get_representation
from tafel.core.logs import LogReader
from tafel.core.logs.serialization import SerializationError, check_compatible, codec
from tafel.core.runtime.platform import EndOfData, Platform, PlatformError, PlatformOptionError
from tafel.representations import load_all

log = logging.getLogger("tafel.platform.log")
CONTEXT_ORDER = ("motion", "cognition")
#: decoded chunks kept for replay (a frame's messages may straddle two chunks; stepping back reuses them)
CHUNK_CACHE = 4


@dataclass(frozen=True)
class _Frame:
    """One recorded frame of one context: where its fed messages are, not the messages themselves."""

    context: str
    number: int
    time_ns: int
    chunks: tuple[int, ...]


class LogPlatform(Platform):
    name = "log"
    description = "replays a recorded MCAP log (--log FILE) frame by frame"
    clock = "simulated"
    drives_schedule = True

    def __init__(self, options: Mapping[str, Any] | None = None) -> None:
        super().__init__(options)
        path = self.options.get("log")
        if not path:
            raise PlatformOptionError("the log platform needs a recording: tafel run --platform log --log FILE.mcap")
        try:
            self.reader = LogReader(path)
        except TafelError as exc:
            raise PlatformError(str(exc)) from None
        load_all()
        self.loop = bool(self.options.get("loop", False))
        self.hold = bool(self.options.get("hold", False))
        replace = [n.strip() for n in str(self.options.get("replace") or "").split(",") if n.strip()]
        if replace == ["all"]:
            replace = sorted({c.representation for c in self.reader.channels.values() if c.metadata.get("source") != "platform"})
        classes = self._resolve_classes(self.reader, replace)
        topics = self._fed_topics(self.reader, replace)
        #: topic -> class of exactly what replay reads: sensor data, --replace, and the frame clock
        self.classes = {topic: cls for topic, cls in classes.items() if any(topic in t for t in topics.values())}
        self.decoders = {topic: codec(cls).decode for topic, cls in self.classes.items()}
        #: the recorded frame clock of each context: given to the runtime, which writes FrameInfo
        self.clock_topics = {topic for topic, cls in self.classes.items() if cls is FrameInfo}
        self.provides = {  # type: ignore[misc] - depends on the file, so per instance
            context: tuple(self.classes[topic] for topic in names if topic in self.classes and topic not in self.clock_topics)
            for context, names in topics.items()
        }
        self.consumes = {}  # type: ignore[misc]
        self._index()
        if not self.steps:
            raise PlatformError(f"{path} holds no sensor data to replay"
                                + (f" ({'; '.join(self.reader.problems)})" if self.reader.problems else ""))
        self.position = 0  # the next step
        self.paused = False
        self.steps_left: int | None = 1 if self.options.get("start_paused") else None  # steps to run before pausing again
        self._pending: dict[str, _Frame] = {}
        self._lock = threading.Lock()
        codes = {name: code for code, name in self._context_names.items()}
        self._by_context = {c: np.flatnonzero(self.frame_context == codes[c]) for c in self.provides}
        self._cursors: dict[str, int] = {}
        self._cache: OrderedDict[int, dict[tuple[str, int], dict[str, bytes]]] = OrderedDict()
        #: context -> (number, time) of the frame its last ``sense`` replayed
        self._stamps: dict[str, tuple[int, int]] = {}

    @property
    def path(self) -> str:
        return str(self.reader.path)

    @classmethod
    def add_arguments(cls, parser: argparse.ArgumentParser) -> None:
        parser.add_argument("--log", help="log: the MCAP file to replay")
        parser.add_argument("--loop", action="store_true", help="log: start again at the end")
        parser.add_argument("--replace", default="", metavar="A,B",
                            help="log: also feed these recorded representations, replacing their modules ('all': every one)")
        parser.add_argument("--start-paused", action="store_true", help="log: replay the first frame, then wait for log:play")
        parser.add_argument("--hold", action="store_true", help="log: pause at the end instead of ending the run")

    # -------------------------------------------------------------------------------- set-up
    @staticmethod
    def _fed_topics(reader: LogReader, replace: list[str]) -> dict[str, list[str]]:
        """Per context, the recorded topics replay reads: what the recording platform provided, what
        ``--replace`` names, and the frame clock (``FrameInfo``, whose channel says ``runtime``, or
        ``platform`` in logs from before the runtime wrote it). Recorded module outputs are only there
        to compare against."""
        recorded = {c.representation for c in reader.channels.values()}
        unknown = [name for name in replace if name not in recorded]
        if unknown:
            raise PlatformOptionError(
                f"--replace names {', '.join(unknown)}, which the log does not hold; "
                + did_you_mean(unknown[0], sorted(recorded))
            )
        topics: dict[str, list[str]] = {}
        for topic, channel in reader.channels.items():
            if (channel.metadata.get("source") == "platform" or channel.representation in replace
                    or channel.representation == FrameInfo.__name__):
                topics.setdefault(channel.context, []).append(topic)
        return topics

    @staticmethod
    def _resolve_classes(reader: LogReader, replace: list[str]) -> dict[str, type]:
        classes = {}
        for topic, channel in reader.channels.items():
            try:
                cls = get_representation(channel.representation)
            except KeyError:
                log.warning("%s: no representation class %s in this program; not replayed", reader.path, channel.representation)
                continue
            if channel.schema is not None:
                try:
                    check_compatible(cls, channel.schema)
                except SerializationError as exc:
                    raise PlatformError(f"{reader.path}, channel {topic}: {exc}") from None
            classes[topic] = cls
        return classes

    def _index(self) -> None:
        """Index the frames in one pass over the file: per frame its context, number, time and chunks.

        The index is a handful of numpy arrays (about 30 bytes a frame), never the messages, so replay
        memory stays small however long the log is. Frames are ordered by time, motion before
        cognition at equal times, and grouped into steps: the frames of all contexts that share a time.
        """
        contexts, numbers, times, chunks = array("b"), array("q"), array("q"), array("i")
        codes = {name: CONTEXT_ORDER.index(name) if name in CONTEXT_ORDER else len(CONTEXT_ORDER) for name in self.provides}
        self._context_names = {code: name for name, code in codes.items()}
        topic_codes = {topic: codes[self.reader.channels[topic].context] for topic in self.classes}
        for number, messages in self.reader.iter_chunks():
            for message in messages:
                code = topic_codes.get(message.topic)
                if code is not None:
                    contexts.append(code)
                    numbers.append(message.sequence)
                    times.append(message.time_ns)
                    chunks.append(number)
        context, number, time_ns, chunk = (np.frombuffer(a, dtype=d) if len(a) else np.zeros(0, d)
                                           for a, d in ((contexts, np.int8), (numbers, np.int64), (times, np.int64), (chunks, np.int32)))
        by_frame = np.lexsort((chunk, number, context))  # messages of one frame next to each other
        context, number, time_ns, chunk = context[by_frame], number[by_frame], time_ns[by_frame], chunk[by_frame]
        first = np.flatnonzero(np.r_[True, (context[1:] != context[:-1]) | (number[1:] != number[:-1])]) if len(context) else np.zeros(0, np.int64)
        last_chunk = np.maximum.reduceat(chunk, first) if len(first) else np.zeros(0, np.int32)
        order = np.lexsort((number[first], context[first], time_ns[first]))
        self.frame_context = context[first][order]
        self.frame_number = number[first][order]
        self.frame_time = time_ns[first][order]
        self.frame_chunks = np.stack([chunk[first][order], last_chunk[order]], axis=1) if len(first) else np.zeros((0, 2), np.int32)
        boundary = np.r_[True, (self.frame_time[1:] != self.frame_time[:-1]) | (self.frame_context[1:] == self.frame_context[:-1])]
        self.step_starts = np.r_[np.flatnonzero(boundary), len(self.frame_time)] if len(self.frame_time) else np.zeros(1, np.int64)

    @property
    def steps(self) -> int:
        return len(self.step_starts) - 1

    def _frame(self, index: int) -> _Frame:
        first, last = (int(c) for c in self.frame_chunks[index])
        return _Frame(self._context_names[int(self.frame_context[index])], int(self.frame_number[index]),
                      int(self.frame_time[index]), tuple(range(first, last + 1)))

    def _step_frames(self, step: int) -> list[_Frame]:
        return [self._frame(i) for i in range(int(self.step_starts[step]), int(self.step_starts[step + 1]))]

    def config_layers(self) -> list[str]:
        """The recording platform's layer first, so that replay runs the program that was recorded."""
        layers = [layer for layer in self.reader.metadata.get("config_layers", "").split(",") if layer]
        recorded = self.reader.metadata.get("platform", "")
        layers = layers or ([recorded] if recorded else [])
        return [layer for layer in layers if layer != self.name] + [self.name]

    def rates(self) -> Mapping[str, float] | None:
        rates = {}
        for context in ("cognition", "motion"):
            value = self.reader.metadata.get(f"{context}_hz")
            if value:
                rates[context] = float(value)
        return rates or None

    # -------------------------------------------------------------------------------- replay
    def next_step(self) -> tuple[int, frozenset[str]] | None:
        with self._lock:
            if self.paused:
                return None
            if self.position >= self.steps:
                if self.hold:
                    self.paused = True
                    return None
                if not self.loop:
                    raise EndOfData(f"end of log {self.path}")
                self.position = 0
            step = self._step_frames(self.position)
            self.position += 1
            self._pending = {frame.context: frame for frame in step}
            if self.steps_left is not None:
                self.steps_left -= 1
                if self.steps_left <= 0:
                    self.paused, self.steps_left = True, None
            return step[0].time_ns, frozenset(self._pending)

    def sense(self, context: str, blackboard: Blackboard, frame_number: int, time_ns: int) -> None:
        frame = self._pending.pop(context, None)
        if frame is None:  # concurrent runtime: no schedule, serve this context's frames in order
            frame = self._next_frame_of(context)
        self._stamps[context] = (frame.number, frame.time_ns)  # without a readable FrameInfo: the message's
        for topic, data in self._messages_of(frame).items():
            try:
                # each channel's schema was checked against its class when the log was opened
                value = self.decoders[topic](data)
            except Exception as exc:  # noqa: BLE001 - a damaged message is reported, the replay goes on
                log.error("%s frame %d of %s: cannot decode: %s", self.path, frame.number, topic, exc)
                continue
            if topic in self.clock_topics:  # the recorded clock: the runtime writes it (frame_number_of, frame_time_ns)
                self._stamps[context] = (int(value.frame_number), int(value.time_ns))
            else:
                blackboard.set(value)

    def frame_number_of(self, context: str) -> int | None:
        """The recorded number of the frame of ``context`` replayed last."""
        stamp = self._stamps.get(context)
        return None if stamp is None else stamp[0]

    def frame_time_ns(self, context: str) -> int | None:
        """The recorded time of the frame of ``context`` replayed last."""
        stamp = self._stamps.get(context)
        return None if stamp is None else stamp[1]

    def _messages_of(self, frame: _Frame) -> dict[str, bytes]:
        messages: dict[str, bytes] = {}
        for number in frame.chunks:
            messages.update(self._chunk(number).get((frame.context, frame.number), {}))
        return messages

    def _chunk(self, number: int) -> dict[tuple[str, int], dict[str, bytes]]:
        """The fed messages of one chunk by frame, decoded from the file on first use."""
        cached = self._cache.get(number)
        if cached is not None:
            self._cache.move_to_end(number)
            return cached
        frames: dict[tuple[str, int], dict[str, bytes]] = {}
        for message in self.reader.read_chunk(number) or []:
            if message.topic in self.classes:
                frames.setdefault((self.reader.channels[message.topic].context, message.sequence), {})[message.topic] = message.data
        self._cache[number] = frames
        while len(self._cache) > CHUNK_CACHE:
            self._cache.popitem(last=False)
        return frames

    def _next_frame_of(self, context: str) -> _Frame:
        frames = self._by_context.get(context, np.zeros(0, np.int64))
        index = self._cursors.get(context, 0)
        if index >= len(frames):
            if not self.loop or not len(frames):
                raise EndOfData(f"end of log {self.path}")
            index = 0
        self._cursors[context] = index + 1
        return self._frame(int(frames[index]))

    # ------------------------------------------------------------------------------ stepping
    def play(self) -> None:
        with self._lock:
            self.paused, self.steps_left = False, None

    def pause(self) -> None:
        with self._lock:
            self.paused = True

    def step(self, count: int = 1) -> None:
        """Run ``count`` more steps and pause; a negative count goes back (and replays that step)."""
        with self._lock:
            if count < 0:
                self.position = max(0, self.position + count - 1)
                count = 1
            self.paused, self.steps_left = False, count

    def goto(self, frame_number: int, context: str = "") -> None:
        """Replay the step holding ``frame_number`` of the main context (or of ``context``) and pause there."""
        context = Context.of(context, "context").value if context else ("motion" if "motion" in self._by_context else "cognition")
        frames = self._by_context.get(context, np.zeros(0, np.int64))
        numbers = self.frame_number[frames]
        found = frames[numbers == frame_number]
        if not len(found):
            raise PlatformError(
                f"the log has no {context} frame {frame_number}; its {context} frames are {numbers.min()}..{numbers.max()}"
                if len(numbers) else f"the log has no {context} frames"
            )
        step = int(np.searchsorted(self.step_starts, found[0], side="right")) - 1
        # from the latest frame of every context at or before it, so that each shows its frame of that moment
        start = step
        for indices in self._by_context.values():
            before = indices[indices < self.step_starts[step + 1]]
            if len(before):
                start = min(start, int(np.searchsorted(self.step_starts, before[-1], side="right")) - 1)
        with self._lock:  # replay up to that step (a seek shows the frame), then pause
            self.position, self.paused, self.steps_left = start, False, step - start + 1

    def status(self) -> dict[str, Any]:
        with self._lock:
            current = self._step_frames(min(self.position, self.steps) - 1) if self.position else []
        return {
            "file": self.path,
            "paused": self.paused,
            "step": self.position,
            "steps": self.steps,
            "frames": {f.context: f.number for f in current},
        }

    def timeline(self) -> dict[str, Any]:
        """Where replay is, for a timeline: the main context's last replayed frame and the range of its frames."""
        status = self.status()
        context = "motion" if "motion" in self._by_context else "cognition"
        frames = self._by_context.get(context, np.zeros(0, np.int64))  # frame indices, in time order
        numbers = self.frame_number[frames]
        done = int(np.searchsorted(frames, self.step_starts[min(status["step"], self.steps)], side="left")) if status["step"] else 0
        return {**status, "context": context, "frame": int(numbers[done - 1]) if done else None,
                "frame_range": [int(numbers.min()), int(numbers.max())] if len(numbers) else [0, 0]}

    def stop(self) -> None:
        self.reader.close()
