"""MCAP files built by hand, record by record: bombs and damaged logs to attack the log reader with.

A *bomb* is a small file whose chunk claims a huge uncompressed size; its zstd data is a frame of RLE
blocks (4 bytes stand for 128 KiB of one repeated byte), so a few kilobytes decompress to gigabytes.
"""

from __future__ import annotations

import io
import random
import struct
import zlib
from pathlib import Path

MAGIC = b"\x89MCAP0\r\n"
#: zstd: the frame magic, a frame header without content size (window descriptor: 128 KiB)
_ZSTD_FRAME = struct.pack("<I", 0xFD2FB528) + bytes([0x00, 7 << 3])
_RLE_BLOCK = 128 << 10


def zstd_rle(size: int, value: int = 0) -> bytes:
    """A valid zstd frame that decompresses to ``size`` bytes of ``value``, in about size / 32768 bytes."""
    blocks = []
    left = size
    while left > 0:
        n = min(left, _RLE_BLOCK)
        left -= n
        blocks.append(((n << 3) | (1 << 1) | (1 if left == 0 else 0)).to_bytes(3, "little") + bytes([value]))
    return _ZSTD_FRAME + b"".join(blocks)


def record(opcode: int, body: bytes) -> bytes:
    return bytes([opcode]) + struct.pack("<Q", len(body)) + body


def _string(text: str) -> bytes:
    data = text.encode()
    return struct.pack("<I", len(data)) + data


def chunk_record(records: bytes | None = None, *, compressed: bytes | None = None, claimed: int | None = None,
                 crc: int | None = None, start_ns: int = 0, end_ns: int = 0) -> bytes:
    """A zstd chunk record: of ``records`` compressed honestly, or of ``compressed`` data claiming ``claimed`` bytes."""
    if records is not None:
        import zstandard

        compressed = zstandard.compress(records)
        claimed = len(records)
        crc = zlib.crc32(records) if crc is None else crc
    assert compressed is not None and claimed is not None
    body = struct.pack("<QQQI", start_ns, end_ns, claimed, crc or 0) + _string("zstd") + struct.pack("<Q", len(compressed)) + compressed
    return record(0x06, body)


def schema_and_channel(topic: str = "motion/FrameInfo") -> bytes:
    """The schema and channel records of one channel (id 1) inside a chunk."""
    schema = record(0x03, struct.pack("<H", 1) + _string("tafel.FrameInfo") + _string("protobuf") + struct.pack("<I", 0))
    channel = record(0x04, struct.pack("<HH", 1, 1) + _string(topic) + _string("protobuf") + struct.pack("<I", 0))
    return schema + channel


def message(sequence: int, time_ns: int, data: bytes = b"", channel: int = 1) -> bytes:
    return record(0x05, struct.pack("<HIQQ", channel, sequence, time_ns, time_ns) + data)


def mcap_file(path: Path, chunks: list[bytes]) -> Path:
    """A file of the given chunk records without a summary (the reader walks it): magic, header, chunks, end."""
    header = record(0x01, _string("tafel") + _string("hand-built"))
    data_end = record(0x0F, struct.pack("<I", 0))
    footer = record(0x02, struct.pack("<QQI", 0, 0, 0))
    path.write_bytes(MAGIC + header + b"".join(chunks) + data_end + footer + MAGIC)
    return path


def good_chunk(first: int, count: int) -> bytes:
    """A chunk of ``count`` FrameInfo messages numbered from ``first`` (with the channel's definition)."""
    records = schema_and_channel() + b"".join(message(n, n * 10_000_000) for n in range(first, first + count))
    return chunk_record(records, start_ns=first * 10_000_000, end_ns=(first + count - 1) * 10_000_000)


def memory_bomb(path: Path, claimed: int = 1 << 30) -> Path:
    """A good chunk, then one that claims ``claimed`` bytes of zeros (about claimed / 32768 bytes in the file)."""
    return mcap_file(path, [good_chunk(0, 10), chunk_record(compressed=zstd_rle(claimed), claimed=claimed)])


def cpu_bomb(path: Path, claimed: int = 8 << 20) -> Path:
    """A chunk whose contents are ``claimed`` zero bytes: 9-byte records of opcode 0, which the mcap library walks one by one."""
    return mcap_file(path, [good_chunk(0, 10), chunk_record(compressed=zstd_rle(claimed), claimed=claimed), good_chunk(10, 10)])


def flip_offsets(size: int, count: int, seed: int) -> list[tuple[int, int]]:
    """``count`` seeded (byte, bit) places in a file of ``size`` bytes."""
    rng = random.Random(seed)
    return [(rng.randrange(size), rng.randrange(8)) for _ in range(count)]


def flipped(data: bytes, offset: int, bit: int) -> bytes:
    damaged = bytearray(data)
    damaged[offset] ^= 1 << bit
    return bytes(damaged)


def chunk_offsets(recording: bytes) -> list[int]:
    """Where the chunk records of a recording written by Tafel lie, from its summary's chunk index."""
    from mcap.reader import make_reader

    summary = make_reader(io.BytesIO(recording)).get_summary()
    assert summary is not None, "a complete recording has a summary"
    return sorted(c.chunk_start_offset for c in summary.chunk_indexes)


def with_chunk_inserted(recording: bytes, chunk: bytes, index: int) -> bytes:
    """A real recording with ``chunk`` put before its chunk number ``index``, and without its summary
    (which would no longer match): the reader walks the data section, as for a cut-off recording."""
    _opcode, _length, summary_start, _offsets, _crc = struct.unpack("<BQQQI", recording[-8 - 29:-8])
    data_end = summary_start - 13
    assert recording[data_end] == 0x0F, "the data section ends with its DataEnd record"
    at = chunk_offsets(recording)[index]
    footer = record(0x02, struct.pack("<QQI", 0, 0, 0))
    return recording[:at] + chunk + recording[at:data_end + 13] + footer + MAGIC
