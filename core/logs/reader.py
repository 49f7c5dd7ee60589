"""Reading Tafel's MCAP logs, damaged and hostile ones included: through the CRC-checked summary and chunk
index where it is intact, by walking the records where not; a damaged chunk is skipped and reading goes
on with the next one; what one chunk may claim is bounded, so a small file cannot take the machine's
memory. ``read_log`` reads a whole (small) log into memory for tests."""

from __future__ import annotations

import builtins
import io
import os
import re
import struct
import zlib
from collections.abc import Iterable, Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import zstandard
from google.protobuf import descriptor_pb2
from mcap.data_stream import ReadDataStream
from mcap.exceptions import McapError
from mcap.opcode import Opcode
from mcap.records import Channel, ChunkIndex, Header, Metadata, MetadataIndex, Schema, Statistics

from tafel.core.logs.format import EXTRA_TOPIC_PREFIX, MAGIC, PROFILE, LogError, log


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
    #: the schema as stored (a protobuf FileDescriptorSet), to copy the channel into another log (builtins: the
    #: field above is called bytes)
    schema_data: builtins.bytes = b""

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


#: the most one chunk may hold uncompressed: Tafel writes chunks of 4 MiB and one message more (a camera
#: image is under 3 MB). A chunk that claims more is refused before anything is allocated for it.
MAX_CHUNK_BYTES = 32 << 20
#: the most a byte of compressed data can stand for (zstd: a block of 128 KiB repeating one byte costs 4
#: bytes; LZ4: one byte extends a match by 255): a chunk claiming more is damaged or a bomb
_MAX_RATIO = {"": 1, "zstd": 32768, "lz4": 255}
#: what a record outside the chunks (header, schema, channel, metadata) and the summary section may claim
MAX_RECORD_BYTES = 16 << 20
MAX_SUMMARY_BYTES = 64 << 20
#: opcode, length, then the chunk's start and end time, uncompressed size and CRC, compression name length
_CHUNK_HEAD = struct.Struct("<BQQQQII")
_FOOTER = struct.Struct("<BQQQI")
#: where a chunk record may start: its opcode, then 36 bytes, then the length and name of a compression
_CHUNK_SIGNATURE = re.compile(rb"\x06.{36}(?:\x04\x00\x00\x00zstd|\x03\x00\x00\x00lz4|\x00\x00\x00\x00)", re.DOTALL)
_SCAN_BLOCK = 1 << 20


class _Damage(Exception):
    """Why a record cannot be trusted (raised inside the reader, reported as a problem with its position)."""


class _Exact(ReadDataStream):
    """A record parser that fails when a field claims more bytes than the record holds."""

    def read(self, length: int) -> bytes:
        data = super().read(length)
        if len(data) != length:
            raise _Damage(f"a field claims {length} bytes where {len(data)} are left")
        return data


def _parse(record_type: Any, body: bytes, *, whole: bool = False) -> Any:
    """One mcap record from its body; ``_Damage`` when a field runs past its end, or with ``whole``
    when its fields leave bytes over (where no CRC vouches for the record's length)."""
    stream = _Exact(io.BytesIO(body))
    record = record_type.read(stream)
    if whole and stream.count != len(body):
        raise _Damage(f"its fields take {stream.count} of its {len(body)} bytes")
    return record


@dataclass(frozen=True)
class _ChunkHead:
    """The fields of a chunk record before its compressed data, checked against each other and the limits."""

    offset: int
    start_ns: int
    end_ns: int
    size: int  # uncompressed
    crc: int
    compression: str
    data_offset: int
    data_length: int

    @property
    def end(self) -> int:
        return self.data_offset + self.data_length


class LogReader:
    """Reads an MCAP log chunk by chunk, never the whole file at once, and never more than a bounded
    amount of memory for one chunk, whatever the file claims.

    An intact file is read through its summary (channels, metadata and the chunk index), which its CRC
    vouches for; a file without one (the recording was cut off) or with a damaged one is walked record
    by record once to find its chunks. A damaged chunk is skipped with a warning naming its byte, and
    reading goes on with the next one: the index says where it is, or the walk finds it by its record
    signature. So one flipped bit loses at most the chunk it hits. A chunk that claims more than
    ``max_chunk_bytes`` uncompressed (or more than its compressed bytes can hold) is refused unread.
    ``problems`` lists what was skipped and why.
    """

    def __init__(self, path: str | Path, *, max_chunk_bytes: int = MAX_CHUNK_BYTES) -> None:
        self.path = Path(path)
        self.max_chunk_bytes = max_chunk_bytes
        try:
            self._file = open(self.path, "rb")  # noqa: SIM115 - closed by close()
            self.size = os.fstat(self._file.fileno()).st_size
        except OSError as exc:
            raise LogError(f"cannot read log {self.path}: {exc.strerror or exc}") from None
        self.channels: dict[str, LogChannel] = {}
        #: channels that are not representations (topic -> schema name), e.g. the Foxglove ones
        self.extra_channels: dict[str, str] = {}
        self.metadata: dict[str, str] = {}
        self.chunks: list[ChunkInfo] = []
        #: messages per topic as the summary counts them (None without a trusted summary)
        self.message_counts: dict[str, int] | None = None
        self.complete = True
        self.problems: list[str] = []
        self._schemas: dict[int, Schema] = {}
        self._topics: dict[int, str] = {}
        self._warned: set[int] = set()
        self._check_magic()
        if not self._read_summary():
            self._walk()
            for _ in self.iter_chunks():  # channels are defined inside the chunks: find them all once
                pass
            if not self.chunks and not self.complete:
                self.close()
                raise LogError(f"{self.path}: nothing can be read: {self.problems[0]}")

    # ------------------------------------------------------------------------------- opening
    def _check_magic(self) -> None:
        """The MCAP magic at the start; one or two flipped bits in it are a damage, not another format."""
        if self.size == 0:
            self.close()
            raise LogError(f"{self.path} is empty (0 bytes): nothing was ever recorded into it "
                           "(a run that stopped before recording started leaves such a file)")
        start = self._file.read(len(MAGIC))
        if start == MAGIC:
            return
        flipped = sum(bin(a ^ b).count("1") for a, b in zip(start, MAGIC, strict=False)) if len(start) == len(MAGIC) else 99
        if flipped <= 2 and self.size > len(MAGIC) and self._file.read(1) == bytes([Opcode.HEADER]):
            self._problem(f"{self.path}: the MCAP magic at byte 0 is damaged ({flipped} bit{'s' if flipped > 1 else ''}); reading on")
            return
        self.close()
        raise LogError(f"{self.path} is not an MCAP log (it does not start with the MCAP magic bytes)")

    def _read_summary(self) -> bool:
        """Channels, metadata and chunks from the summary section; False when there is none or it is damaged."""
        footer_at = self.size - _FOOTER.size - len(MAGIC)
        if footer_at < len(MAGIC):
            return False
        self._file.seek(footer_at)
        footer = self._file.read(_FOOTER.size)
        opcode, length, summary_start, _offsets_start, crc = _FOOTER.unpack(footer)
        if opcode != Opcode.FOOTER or length != _FOOTER.size - 9:
            return False  # cut off, or the footer is damaged: the walk says which
        if summary_start == 0:
            return False  # written without a summary
        if not len(MAGIC) <= summary_start <= footer_at or footer_at - summary_start > MAX_SUMMARY_BYTES:
            self._problem(f"{self.path}: the footer at byte {footer_at} points to a summary at byte {summary_start}, "
                          "which cannot be; walking the file instead")
            return False
        self._file.seek(summary_start)
        data = self._file.read(footer_at - summary_start)
        if crc != 0 and zlib.crc32(footer[:-4], zlib.crc32(data)) != crc:
            self._problem(f"{self.path}: the summary section at byte {summary_start} is damaged (its CRC does not match); "
                          "walking the file instead")
            return False
        try:
            schemas, channels, chunks, metadata, counts = self._summary_records(data, summary_start)
        except (_Damage, ValueError, struct.error, UnicodeDecodeError, McapError) as exc:
            self._problem(f"{self.path}: the summary section at byte {summary_start} cannot be read ({exc}); walking the file instead")
            return False
        self._schemas.update(schemas)
        for channel in channels:
            self._add_channel(channel)
        self.chunks = sorted(chunks, key=lambda c: c.offset)
        self.message_counts = {topic: counts.get(channel_id, 0) for channel_id, topic in self._topics.items()}
        for offset, size in metadata:
            try:
                self._register(_parse(Metadata, self._record_body(offset, Opcode.METADATA, size)))
            except (_Damage, ValueError, struct.error, UnicodeDecodeError, McapError) as exc:  # the messages matter more
                self._problem(f"{self.path}: the run's metadata at byte {offset} cannot be read ({exc})")
        return True

    def _summary_records(self, data: bytes, start: int) -> tuple[dict[int, Schema], list[Channel], list[ChunkInfo], list[tuple[int, int]], dict[int, int]]:
        """The summary's schemas, channels, chunk index, metadata index (offset, length) and message counts."""
        schemas: dict[int, Schema] = {}
        channels: list[Channel] = []
        chunks: list[ChunkInfo] = []
        metadata: list[tuple[int, int]] = []
        counts: dict[int, int] = {}
        position = 0
        while position < len(data):
            if position + 9 > len(data):
                raise _Damage(f"a record at byte {start + position} is cut off")
            opcode, length = struct.unpack_from("<BQ", data, position)
            body = data[position + 9:position + 9 + length]
            if len(body) != length:
                raise _Damage(f"the record at byte {start + position} runs past the summary's end")
            if opcode == Opcode.SCHEMA:
                schema = _parse(Schema, body)
                schemas[schema.id] = schema
            elif opcode == Opcode.CHANNEL:
                channels.append(_parse(Channel, body))
            elif opcode == Opcode.CHUNK_INDEX:
                index = _parse(ChunkIndex, body)
                if not len(MAGIC) <= index.chunk_start_offset <= start - 9 - index.chunk_length:
                    raise _Damage(f"its chunk index names byte {index.chunk_start_offset}, outside the data section")
                chunks.append(ChunkInfo(index.chunk_start_offset, index.message_start_time, index.message_end_time))
            elif opcode == Opcode.METADATA_INDEX:
                index = _parse(MetadataIndex, body)
                if index.name == PROFILE:
                    metadata.append((index.offset, index.length))
            elif opcode == Opcode.STATISTICS:
                counts = dict(_parse(Statistics, body).channel_message_counts)
            position += 9 + length
        return schemas, channels, chunks, metadata, counts

    def _record_body(self, offset: int, opcode: int, expected: int | None = None) -> bytes:
        """The body of the record at ``offset``, which must have ``opcode`` and a bounded, fitting length."""
        self._file.seek(offset)
        head = self._file.read(9)
        if len(head) < 9 or head[0] != opcode:
            raise _Damage(f"no {Opcode(opcode).name.lower()} record there")
        length = int.from_bytes(head[1:], "little")
        if length > MAX_RECORD_BYTES or offset + 9 + length > self.size or (expected is not None and 9 + length != expected):
            raise _Damage(f"its length ({length} bytes) cannot be right")
        return self._file.read(length)

    def _walk(self) -> None:
        """Find chunks, schemas, channels and metadata by walking the records from the start.

        A record that cannot be right (an unknown opcode, lengths that disagree, a chunk over the
        limits) is reported, and the walk goes on from the next chunk record a scan finds.
        """
        position = len(MAGIC)
        while True:
            self._file.seek(position)
            head = self._file.read(9)
            if len(head) < 9:
                self.complete = False
                self._problem(f"{self.path}: the file ends at byte {self.size} without the MCAP footer (the recording was cut off)")
                return
            opcode, length = head[0], int.from_bytes(head[1:], "little")
            try:
                if position + 9 + length > self.size:
                    raise _Damage(f"it runs past the end of the file (byte {self.size})")
                if opcode == Opcode.CHUNK:
                    chunk = self._chunk_head(position)
                    self.chunks.append(ChunkInfo(position, chunk.start_ns, chunk.end_ns))
                elif opcode in (Opcode.SCHEMA, Opcode.CHANNEL, Opcode.METADATA):
                    self._register(_parse(_RECORD_TYPES[opcode], self._record_body(position, opcode), whole=True))
                elif opcode == Opcode.HEADER:
                    if position != len(MAGIC):
                        raise _Damage("a header in the middle of the file")
                    _parse(Header, self._record_body(position, opcode), whole=True)
                elif opcode == Opcode.MESSAGE_INDEX:
                    entries = int.from_bytes(self._file.read(6)[2:], "little")
                    if length != 6 + entries or entries % 16:
                        raise _Damage("its lengths disagree")
                elif opcode in (Opcode.DATA_END, Opcode.FOOTER):
                    if length != (4 if opcode == Opcode.DATA_END else 20):
                        raise _Damage("its length is wrong for its kind")
                    return
                elif opcode != Opcode.ATTACHMENT and opcode < 0x80:  # 0x80 and up: records of other writers
                    raise _Damage(f"opcode {opcode:#04x} does not belong in the data section")
                position += 9 + length
            except (_Damage, ValueError, struct.error, UnicodeDecodeError, McapError) as exc:
                following = self._next_chunk(position + 1)
                kind = "chunk" if opcode == Opcode.CHUNK else "record"
                if following is None:
                    self.complete = False
                    cut = "runs past the end of the file" in str(exc)
                    self._problem(f"{self.path}: the {kind} at byte {position} " + (
                        f"runs past the end of the file (byte {self.size}): the recording was cut off" if cut else
                        f"is damaged ({exc}), and no intact chunk follows it: the file is damaged from here on"))
                    return
                self._problem(f"{self.path}: the {kind} at byte {position} is damaged ({exc}); "
                              f"{following - position} bytes skipped, reading on with the chunk at byte {following}")
                position = following

    def _next_chunk(self, start: int) -> int | None:
        """The offset of the next intact-looking chunk record from ``start`` on (a scan through a damaged file)."""
        block = start
        while block < self.size:
            self._file.seek(block)
            data = self._file.read(_SCAN_BLOCK + 64)  # a signature that starts in this block ends in it
            found = _CHUNK_SIGNATURE.search(data)
            while found is not None and found.start() < _SCAN_BLOCK:
                try:
                    self._chunk_head(block + found.start())
                    return block + found.start()
                except _Damage:
                    found = _CHUNK_SIGNATURE.search(data, found.start() + 1)
            block += _SCAN_BLOCK
        return None

    def _chunk_head(self, offset: int) -> _ChunkHead:
        """The chunk record at ``offset``, its fields checked against each other, the file and the limits."""
        self._file.seek(offset)
        head = self._file.read(_CHUNK_HEAD.size)
        if len(head) < _CHUNK_HEAD.size:
            raise _Damage("the file ends inside it")
        opcode, length, start_ns, end_ns, size, crc, name_length = _CHUNK_HEAD.unpack(head)
        if opcode != Opcode.CHUNK:
            raise _Damage(f"no chunk record there (opcode {opcode:#04x})")
        if name_length > 8:
            raise _Damage(f"its compression's name claims {name_length} bytes")
        rest = self._file.read(name_length + 8)
        if len(rest) < name_length + 8:
            raise _Damage("the file ends inside it")
        compression = rest[:name_length].decode("latin-1")
        data_length = int.from_bytes(rest[name_length:], "little")
        if length != 40 + name_length + data_length:
            raise _Damage(f"its length ({length} bytes) disagrees with its contents ({40 + name_length + data_length} bytes)")
        if offset + 9 + length > self.size:
            raise _Damage(f"it runs past the end of the file (byte {self.size})")
        if compression not in _MAX_RATIO:
            raise _Damage(f"unknown compression {compression!r} (Tafel reads zstd, lz4 and none)")
        if size > self.max_chunk_bytes:
            raise _Damage(f"it claims {size} bytes uncompressed, more than the {self.max_chunk_bytes} a chunk may hold "
                          "(LogReader's max_chunk_bytes); a damaged or hostile file")
        if size > data_length * _MAX_RATIO[compression] or data_length > size + size // 64 + 1024:
            raise _Damage(f"it claims {size} bytes uncompressed from {data_length} bytes of {compression or 'uncompressed'} "
                          "data, which no compression gives; a damaged or hostile file")
        return _ChunkHead(offset, start_ns, end_ns, size, crc, compression, offset + len(head) + len(rest), data_length)

    def _inflate(self, chunk: _ChunkHead) -> bytes:
        """The chunk's records, decompressed into at most its (bounded) declared size and checked against its CRC."""
        self._file.seek(chunk.data_offset)
        data = self._file.read(chunk.data_length)
        if len(data) != chunk.data_length:
            raise _Damage("the file ends inside it")
        if chunk.compression == "zstd":
            declared = zstandard.frame_content_size(data)
            if declared not in (-1, chunk.size):  # the frame's own claim decides what zstd allocates
                raise _Damage(f"its zstd frame claims {declared} bytes, the chunk {chunk.size}")
            records = zstandard.ZstdDecompressor().decompress(data, max_output_size=chunk.size)
        elif chunk.compression == "lz4":
            import lz4.frame  # an mcap dependency; Tafel itself writes zstd

            decompressor = lz4.frame.LZ4FrameDecompressor()
            records = decompressor.decompress(data, max_length=chunk.size)
            if not decompressor.eof:
                raise _Damage(f"it holds more than the {chunk.size} bytes it claims")
        else:
            records = data
        if len(records) != chunk.size:
            raise _Damage(f"it holds {len(records)} bytes uncompressed, not the {chunk.size} it claims")
        if chunk.crc != 0 and zlib.crc32(records) != chunk.crc:
            raise _Damage("its CRC does not match its contents")
        return records

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
        messages = self._chunk_messages(number)
        first = next(messages, None)
        if first is None and number in self._warned:
            return None
        return ([] if first is None else [first]) + list(messages)

    def _chunk_messages(self, number: int) -> Iterator[LogMessage]:
        """The messages of one chunk, one by one, from its decompressed records (never more than one chunk in memory).

        A chunk whose head, size or CRC is wrong yields nothing; one without a CRC whose records turn
        out wrong half-way yields those before (both with a warning naming its byte).
        """
        chunk = self.chunks[number]
        try:
            records = self._inflate(self._chunk_head(chunk.offset))
        except (_Damage, ValueError, zstandard.ZstdError, RuntimeError, OSError) as exc:  # skip this chunk and go on
            self._chunk_problem(number, f"is damaged ({exc}); skipped, reading on with the next chunk")
            return
        position, end = 0, len(records)
        while position < end:
            if position + 9 > end:
                self._chunk_problem(number, f"is damaged: its last record is cut off at byte {position} of its contents")
                return
            opcode, length = struct.unpack_from("<BQ", records, position)
            body_at, position = position + 9, position + 9 + length
            if position > end:
                self._chunk_problem(number, f"is damaged: a record at byte {body_at - 9} of its contents runs past its end")
                return
            if opcode == Opcode.MESSAGE and length >= 22:
                channel_id, sequence, log_time, publish_time = struct.unpack_from("<HIQQ", records, body_at)
                topic = self._topics.get(channel_id)
                if topic is not None:
                    yield LogMessage(topic, publish_time, sequence, records[body_at + 22:position], log_time)
            elif opcode in (Opcode.SCHEMA, Opcode.CHANNEL):
                try:
                    self._register(_parse(_RECORD_TYPES[opcode], records[body_at:position]))
                except (_Damage, ValueError, struct.error, UnicodeDecodeError, McapError) as exc:
                    self._chunk_problem(number, f"holds a damaged {Opcode(opcode).name.lower()} record ({exc}); skipped it")
            elif opcode < 0x80:  # 0x80 and up: records of other writers, skipped
                self._chunk_problem(number, f"is damaged: a record of opcode {opcode:#04x} (length {length}) at byte "
                                            f"{body_at - 9} of its contents, which a chunk cannot hold; the rest of it skipped")
                return

    def _chunk_problem(self, number: int, text: str) -> None:
        if number not in self._warned:
            self._warned.add(number)
            self._problem(f"{self.path}: the chunk at byte {self.chunks[number].offset} {text}")

    def messages(self, topics: Iterable[str] | None = None, start_ns: int | None = None) -> Iterator[LogMessage]:
        """Every readable message (of ``topics``, from frame time ``start_ns`` on), chunk by chunk in file order."""
        wanted = None if topics is None else set(topics)
        for number in range(len(self.chunks)):  # chunks are indexed by log (wall) time, not frame time
            for message in self._chunk_messages(number):
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


def _file_of(schema: Schema | None) -> descriptor_pb2.FileDescriptorProto | None:
    if schema is None or schema.encoding != "protobuf":
        return None
    fds = descriptor_pb2.FileDescriptorSet.FromString(schema.data)
    wanted = schema.name.rsplit(".", 1)[-1]
    for file in fds.file:
        if any(m.name == wanted for m in file.message_type):
            return file
    return fds.file[0] if fds.file else None
