"""MCAP log files of representations: writing in the background, reading even what a crash left behind.

Layout: one channel per context and representation, topic ``<context>/<RepresentationName>``, protobuf
encoding with the schema as a FileDescriptorSet (so Foxglove and the ``mcap`` tool read it, and a
reader with only ``mcap`` and ``protobuf`` decodes it), publish time = frame time in nanoseconds (what
replay uses), log time = wall-clock time at recording (ns since the epoch, what viewers show), sequence
= frame number. Channel metadata says who wrote the representation (``source`` = ``platform`` or
``module``), and a ``tafel`` metadata record holds the rates and the platform of the run.

Other channels may ride along (``translate``: Foxglove's well-known messages, computed from the
representations in the writer thread); their topics start with ``/`` and replay leaves them alone.

The writer never blocks the loop that records: messages go into a bounded queue and a background
thread writes them; when the queue is full a message is dropped and counted. The thread closes a chunk
at least every ``flush_interval`` seconds, so a process killed with SIGKILL loses at most that much.
"""

from __future__ import annotations

import io
import logging
import os
import queue
import threading
import time
from collections.abc import Callable, Iterable, Iterator, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from google.protobuf import descriptor_pb2
from mcap.data_stream import ReadDataStream
from mcap.opcode import Opcode
from mcap.reader import SeekingReader
from mcap.records import Channel, Chunk, Message, Metadata, Schema
from mcap.stream_reader import breakup_chunk
from mcap.writer import CompressionType, Writer

from tafel.core.errors import TafelError
from tafel.core.serialization import file_descriptor_set, message_name

PROFILE = "tafel"
MAGIC = b"\x89MCAP0\r\n"
#: ns of log time one chunk holds at the most, so a cut-off file loses at most this much
CHUNK_SPAN_NS = 1_000_000_000
log = logging.getLogger("tafel.log")


class LogError(TafelError, RuntimeError):
    """A log file that cannot be written, or read (with the file and the position)."""


#: topics of channels that are not representations (Foxglove's) start with this
EXTRA_TOPIC_PREFIX = "/"


@dataclass
class _Item:
    topic: str
    cls: type
    time_ns: int
    sequence: int
    data: bytes
    metadata: Mapping[str, str]
    wall_ns: int = 0


@dataclass
class ExtraMessage:
    """A message of a channel that is not a representation, with its schema (written as given)."""

    topic: str
    schema_name: str
    schema_encoding: str  # "protobuf" or "jsonschema"
    schema_data: bytes
    message_encoding: str  # "protobuf" or "json"
    data: bytes
    time_ns: int  # frame time
    wall_ns: int  # wall-clock time (ns since the epoch)


#: what a ``LogWriter`` may be given to add channels: called in the writer thread with every
#: representation message (topic, class, frame time, wall time, protobuf bytes)
Translate = Callable[[str, type, int, int, bytes], Iterable[ExtraMessage]]

class _ExtraChannels:
    """Channels that are not representations in an MCAP writer: registered as their messages come."""

    def __init__(self, writer: Writer) -> None:
        self.writer = writer
        self.schemas: dict[tuple[str, str], int] = {}
        self.channels: dict[str, int] = {}

    def add(self, extra: ExtraMessage) -> None:
        channel = self.channels.get(extra.topic)
        if channel is None:
            key = (extra.schema_name, extra.schema_encoding)
            if key not in self.schemas:
                self.schemas[key] = self.writer.register_schema(name=extra.schema_name, encoding=extra.schema_encoding,
                                                                data=extra.schema_data)
            channel = self.channels[extra.topic] = self.writer.register_channel(
                topic=extra.topic, message_encoding=extra.message_encoding, schema_id=self.schemas[key])
        self.writer.add_message(channel, log_time=extra.wall_ns, data=extra.data, publish_time=extra.time_ns)


class LogWriter:
    """Writes representation messages to an MCAP file from a background thread."""

    def __init__(self, path: str | Path, *, metadata: Mapping[str, str] | None = None, queue_size: int = 4096,
                 flush_interval: float = 0.5, chunk_size: int = 4 << 20, translate: Translate | None = None) -> None:
        self.path = Path(path)
        self.translate = translate
        try:
            self._stream = open(self.path, "wb")  # noqa: SIM115 - closed by close()
        except OSError as exc:
            raise LogError(f"cannot write log {self.path}: {exc.strerror}") from None
        self._writer = Writer(self._stream, chunk_size=chunk_size, compression=CompressionType.ZSTD)
        self._writer.start(profile=PROFILE, library="tafel")
        if metadata:
            self._writer.add_metadata("tafel", dict(metadata))
        self._queue: queue.Queue[_Item | ExtraMessage | None] = queue.Queue(maxsize=queue_size)
        self._channels: dict[str, int] = {}
        self._schemas: dict[type, int] = {}
        self._extras = _ExtraChannels(self._writer)
        self.flush_interval = flush_interval
        self.blocking = False
        self.written = 0
        self.dropped = 0
        self.bytes_written = 0
        self.error = ""
        #: a write to the file failed (disk full, say): recording stopped, what was written stays readable
        self.failed = False
        self._closed = False
        self._thread = threading.Thread(target=self._run, name="tafel-log-writer", daemon=True)
        self._thread.start()

    def write(self, topic: str, cls: type, time_ns: int, sequence: int, data: bytes,
              metadata: Mapping[str, str] | None = None) -> bool:
        """Queue one message; returns False (and counts it) when it had to be dropped.

        With ``blocking`` set (a run without a beat to keep, ``--speed max``) it waits for room instead.
        """
        return self._queue_item(_Item(topic, cls, time_ns, sequence, data, metadata or {}, time.time_ns()), self.blocking)

    def write_extra(self, extra: ExtraMessage) -> bool:
        """Queue one message of a channel that is not a representation (any thread; never blocks)."""
        return self._queue_item(extra, False)

    def _queue_item(self, item: _Item | ExtraMessage, wait: bool) -> bool:
        if self._closed or self.failed:
            return False
        try:
            if wait:
                self._queue.put(item)
            else:
                self._queue.put_nowait(item)
            return True
        except queue.Full:
            self.dropped += 1
            return False

    def close(self) -> None:
        """Write what is queued, finish the file (summary and index) and close it."""
        if self._closed:
            return
        self._closed = True
        if not self.failed:
            self._queue.put(None)
        self._thread.join()
        if not self.failed:
            try:
                self._writer.finish()
            except Exception as exc:  # noqa: BLE001 - report, never lose the rest
                self.error = self.error or f"{type(exc).__name__}: {exc}"
        try:
            self._stream.close()
        except OSError as exc:  # the last buffered bytes did not fit either: what is on disk stays
            self.error = self.error or f"{type(exc).__name__}: {exc}"

    def _run(self) -> None:
        last_flush = time.monotonic()
        chunk_start_ns: int | None = None  # log time of the first message in the open chunk
        while True:
            try:
                item = self._queue.get(timeout=self.flush_interval)
            except queue.Empty:
                item = _Item("", type(None), 0, 0, b"", {})  # nothing came: just flush
            if item is None:
                return
            try:
                if isinstance(item, ExtraMessage):  # a log line, say: written as it comes
                    self.add_extra(item)
                    continue
                # a chunk holds at most CHUNK_SPAN_NS of log time, at any speed, and at most
                # flush_interval of wall time: a cut-off file loses only its last chunk
                if item.topic and chunk_start_ns is not None and abs(item.time_ns - chunk_start_ns) >= CHUNK_SPAN_NS:
                    self._writer.flush()
                    last_flush, chunk_start_ns = time.monotonic(), None
                if item.topic:
                    self._add(item)
                    if self.translate is not None:
                        for extra in self.translate(item.topic, item.cls, item.time_ns, item.wall_ns, item.data):
                            self.add_extra(extra)
                    chunk_start_ns = item.time_ns if chunk_start_ns is None else chunk_start_ns
                if time.monotonic() - last_flush >= self.flush_interval:
                    self._writer.flush()
                    last_flush, chunk_start_ns = time.monotonic(), None
            except OSError as exc:  # a full disk, a quota, a gone USB stick: stop cleanly, keep what is written
                self._fail(exc)
                return
            except Exception as exc:  # noqa: BLE001 - a bad message must not kill the program
                self.error = f"{type(exc).__name__}: {exc}"
                self.dropped += 1

    def _fail(self, exc: OSError) -> None:
        """The first write error: say so at once, stop recording, keep every chunk already on disk."""
        self.failed = True
        self.error = f"{exc.strerror or exc} (errno {exc.errno})" if exc.errno else f"{type(exc).__name__}: {exc}"
        log.error("recording to %s stopped: %s; the %d messages written before are kept", self.path, self.error, self.written)
        while True:  # whoever waits for room in the queue (a blocking writer) goes on
            try:
                self._queue.get_nowait()
            except queue.Empty:
                break

    def _add(self, item: _Item) -> None:
        channel = self._channels.get(item.topic)
        if channel is None:
            schema = self._schemas.get(item.cls)
            if schema is None:
                schema = self._schemas[item.cls] = self._writer.register_schema(
                    name=message_name(item.cls), encoding="protobuf", data=file_descriptor_set(item.cls)
                )
            channel = self._channels[item.topic] = self._writer.register_channel(
                topic=item.topic, message_encoding="protobuf", schema_id=schema, metadata=dict(item.metadata)
            )
        self._writer.add_message(channel, log_time=item.wall_ns or item.time_ns, data=item.data, publish_time=item.time_ns,
                                 sequence=item.sequence)
        self.written += 1
        self.bytes_written += len(item.data)

    def add_extra(self, extra: ExtraMessage) -> None:
        """Write one message of a channel that is not a representation (writer thread only)."""
        self._extras.add(extra)
        self.written += 1
        self.bytes_written += len(extra.data)


@dataclass
class LogMessage:
    topic: str
    time_ns: int  # frame time (the publish time)
    sequence: int
    data: bytes
    #: wall-clock time of the recording (ns since the epoch); logs from before 0.3 hold the frame time here
    log_time_ns: int = 0


@dataclass
class LogChannel:
    topic: str
    schema_name: str
    schema: descriptor_pb2.FileDescriptorProto | None
    metadata: dict[str, str]
    messages: int = 0
    bytes: int = 0
    #: the schema as stored (a protobuf FileDescriptorSet), to copy the channel into another log
    schema_data: bytes = b""

    @property
    def context(self) -> str:
        return self.topic.split("/", 1)[0]

    @property
    def representation(self) -> str:
        return self.topic.split("/", 1)[-1]



@dataclass(frozen=True)
class ChunkInfo:
    """Where one chunk of messages lies in the file, and the log times it covers."""

    offset: int
    start_ns: int
    end_ns: int


class LogReader:
    """Reads an MCAP log chunk by chunk, never the whole file at once.

    An intact file is read through its summary (channels, metadata and the chunk index); a file
    without one (the recording was cut off) is walked record by record once to find its chunks.
    A damaged chunk is skipped with a warning and reading goes on with the next one; a file cut off
    in the middle yields everything before the cut. ``problems`` lists what was skipped and why.
    """

    def __init__(self, path: str | Path) -> None:
        self.path = Path(path)
        try:
            self._file = open(self.path, "rb")  # noqa: SIM115 - closed by close()
            self.size = os.fstat(self._file.fileno()).st_size
        except OSError as exc:
            raise LogError(f"cannot read log {self.path}: {exc.strerror or exc}") from None
        if self._file.read(len(MAGIC)) != MAGIC:
            self.close()
            raise LogError(f"{self.path} is not an MCAP log (it does not start with the MCAP magic bytes)")
        self.channels: dict[str, LogChannel] = {}
        #: channels that are not representations (topic -> schema name), e.g. the Foxglove ones
        self.extra_channels: dict[str, str] = {}
        self.metadata: dict[str, str] = {}
        self.chunks: list[ChunkInfo] = []
        self.complete = True
        self.problems: list[str] = []
        self._schemas: dict[int, Schema] = {}
        self._topics: dict[int, str] = {}
        self._warned: set[int] = set()
        if not self._read_summary():
            self._walk()
            for _ in self.iter_chunks():  # channels are defined inside the chunks: find them all once
                pass
            if not self.chunks and not self.complete:
                self.close()
                raise LogError(f"{self.path}: nothing can be read: {self.problems[0]}")

    # ------------------------------------------------------------------------------- opening
    def _read_summary(self) -> bool:
        """Channels, metadata and chunks from the summary section; False when there is none."""
        try:
            reader = SeekingReader(self._file, record_size_limit=self.size)
            summary = reader.get_summary()
        except Exception:  # noqa: BLE001 - no intact summary: walk the file instead
            return False
        if summary is None:
            return False
        for schema in summary.schemas.values():
            self._schemas[schema.id] = schema
        for channel in summary.channels.values():
            self._add_channel(channel)
        try:
            for record in reader.iter_metadata():
                if record.name == PROFILE:
                    self.metadata.update(record.metadata)
        except Exception as exc:  # noqa: BLE001 - metadata is a convenience; the messages matter
            self._problem(f"{self.path}: the run's metadata cannot be read: {exc}")
        self.chunks = sorted((ChunkInfo(c.chunk_start_offset, c.message_start_time, c.message_end_time)
                              for c in summary.chunk_indexes), key=lambda c: c.offset)
        return True

    def _walk(self) -> None:
        """Find chunks, schemas, channels and metadata by walking the records from the start."""
        position = len(MAGIC)
        while True:
            self._file.seek(position)
            head = self._file.read(9)
            if len(head) < 9:
                self.complete = False
                self._problem(f"{self.path}: the file ends at byte {self.size} without the MCAP footer (the recording was cut off)")
                return
            opcode, length = head[0], int.from_bytes(head[1:], "little")
            if position + 9 + length > self.size:
                self.complete = False
                self._problem(f"{self.path}: the record at byte {position} runs past the end of the file "
                              f"(byte {self.size}): the recording was cut off")
                return
            if opcode == Opcode.CHUNK:
                times = self._file.read(16)
                self.chunks.append(ChunkInfo(position, int.from_bytes(times[:8], "little"), int.from_bytes(times[8:], "little")))
            elif opcode in (Opcode.SCHEMA, Opcode.CHANNEL, Opcode.METADATA):
                try:
                    self._register(_RECORD_TYPES[opcode].read(ReadDataStream(io.BytesIO(self._file.read(length)))))
                except Exception as exc:  # noqa: BLE001 - a damaged record is skipped, the rest read
                    self._problem(f"{self.path}: damaged record at byte {position} skipped ({type(exc).__name__}: {exc})")
            elif opcode in (Opcode.DATA_END, Opcode.FOOTER):
                return
            elif opcode not in _KNOWN_OPCODES:
                self.complete = False
                self._problem(f"{self.path}: unknown record (opcode {opcode:#x}) at byte {position}: the file is damaged from here on")
                return
            position += 9 + length

    def _register(self, record: Any) -> None:
        if isinstance(record, Schema):
            self._schemas[record.id] = record
        elif isinstance(record, Channel):
            self._add_channel(record)
        elif isinstance(record, Metadata) and record.name == PROFILE:
            self.metadata.update(record.metadata)

    def _add_channel(self, record: Channel) -> None:
        schema = self._schemas.get(record.schema_id)
        if record.topic.startswith(EXTRA_TOPIC_PREFIX):  # Foxglove's channels: listed, never read as representations
            self.extra_channels.setdefault(record.topic, schema.name if schema else "")
            return
        self._topics[record.id] = record.topic
        if record.topic not in self.channels:
            self.channels[record.topic] = LogChannel(record.topic, schema.name if schema else "", _file_of(schema), dict(record.metadata),
                                                     schema_data=bytes(schema.data) if schema else b"")

    def _problem(self, text: str) -> None:
        self.problems.append(text)
        log.warning("%s", text)

    # ------------------------------------------------------------------------------- reading
    def iter_chunks(self, start_ns: int | None = None) -> Iterator[tuple[int, list[LogMessage]]]:
        """(chunk number, its messages in file order) for every readable chunk ending at or after ``start_ns``."""
        for number, chunk in enumerate(self.chunks):
            if start_ns is not None and chunk.end_ns < start_ns:
                continue
            messages = self.read_chunk(number)
            if messages is not None:
                yield number, messages

    def read_chunk(self, number: int) -> list[LogMessage] | None:
        """The messages of one chunk; None (and a warning, once) when the chunk is damaged."""
        chunk = self.chunks[number]
        try:
            self._file.seek(chunk.offset)
            head = self._file.read(9)
            if len(head) < 9 or head[0] != Opcode.CHUNK:
                raise LogError("no chunk record there")
            records = breakup_chunk(Chunk.read(ReadDataStream(io.BytesIO(self._file.read(int.from_bytes(head[1:], "little"))))),
                                    validate_crc=True)
        except Exception as exc:  # noqa: BLE001 - whatever the damage, skip this chunk and go on
            if number not in self._warned:
                self._warned.add(number)
                self._problem(f"{self.path}: the chunk at byte {chunk.offset} is damaged ({type(exc).__name__}: {exc}); "
                              "skipped, reading on with the next chunk")
            return None
        messages = []
        for record in records:
            if isinstance(record, Message):
                topic = self._topics.get(record.channel_id)
                if topic is not None:
                    messages.append(LogMessage(topic, record.publish_time, record.sequence, record.data, record.log_time))
            else:
                self._register(record)
        return messages

    def messages(self, topics: Iterable[str] | None = None, start_ns: int | None = None) -> Iterator[LogMessage]:
        """Every readable message (of ``topics``, from frame time ``start_ns`` on), chunk by chunk in file order."""
        wanted = None if topics is None else set(topics)
        for _number, messages in self.iter_chunks():  # chunks are indexed by log (wall) time, not frame time
            for message in messages:
                if (wanted is None or message.topic in wanted) and (start_ns is None or message.time_ns >= start_ns):
                    yield message

    def summary(self) -> dict[str, Any]:
        """Duration, frames per context and channels with counts and sizes, from one pass (``tafel log info``)."""
        for channel in self.channels.values():
            channel.messages = channel.bytes = 0
        first, last = None, None
        frames: dict[str, set[int]] = {}
        for message in self.messages():
            channel = self.channels[message.topic]
            channel.messages += 1
            channel.bytes += len(message.data)
            first = message.time_ns if first is None else min(first, message.time_ns)
            last = message.time_ns if last is None else max(last, message.time_ns)
            frames.setdefault(channel.context, set()).add(message.sequence)
        return {
            "file": str(self.path),
            "bytes": self.size,
            "complete": self.complete and not self.problems,
            "problem": "; ".join(self.problems),
            "duration_s": (last - first) * 1e-9 if first is not None and last is not None else 0.0,
            "frames": {context: len(numbers) for context, numbers in sorted(frames.items())},
            "channels": {
                topic: {"messages": c.messages, "bytes": c.bytes, "schema": c.schema_name, **c.metadata}
                for topic, c in sorted(self.channels.items())
            },
            "metadata": dict(self.metadata),
            "extra_channels": dict(sorted(self.extra_channels.items())),
        }

    def close(self) -> None:
        self._file.close()

    def __enter__(self) -> LogReader:
        return self

    def __exit__(self, *_exc: object) -> None:
        self.close()


_RECORD_TYPES: dict[int, Any] = {Opcode.SCHEMA: Schema, Opcode.CHANNEL: Channel, Opcode.METADATA: Metadata}
_KNOWN_OPCODES = {int(op) for op in Opcode}


@dataclass
class LogContents:
    """A whole log in memory, messages in file order: for tests and small logs (tools stream instead)."""

    path: Path
    channels: dict[str, LogChannel] = field(default_factory=dict)
    messages: list[LogMessage] = field(default_factory=list)
    metadata: dict[str, str] = field(default_factory=dict)
    complete: bool = True
    #: why reading stopped early or skipped something (a truncated or damaged file), with the byte position
    problem: str = ""

    def frames(self, context: str) -> dict[int, dict[str, LogMessage]]:
        """Frame number -> representation name -> message, for one context."""
        result: dict[int, dict[str, LogMessage]] = {}
        for message in self.messages:
            channel = self.channels[message.topic]
            if channel.context == context:
                result.setdefault(message.sequence, {})[channel.representation] = message
        return result


def read_log(path: str | Path) -> LogContents:
    """Read a whole MCAP log into memory; a truncated file yields what was complete and says where it stopped.

    Raises ``LogError`` naming the file for files that are missing, unreadable, not MCAP at all, or
    hold nothing readable. Programs that handle long logs use ``LogReader``, which streams.
    """
    with LogReader(path) as reader:
        messages = list(reader.messages())
        for message in messages:
            channel = reader.channels[message.topic]
            channel.messages += 1
            channel.bytes += len(message.data)
        return LogContents(path=reader.path, channels=reader.channels, messages=messages, metadata=reader.metadata,
                           complete=reader.complete and not reader.problems, problem="; ".join(reader.problems))


def write_slice(source: str | Path, target: str | Path, *, representations: Iterable[str] | None = None,
                start_s: float = 0.0, seconds: float | None = None, translate: Translate | None = None) -> dict[str, int]:
    """Copy part of a log into a new one: the chosen representations (all without a choice), from
    ``start_s`` after the log's first message for ``seconds``. Schemas, channel metadata and the
    recording's metadata travel along, so the slice replays and decodes like the original.

    ``translate`` adds channels made from the copied messages (``tafel log convert``: Foxglove's). A log
    from before wall-clock log times gets them: its frame times moved to end when the file was last
    written. Returns messages per topic. Raises ``LogError`` when nothing would be copied.
    """
    from tafel.core.representation import get_representation

    wanted = set(representations) if representations else None
    with LogReader(source) as reader:
        topics = [t for t, c in reader.channels.items() if wanted is None or c.representation in wanted]
        if wanted is not None and (unknown := wanted - {reader.channels[t].representation for t in topics}):
            from tafel.core.naming import did_you_mean

            names = sorted({c.representation for c in reader.channels.values()})
            name = sorted(unknown)[0]
            raise LogError(f"{source} holds no representation {name!r}; {did_you_mean(name, names)}")
        first = next(iter(reader.messages(topics)), None)
        if first is None:
            raise LogError(f"{source} holds no messages of {', '.join(sorted(wanted or []) or 'any channel')}")
        begin = first.time_ns + int(start_s * 1e9)
        end = None if seconds is None else begin + int(seconds * 1e9)
        last_ns = max((c.end_ns for c in reader.chunks), default=0)
        anchor_ns = os.stat(source).st_mtime_ns - last_ns  # for logs whose log times are frame times
        counts: dict[str, int] = {}
        with open(target, "wb") as stream:
            writer = Writer(stream, compression=CompressionType.ZSTD)
            writer.start(profile=PROFILE, library="tafel")
            if reader.metadata:
                writer.add_metadata(PROFILE, {**reader.metadata, "sliced_from": Path(source).name,
                                              "slice_start_s": f"{start_s:g}"})
            schema_ids: dict[str, int] = {}
            channel_ids: dict[str, int] = {}
            extras = _ExtraChannels(writer)
            for message in reader.messages(topics, start_ns=begin):
                if message.time_ns < begin or (end is not None and message.time_ns >= end):
                    continue
                channel = reader.channels[message.topic]
                if message.topic not in channel_ids:
                    if channel.schema_name not in schema_ids:
                        schema_ids[channel.schema_name] = writer.register_schema(
                            name=channel.schema_name, encoding="protobuf", data=channel.schema_data)
                    channel_ids[message.topic] = writer.register_channel(
                        topic=message.topic, message_encoding="protobuf", schema_id=schema_ids[channel.schema_name],
                        metadata=dict(channel.metadata))
                wall_ns = message.log_time_ns if message.log_time_ns != message.time_ns else anchor_ns + message.time_ns
                writer.add_message(channel_ids[message.topic], log_time=wall_ns, data=message.data,
                                   publish_time=message.time_ns, sequence=message.sequence)
                counts[message.topic] = counts.get(message.topic, 0) + 1
                if translate is not None:
                    try:
                        cls = get_representation(channel.representation)
                    except KeyError:
                        continue
                    for extra in translate(message.topic, cls, message.time_ns, wall_ns, message.data):
                        extras.add(extra)
                        counts[extra.topic] = counts.get(extra.topic, 0) + 1
            writer.finish()
    if not counts:
        Path(target).unlink(missing_ok=True)
        raise LogError(f"{source}: no message between {start_s:g} s and {'the end' if seconds is None else f'{start_s + seconds:g} s'}")
    return counts


def _file_of(schema: Schema | None) -> descriptor_pb2.FileDescriptorProto | None:
    if schema is None or schema.encoding != "protobuf":
        return None
    fds = descriptor_pb2.FileDescriptorSet.FromString(schema.data)
    wanted = schema.name.rsplit(".", 1)[-1]
    for file in fds.file:
        if any(m.name == wanted for m in file.message_type):
            return file
    return fds.file[0] if fds.file else None
