"""MCAP log files of representations: writing in the background, reading even what a crash left behind.

Layout: one channel per context and representation, topic ``<context>/<RepresentationName>``, protobuf
encoding with the schema as a FileDescriptorSet (so Foxglove and the ``mcap`` tool read it, and a
reader with only ``mcap`` and ``protobuf`` decodes it), log time = frame time in nanoseconds, sequence
= frame number. Channel metadata says who wrote the representation (``source`` = ``platform`` or
``module``), and a ``tafel`` metadata record holds the rates and the platform of the run.

The writer never blocks the loop that records: messages go into a bounded queue and a background
thread writes them; when the queue is full a message is dropped and counted. The thread closes a chunk
at least every ``flush_interval`` seconds, so a process killed with SIGKILL loses at most that much.
"""

from __future__ import annotations

import io
import queue
import threading
import time
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from google.protobuf import descriptor_pb2
from mcap.records import Channel, Message, Metadata, Schema
from mcap.stream_reader import StreamReader
from mcap.writer import CompressionType, Writer

from tafel.core.errors import TafelError
from tafel.core.serialization import file_descriptor_set, message_name

PROFILE = "tafel"


class LogError(TafelError, RuntimeError):
    """A log file that cannot be written, or read (with the file and the position)."""


@dataclass
class _Item:
    topic: str
    cls: type
    time_ns: int
    sequence: int
    data: bytes
    metadata: Mapping[str, str]


class LogWriter:
    """Writes representation messages to an MCAP file from a background thread."""

    def __init__(self, path: str | Path, *, metadata: Mapping[str, str] | None = None, queue_size: int = 4096,
                 flush_interval: float = 0.5, chunk_size: int = 4 << 20) -> None:
        self.path = Path(path)
        try:
            self._stream = open(self.path, "wb")  # noqa: SIM115 - closed by close()
        except OSError as exc:
            raise LogError(f"cannot write log {self.path}: {exc.strerror}") from None
        self._writer = Writer(self._stream, chunk_size=chunk_size, compression=CompressionType.ZSTD)
        self._writer.start(profile=PROFILE, library="tafel")
        if metadata:
            self._writer.add_metadata("tafel", dict(metadata))
        self._queue: queue.Queue[_Item | None] = queue.Queue(maxsize=queue_size)
        self._channels: dict[str, int] = {}
        self._schemas: dict[type, int] = {}
        self.flush_interval = flush_interval
        self.blocking = False
        self.written = 0
        self.dropped = 0
        self.bytes_written = 0
        self.error = ""
        self._closed = False
        self._thread = threading.Thread(target=self._run, name="tafel-log-writer", daemon=True)
        self._thread.start()

    def write(self, topic: str, cls: type, time_ns: int, sequence: int, data: bytes,
              metadata: Mapping[str, str] | None = None) -> bool:
        """Queue one message; returns False (and counts it) when it had to be dropped.

        With ``blocking`` set (a run without a beat to keep, ``--speed max``) it waits for room instead.
        """
        if self._closed:
            return False
        item = _Item(topic, cls, time_ns, sequence, data, metadata or {})
        try:
            if self.blocking:
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
        self._queue.put(None)
        self._thread.join()
        try:
            self._writer.finish()
        except Exception as exc:  # noqa: BLE001 - report, never lose the rest
            self.error = self.error or f"{type(exc).__name__}: {exc}"
        self._stream.close()

    def _run(self) -> None:
        last_flush = time.monotonic()
        while True:
            try:
                item = self._queue.get(timeout=self.flush_interval)
            except queue.Empty:
                item = _Item("", type(None), 0, 0, b"", {})  # nothing came: just flush
            if item is None:
                return
            try:
                if item.topic:
                    self._add(item)
                if time.monotonic() - last_flush >= self.flush_interval:
                    self._writer.flush()
                    last_flush = time.monotonic()
            except Exception as exc:  # noqa: BLE001 - a full disk must not kill the program
                self.error = f"{type(exc).__name__}: {exc}"
                self.dropped += 1

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
        self._writer.add_message(channel, log_time=item.time_ns, data=item.data, publish_time=item.time_ns, sequence=item.sequence)
        self.written += 1
        self.bytes_written += len(item.data)


@dataclass
class LogMessage:
    topic: str
    time_ns: int
    sequence: int
    data: bytes


@dataclass
class LogChannel:
    topic: str
    schema_name: str
    schema: descriptor_pb2.FileDescriptorProto | None
    metadata: dict[str, str]
    messages: int = 0
    bytes: int = 0

    @property
    def context(self) -> str:
        return self.topic.split("/", 1)[0]

    @property
    def representation(self) -> str:
        return self.topic.split("/", 1)[-1]


@dataclass
class LogContents:
    """Everything read from a log file (messages in file order)."""

    path: Path
    channels: dict[str, LogChannel] = field(default_factory=dict)
    messages: list[LogMessage] = field(default_factory=list)
    metadata: dict[str, str] = field(default_factory=dict)
    complete: bool = True
    #: why reading stopped early (a truncated or damaged file), with the byte position
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
    """Read a whole MCAP log; a truncated file yields what was complete and says where it stopped.

    Raises ``LogError`` naming the file for files that are missing, unreadable or not MCAP at all.
    """
    path = Path(path)
    try:
        data = path.read_bytes()
    except OSError as exc:
        raise LogError(f"cannot read log {path}: {exc.strerror or exc}") from None
    if not data.startswith(b"\x89MCAP0\r\n"):
        raise LogError(f"{path} is not an MCAP log (it does not start with the MCAP magic bytes)")
    contents = LogContents(path=path)
    stream = io.BytesIO(data)
    reader = StreamReader(stream, skip_magic=False, validate_crcs=True)
    schemas: dict[int, Schema] = {}
    channel_ids: dict[int, str] = {}
    try:
        for record in reader.records:
            if isinstance(record, Schema):
                schemas[record.id] = record
            elif isinstance(record, Channel):
                if record.topic not in contents.channels:
                    schema = schemas.get(record.schema_id)
                    contents.channels[record.topic] = LogChannel(
                        record.topic, schema.name if schema else "", _file_of(schema), dict(record.metadata)
                    )
                channel_ids[record.id] = record.topic
            elif isinstance(record, Message):
                topic = channel_ids.get(record.channel_id)
                if topic is None:
                    continue
                contents.messages.append(LogMessage(topic, record.log_time, record.sequence, record.data))
                channel = contents.channels[topic]
                channel.messages += 1
                channel.bytes += len(record.data)
            elif isinstance(record, Metadata) and record.name == "tafel":
                contents.metadata.update(record.metadata)
    except Exception as exc:  # noqa: BLE001 - any damage ends reading, whatever the reader raises
        contents.complete = False
        contents.problem = f"{path}: stopped reading at byte {stream.tell()} of {len(data)}: {type(exc).__name__}: {exc}"
    if contents.complete and not data.endswith(b"\x89MCAP0\r\n"):
        contents.complete = False
        contents.problem = f"{path}: the file ends at byte {len(data)} without the MCAP footer (the recording was cut off)"
    return contents


def _file_of(schema: Schema | None) -> descriptor_pb2.FileDescriptorProto | None:
    if schema is None or schema.encoding != "protobuf":
        return None
    fds = descriptor_pb2.FileDescriptorSet.FromString(schema.data)
    wanted = schema.name.rsplit(".", 1)[-1]
    for file in fds.file:
        if any(m.name == wanted for m in file.message_type):
            return file
    return fds.file[0] if fds.file else None


def as_dict(contents: LogContents) -> dict[str, Any]:
    """A summary of the log as plain data (for ``tafel log info``)."""
    times = [m.time_ns for m in contents.messages]
    per_context: dict[str, set[int]] = {}
    for message in contents.messages:
        per_context.setdefault(contents.channels[message.topic].context, set()).add(message.sequence)
    return {
        "file": str(contents.path),
        "complete": contents.complete,
        "problem": contents.problem,
        "duration_s": (max(times) - min(times)) * 1e-9 if times else 0.0,
        "frames": {context: len(frames) for context, frames in sorted(per_context.items())},
        "channels": {
            topic: {"messages": c.messages, "bytes": c.bytes, "schema": c.schema_name, **c.metadata}
            for topic, c in sorted(contents.channels.items())
        },
        "metadata": contents.metadata,
    }
