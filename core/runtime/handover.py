"""Hand-over of representations between contexts at frame boundaries.

The producing context publishes, at the end of each frame, one bundle with a private copy of every
representation the other context reads; the consuming context takes the newest complete bundle at the
start of its frame. Neither side ever waits for the other, and a consumer never sees a half-written
value: in one process the bundle is swapped in by one reference assignment; across processes it goes
through a shared-memory seqlock with two slots, and a read that overlapped a write is retried.
"""

from __future__ import annotations

import copy
import logging
import pickle
import struct
import time
import zlib
from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from multiprocessing import shared_memory
from typing import Any

import numpy as np

from tafel.core.framework.errors import TafelError
from tafel.core.framework.manager import Blackboard

log = logging.getLogger("tafel.handover")


class HandoverError(TafelError, RuntimeError):
    """A bundle does not fit the channel, or a channel cannot be attached."""


def snapshot(instance: Any) -> dict[str, Any]:
    """Field values of a representation, copied so that later writes by its provider do not show."""
    values: dict[str, Any] = {}
    for name, value in instance.__dict__.items():
        if isinstance(value, np.ndarray):
            values[name] = value.copy()
        elif isinstance(value, (int, float, str, bytes, bool)) or value is None:
            values[name] = value
        else:
            values[name] = private_copy(value)
    return values


def private_copy(value: Any) -> Any:
    """A deep copy of a list, dict or nested dataclass. A pickle round trip copies such values several
    times faster than ``copy.deepcopy`` (in C, not call by call); what pickle refuses is deep-copied."""
    try:
        return pickle.loads(pickle.dumps(value, protocol=pickle.HIGHEST_PROTOCOL))
    except (pickle.PicklingError, TypeError, AttributeError):
        return copy.deepcopy(value)


@dataclass(frozen=True)
class Bundle:
    """What one context hands over after one frame."""

    frame_number: int
    time_ns: int
    published_ns: int  # monotonic wall clock when it was published
    values: Mapping[str, dict[str, Any]]


def make_bundle(blackboard: Blackboard, reps: Iterable[type], frame_number: int, time_ns: int) -> Bundle:
    return Bundle(
        frame_number,
        time_ns,
        time.monotonic_ns(),
        {rep.__name__: snapshot(blackboard[rep]) for rep in reps},
    )


def apply_bundle(bundle: Bundle, blackboard: Blackboard, reps: Iterable[type]) -> None:
    """Copy a bundle's values into the consumer's instances (identity kept for the modules' views)."""
    for rep in reps:
        values = bundle.values.get(rep.__name__)
        if values is not None:
            blackboard[rep].__dict__.update(values)


class LocalChannel:
    """Hand-over within one process: the newest bundle behind one reference."""

    def __init__(self) -> None:
        self._latest: Bundle | None = None

    def publish(self, bundle: Bundle) -> None:
        self._latest = bundle

    def latest(self) -> Bundle | None:
        return self._latest

    def close(self) -> None:
        self._latest = None


_HEADER = struct.Struct("<Q")  # sequence number of the newest complete bundle
_SLOT = struct.Struct("<QI")  # payload length, CRC-32 of the payload


def _buffer(shm: shared_memory.SharedMemory) -> memoryview:
    """The bytes of a shared memory block; closing it takes them away (then this raises)."""
    if shm.buf is None:
        raise HandoverError(f"hand-over channel {shm.name} is closed")
    return shm.buf


class SharedChannel:
    """Hand-over between processes through shared memory (single writer, any number of readers).

    Layout: sequence number, then two slots of (length, CRC-32, payload). Bundle ``n`` goes into slot
    ``n % 2`` and becomes visible when the sequence number is set to ``n``. A reader copies the slot of
    the sequence number it saw and accepts the copy only if the sequence number has not moved meanwhile
    (the writer only touches that slot again after publishing the next bundle) and the checksum holds.
    A payload that is damaged or does not decode is skipped and counted (``skipped``); the reader keeps
    the last good bundle, and no loop ever ends for it.
    """

    def __init__(self, name: str | None = None, capacity: int = 4 << 20, create: bool = True) -> None:
        size = _HEADER.size + 2 * (_SLOT.size + capacity)
        try:
            if create:
                self._shm = shared_memory.SharedMemory(name=name, create=True, size=size)
                _buffer(self._shm)[: _HEADER.size] = b"\0" * _HEADER.size
            else:
                self._shm = shared_memory.SharedMemory(name=name)
        except OSError as exc:
            raise HandoverError(f"cannot {'create' if create else 'attach'} hand-over channel {name}: {exc}") from None
        self.name = self._shm.name
        self.capacity = (self._shm.size - _HEADER.size) // 2 - _SLOT.size
        self._owner = create
        self._sequence = 0
        self._last_good: Bundle | None = None
        self._bad_sequence = 0
        #: bundles skipped because their checksum failed or they did not decode
        self.skipped = 0

    @classmethod
    def attach(cls, name: str) -> SharedChannel:
        """Open a channel created by another process (the creator unlinks it)."""
        return cls(name=name, create=False)

    def _slot_offset(self, sequence: int) -> int:
        return _HEADER.size + (sequence % 2) * (_SLOT.size + self.capacity)

    def publish(self, bundle: Bundle) -> None:
        payload = pickle.dumps(bundle, protocol=5)
        if len(payload) > self.capacity:
            raise HandoverError(
                f"hand-over bundle of {len(payload)} bytes exceeds the channel capacity of {self.capacity} bytes; "
                "hand over fewer or smaller representations (images stay in the context that senses them)"
            )
        sequence = self._sequence + 1
        offset = self._slot_offset(sequence)
        buf = _buffer(self._shm)
        _SLOT.pack_into(buf, offset, len(payload), zlib.crc32(payload))
        start = offset + _SLOT.size
        buf[start : start + len(payload)] = payload
        _HEADER.pack_into(buf, 0, sequence)
        self._sequence = sequence

    def latest(self) -> Bundle | None:
        buf = _buffer(self._shm)
        for _ in range(100):
            (sequence,) = _HEADER.unpack_from(buf, 0)
            if sequence == 0:
                return None
            if sequence == self._bad_sequence:
                return self._last_good  # already found damaged: skipped once, counted once
            offset = self._slot_offset(sequence)
            length, checksum = _SLOT.unpack_from(buf, offset)
            start = offset + _SLOT.size
            payload = bytes(buf[start : start + min(length, self.capacity)])
            if _HEADER.unpack_from(buf, 0)[0] != sequence:
                continue  # the writer overtook this read: try again
            try:
                if length > self.capacity or zlib.crc32(payload) != checksum:
                    raise HandoverError(f"checksum of bundle {sequence} does not match")
                self._last_good = pickle.loads(payload)
            except Exception as exc:  # noqa: BLE001 - a damaged bundle never ends a loop
                self._bad_sequence = sequence
                self.skipped += 1
                if self.skipped == 1 or self.skipped % 1000 == 0:
                    log.warning("hand-over channel %s: bundle %d skipped (%s); %d skipped so far", self.name, sequence, exc, self.skipped)
            return self._last_good
        return self._last_good  # the writer kept overtaking; next frame will succeed

    def close(self) -> None:
        """Release the mapping; the creator also removes the shared memory, even when closing fails."""
        try:
            self._shm.close()
        except (BufferError, OSError) as exc:  # a view still open somewhere: unlinking still frees it
            log.warning("hand-over channel %s: close failed (%s); removing it anyway", self.name, exc)
        finally:
            if self._owner:
                try:
                    self._shm.unlink()
                except FileNotFoundError:
                    pass
