"""The log platform: replays a recorded MCAP log frame by frame, so modules run again on recorded data.

Recorded sensor data (what the recording platform provided) is fed to both contexts in the recorded
order and with the recorded frame times; every processing module runs again. ``--replace`` feeds
further recorded representations in place of the modules that computed them, so the modules
downstream can be tested alone. Replay can be paused, stepped forward and backward, and sent to a
frame; the debug server exposes these as ``log:*`` commands.
"""

from __future__ import annotations

import argparse
import logging
import threading
from collections import OrderedDict
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from tafel.core.errors import TafelError
from tafel.core.logfile import LogReader
from tafel.core.naming import did_you_mean
from tafel.core.manager import Blackboard
from tafel.core.platform import EndOfData, Platform, PlatformError, PlatformOptionError
from tafel.core.representation import get_representation
from tafel.core.serialization import SerializationError, check_compatible, codec
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
        replace = [n.strip() for n in str(self.options.get("replace") or "").split(",") if n.strip()]
        classes = self._resolve_classes(self.reader, replace)
        topics = self._fed_topics(self.reader, replace)
        #: topic -> class of exactly what replay writes onto the blackboards: sensor data and --replace
        self.classes = {topic: cls for topic, cls in classes.items() if any(topic in t for t in topics.values())}
        self.decoders = {topic: codec(cls).decode for topic, cls in self.classes.items()}
        self.provides = {  # type: ignore[misc] - depends on the file, so per instance
            context: tuple(self.classes[topic] for topic in names if topic in self.classes)
            for context, names in topics.items()
        }
        self.consumes = {}  # type: ignore[misc]
        self.timeline = self._timeline()
        if not self.timeline:
            raise PlatformError(f"{path} holds no sensor data to replay"
                                + (f" ({'; '.join(self.reader.problems)})" if self.reader.problems else ""))
        self.position = 0  # index into the timeline of the next step
        self.paused = False
        self.steps_left: int | None = None  # frames to run before pausing again (stepping)
        self._pending: dict[str, _Frame] = {}
        self._lock = threading.Lock()
        self._by_context = {c: [f for step in self.timeline for f in step if f.context == c] for c in self.provides}
        self._cursors: dict[str, int] = {}
        self._cache: OrderedDict[int, dict[tuple[str, int], dict[str, bytes]]] = OrderedDict()

    @property
    def path(self) -> str:
        return str(self.reader.path)

    @classmethod
    def add_arguments(cls, parser: argparse.ArgumentParser) -> None:
        parser.add_argument("--log", help="log: the MCAP file to replay")
        parser.add_argument("--loop", action="store_true", help="log: start again at the end")
        parser.add_argument("--replace", default="", metavar="A,B",
                            help="log: also feed these recorded representations, replacing their modules")

    # -------------------------------------------------------------------------------- set-up
    @staticmethod
    def _fed_topics(reader: LogReader, replace: list[str]) -> dict[str, list[str]]:
        """Per context, the recorded topics replay feeds: what the recording platform provided, and
        what ``--replace`` names. Recorded module outputs are only there to compare against."""
        recorded = {c.representation for c in reader.channels.values()}
        unknown = [name for name in replace if name not in recorded]
        if unknown:
            raise PlatformOptionError(
                f"--replace names {', '.join(unknown)}, which the log does not hold; "
                + did_you_mean(unknown[0], sorted(recorded))
            )
        topics: dict[str, list[str]] = {}
        for topic, channel in reader.channels.items():
            if channel.metadata.get("source") == "platform" or channel.representation in replace:
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

    def _timeline(self) -> list[list[_Frame]]:
        """Steps in recorded order: the frames of all contexts that share one time.

        One pass over the file; only frame numbers, times and chunk numbers are kept, so memory does
        not grow with the size of what was recorded.
        """
        found: dict[tuple[str, int], tuple[int, set[int]]] = {}
        for number, messages in self.reader.iter_chunks():
            for message in messages:
                if message.topic in self.classes:
                    key = (self.reader.channels[message.topic].context, message.sequence)
                    time_ns, chunks = found.setdefault(key, (message.time_ns, set()))
                    chunks.add(number)
        frames = [_Frame(context, sequence, time_ns, tuple(sorted(chunks))) for (context, sequence), (time_ns, chunks) in found.items()]
        frames.sort(key=lambda f: (f.time_ns, CONTEXT_ORDER.index(f.context) if f.context in CONTEXT_ORDER else 9, f.number))
        steps: list[list[_Frame]] = []
        for frame in frames:
            if steps and steps[-1][0].time_ns == frame.time_ns and all(f.context != frame.context for f in steps[-1]):
                steps[-1].append(frame)
            else:
                steps.append([frame])
        return steps

    def config_layers(self) -> list[str]:
        """The recording platform's layer first, so that replay runs the program that was recorded."""
        recorded = self.reader.metadata.get("platform", "")
        return [recorded, self.name] if recorded and recorded != self.name else [self.name]

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
            if self.position >= len(self.timeline):
                if not self.loop:
                    raise EndOfData(f"end of log {self.path}")
                self.position = 0
            step = self.timeline[self.position]
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
        for topic, data in self._messages_of(frame).items():
            try:
                # each channel's schema was checked against its class when the log was opened
                blackboard.set(self.decoders[topic](data))
            except Exception as exc:  # noqa: BLE001 - a damaged message is reported, the replay goes on
                log.error("%s frame %d of %s: cannot decode: %s", self.path, frame.number, topic, exc)

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
        frames = self._by_context.get(context, [])
        index = self._cursors.get(context, 0)
        if index >= len(frames):
            if not self.loop or not frames:
                raise EndOfData(f"end of log {self.path}")
            index = 0
        self._cursors[context] = index + 1
        return frames[index]

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
        """Pause at the step holding ``frame_number`` of the main context (or of ``context``)."""
        context = context or ("motion" if any(f.context == "motion" for s in self.timeline for f in s) else "cognition")
        for index, step in enumerate(self.timeline):
            if any(f.context == context and f.number == frame_number for f in step):
                with self._lock:
                    self.position, self.paused, self.steps_left = index, True, None
                return
        numbers = [f.number for s in self.timeline for f in s if f.context == context]
        raise PlatformError(
            f"the log has no {context} frame {frame_number}; its {context} frames are {min(numbers)}..{max(numbers)}"
            if numbers else f"the log has no {context} frames"
        )

    def status(self) -> dict[str, Any]:
        with self._lock:
            current = self.timeline[min(self.position, len(self.timeline)) - 1] if self.position else []
        return {
            "file": self.path,
            "paused": self.paused,
            "step": self.position,
            "steps": len(self.timeline),
            "frames": {f.context: f.number for f in current},
        }

    def stop(self) -> None:
        self.reader.close()
