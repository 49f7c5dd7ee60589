"""MCAP log files of representations: writing in the background, reading even what a crash left behind.

Layout: one channel per context and representation, topic ``<context>/<RepresentationName>``, protobuf
encoding with the schema as a FileDescriptorSet (so Foxglove and the ``mcap`` tool read it, and a
reader with only ``mcap`` and ``protobuf`` decodes it), publish time = frame time in nanoseconds (what
replay uses), log time = wall-clock time at recording (ns since the epoch, what viewers show), sequence
= frame number. Channel metadata says who wrote the representation (``source`` = ``platform``,
``module``, ``runtime`` for ``FrameInfo``, which logs before it name ``platform``, or ``debug``), and a ``tafel`` metadata record holds the rates and the platform of the run.

Other channels may ride along (``translate``: Foxglove's well-known messages, computed from the
representations in the writer thread); their topics start with ``/`` and replay leaves them alone.

The writer never blocks the loop that records: messages go into a bounded queue and a background
thread writes them; when the queue is full a message is dropped and counted. The thread closes a chunk
at least every ``flush_interval`` seconds, so a process killed with SIGKILL loses at most that much.
"""

from __future__ import annotations

import atexit
import queue
import threading
import time
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass
from pathlib import Path

from mcap.writer import CompressionType, Writer

from tafel.core.logs.format import CHUNK_SPAN_NS, PROFILE, LogError, LogExistsError, log
from tafel.core.logs.serialization import file_descriptor_set, message_name


@dataclass
class PendingMessage:
    """One message on its way into a log: its channel, class, frame time (ns), frame number, bytes,
    channel metadata, and the wall-clock time it was taken (ns since the epoch; 0: when written)."""

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
                 flush_interval: float = 0.5, chunk_size: int = 4 << 20, translate: Translate | None = None,
                 exclusive: bool = False) -> None:
        """``exclusive``: never replace an existing file (``LogExistsError`` instead), decided atomically."""
        self.path = Path(path)
        self.translate = translate
        try:
            self._stream = open(self.path, "xb" if exclusive else "wb")  # noqa: SIM115 - closed by close()
        except FileExistsError:
            raise LogExistsError(f"{self.path} exists; a new recording never replaces it") from None
        except OSError as exc:
            raise LogError(f"cannot write log {self.path}: {exc.strerror}") from None
        # A program that ends before it records anything (a port taken at start) leaves no empty file behind.
        atexit.register(self._abandon)
        self._writer = Writer(self._stream, chunk_size=chunk_size, compression=CompressionType.ZSTD)
        self._writer.start(profile=PROFILE, library="tafel")
        if metadata:
            self._writer.add_metadata("tafel", dict(metadata))
        self._queue: queue.Queue[PendingMessage | ExtraMessage | None] = queue.Queue(maxsize=queue_size)
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
        return self._queue_item(PendingMessage(topic, cls, time_ns, sequence, data, metadata or {}, time.time_ns()), self.blocking)

    def write_extra(self, extra: ExtraMessage) -> bool:
        """Queue one message of a channel that is not a representation (any thread; never blocks)."""
        return self._queue_item(extra, False)

    def _queue_item(self, item: PendingMessage | ExtraMessage, wait: bool) -> bool:
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
        atexit.unregister(self._abandon)
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

    def _abandon(self) -> None:
        """At exit, a file that was never closed and holds no message is removed, not left empty."""
        if self._closed or self.written or not self._queue.empty():
            return
        self._closed = True
        try:
            self._stream.close()
            self.path.unlink(missing_ok=True)
        except (OSError, ValueError):  # exiting anyway: a file that stays is no reason to fail
            pass

    def _run(self) -> None:
        last_flush = time.monotonic()
        chunk_start_ns: int | None = None  # log time of the first message in the open chunk
        while True:
            try:
                item = self._queue.get(timeout=self.flush_interval)
            except queue.Empty:
                item = PendingMessage("", type(None), 0, 0, b"", {})  # nothing came: just flush
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

    def _add(self, item: PendingMessage) -> None:
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


