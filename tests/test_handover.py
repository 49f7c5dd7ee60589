"""Hand-over channels: a consumer never observes a torn value, whatever the interleaving."""

from __future__ import annotations

import multiprocessing
import threading
import time
import zlib
from multiprocessing import shared_memory

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tafel.core import Module, ModuleManager, provides, representation
from tafel.core.framework.access import AccessMark, protect, read_view
from tafel.core.runtime.handover import HandoverError, LocalChannel, SharedChannel, apply_bundle, make_bundle, private_copy, snapshot


@representation
class HoConsistent:
    """Fields that must agree: b == 2 * a, every element of samples == a, label == str(a)."""

    a: int
    b: int
    samples: np.ndarray
    label: str


@provides(HoConsistent)
class HoWriter(Module):
    def __init__(self) -> None:
        self.value = 0

    def execute(self) -> None:
        rep = self.ho_consistent
        rep.a = self.value
        rep.b = 2 * self.value
        rep.samples = np.full(20_000, self.value, dtype=np.int64)  # large enough to make copies slow
        rep.label = str(self.value)


def consistent(values: dict) -> bool:
    a = values["a"]
    return values["b"] == 2 * a and values["label"] == str(a) and bool((values["samples"] == a).all())


def _publish_all(name: str, sequence: list[int], done) -> None:
    channel = SharedChannel.attach(name)
    manager = ModuleManager([HoWriter])
    writer = manager.module("HoWriter")
    for frame, value in enumerate(sequence, start=1):
        writer.value = value
        manager.execute()
        channel.publish(make_bundle(manager.blackboard, [HoConsistent], frame, frame))
    done.set()
    channel.close()


@settings(max_examples=15, deadline=None)
@given(st.lists(st.integers(-(2**40), 2**40), min_size=50, max_size=300))
def test_shared_channel_never_shows_a_torn_value(sequence: list[int]) -> None:
    channel = SharedChannel()
    context = multiprocessing.get_context("fork")
    done = context.Event()
    writer = context.Process(target=_publish_all, args=(channel.name, sequence, done))
    writer.start()
    observed = 0
    last_frame = 0
    deadline = time.monotonic() + 60  # a writer that died must fail the test, not hang it
    try:
        while not done.is_set() or observed == 0:
            assert time.monotonic() < deadline, f"the writer process stopped publishing (exit code {writer.exitcode})"
            bundle = channel.latest()
            if bundle is None:
                continue
            values = bundle.values["HoConsistent"]
            assert consistent(values), values["a"]
            assert bundle.frame_number >= last_frame  # never goes back in time
            assert values["a"] == sequence[bundle.frame_number - 1]
            last_frame = bundle.frame_number
            observed += 1
        final = channel.latest()
        assert final is not None and final.frame_number == len(sequence)
    finally:
        writer.join(timeout=10)
        channel.close()
    assert observed > 0


@settings(max_examples=20, deadline=None)
@given(st.lists(st.integers(-1000, 1000), min_size=20, max_size=200))
def test_local_channel_between_threads_never_shows_a_torn_value(sequence: list[int]) -> None:
    channel = LocalChannel()
    manager = ModuleManager([HoWriter])
    done = threading.Event()

    def publish() -> None:
        for frame, value in enumerate(sequence, start=1):
            manager.module("HoWriter").value = value
            manager.execute()
            channel.publish(make_bundle(manager.blackboard, [HoConsistent], frame, frame))
        done.set()

    thread = threading.Thread(target=publish)
    thread.start()
    from tafel.core.framework.manager import Blackboard

    board = Blackboard()
    board.ensure(HoConsistent)
    deadline = time.monotonic() + 60
    while not done.is_set():
        assert time.monotonic() < deadline, "the publishing thread stopped"
        bundle = channel.latest()
        if bundle is not None:
            apply_bundle(bundle, board, [HoConsistent])
            assert consistent(board[HoConsistent].__dict__)
    thread.join()
    apply_bundle(channel.latest(), board, [HoConsistent])
    assert board[HoConsistent].a == sequence[-1] and consistent(board[HoConsistent].__dict__)


def test_snapshots_do_not_change_with_the_producer() -> None:
    rep = HoConsistent(a=1, b=2, samples=np.ones(3, dtype=np.int64), label="1")
    copy = snapshot(rep)
    rep.samples[0] = 5
    assert copy["samples"].tolist() == [1, 1, 1]


@representation
class HoSeen:
    """A list of nested dataclasses, as the obstacle and teammate representations hold."""

    robots: list[HoConsistent]


def test_snapshots_of_nested_values_are_private_and_views_in_them_become_plain_copies() -> None:
    """The pickle round trip of ``private_copy`` copies lists of dataclasses deeply; a read-only view or list a module
    stored in its output copies to the plain value, as ``deepcopy`` gives it (a view's class is made at run time and
    cannot be pickled itself; the module harness copies its history so too)."""
    inner = HoConsistent(a=1, b=2, samples=np.ones(2, dtype=np.int64), label="1")
    rep = HoSeen(robots=[inner, inner])
    copied = snapshot(rep)["robots"]
    inner.a, inner.samples[0] = 7, 9
    assert [r.a for r in copied] == [1, 1] and copied[0].samples.tolist() == [1, 1]
    assert copied[0] is copied[1]  # shared values stay shared, as with deepcopy
    view = read_view(HoConsistent(a=3, b=6, samples=np.zeros(1, dtype=np.int64), label="3"), "M", AccessMark())
    plain = private_copy([view])[0]
    assert type(plain) is HoConsistent and plain.a == 3
    plain.samples[0] = 1  # writeable: a private copy, not a view
    items = protect([inner, [1, 2]], "list", "M", "HoSeen", ".robots", AccessMark())
    listed = private_copy({"robots": items})["robots"]
    assert type(listed) is list and type(listed[0]) is HoConsistent and listed[1] == [1, 2]
    listed[1].append(3)  # a private list: the module's input is untouched
    assert items[1] == [1, 2]


def test_oversized_bundles_are_refused_with_advice() -> None:
    channel = SharedChannel(capacity=1024)
    try:
        manager = ModuleManager([HoWriter])
        manager.execute()
        with pytest.raises(HandoverError, match="exceeds the channel capacity"):
            channel.publish(make_bundle(manager.blackboard, [HoConsistent], 1, 1))
        assert channel.latest() is None
    finally:
        channel.close()


def test_attaching_a_missing_channel_fails_clearly() -> None:
    with pytest.raises(HandoverError, match="cannot attach hand-over channel"):
        SharedChannel.attach("tafel-no-such-channel")


def publish_one(channel: SharedChannel, value: int, frame: int) -> None:
    manager = ModuleManager([HoWriter])
    manager.module("HoWriter").value = value
    manager.execute()
    channel.publish(make_bundle(manager.blackboard, [HoConsistent], frame, frame))


def test_a_damaged_bundle_is_skipped_and_counted_and_the_last_good_one_stays() -> None:
    channel = SharedChannel(capacity=1 << 20)
    try:
        publish_one(channel, 7, 1)
        assert channel.latest().values["HoConsistent"]["a"] == 7
        publish_one(channel, 8, 2)
        offset = channel._slot_offset(2) + 12 + 20  # inside bundle 2's payload
        channel._shm.buf[offset] ^= 0xFF
        for _ in range(3):  # read every frame: skipped once, counted once, never raising
            assert channel.latest().values["HoConsistent"]["a"] == 7
        assert channel.skipped == 1
        publish_one(channel, 9, 3)
        assert channel.latest().values["HoConsistent"]["a"] == 9
    finally:
        channel.close()


def test_a_payload_that_does_not_decode_is_skipped() -> None:
    channel = SharedChannel(capacity=4096)
    try:
        garbage = b"not a pickle at all"
        offset = channel._slot_offset(1)
        struct_slot = __import__("struct").Struct("<QI")
        struct_slot.pack_into(channel._shm.buf, offset, len(garbage), zlib.crc32(garbage))
        channel._shm.buf[offset + struct_slot.size : offset + struct_slot.size + len(garbage)] = garbage
        __import__("struct").Struct("<Q").pack_into(channel._shm.buf, 0, 1)
        assert channel.latest() is None and channel.skipped == 1
    finally:
        channel.close()


def test_shared_memory_is_released_even_when_closing_raises() -> None:
    channel = SharedChannel(capacity=1024)
    name = channel.name
    view = channel._shm.buf[0:8]  # an exported view makes SharedMemory.close raise BufferError
    try:
        channel.close()
    finally:
        view.release()
    with pytest.raises(FileNotFoundError):
        shared_memory.SharedMemory(name=name)
