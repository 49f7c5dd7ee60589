"""Recorded situations: one module run again on a piece of a log (``replay_module``)."""

from __future__ import annotations

import copy
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from tafel.core.framework.frame_info import FrameInfo
from tafel.core.framework.module import Module
from tafel.core.testing.compare import differences
from tafel.core.testing.harness import ModuleHarness, R, context_of


@dataclass
class ReplayFrame:
    """One frame of a module replayed on recorded inputs: its outputs next to the recorded ones."""

    frame_number: int
    time_ns: int
    outputs: dict[type, Any]
    recorded: dict[type, Any] = field(default_factory=dict)


@dataclass
class ReplayResult:
    module: type[Module]
    path: Path
    context: str
    frames: list[ReplayFrame]

    def outputs(self, rep: type[R]) -> list[R]:
        return [frame.outputs[rep] for frame in self.frames]

    def recorded(self, rep: type[R]) -> list[R | None]:
        """The recorded value in each frame (None where the log has none for that frame)."""
        return [frame.recorded.get(rep) for frame in self.frames]

    def differences(self, *, rel: float = 1e-9, abs: float = 0.0) -> list[str]:
        """Where the module's outputs differ from the recorded ones, frame by frame."""
        found = []
        for frame in self.frames:
            for rep, recorded in frame.recorded.items():
                found += [f"frame {frame.frame_number}: {text}"
                          for text in differences(frame.outputs[rep], recorded, rel=rel, abs=abs)]
        return found


def replay_module(module: type[Module], path: str | Path, *, start_s: float = 0.0, seconds: float | None = None,
                  context: str | None = None, parameters: Mapping[str, Any] | None = None,
                  allow_missing: Iterable[type] = ()) -> ReplayResult:
    """Feed ``module`` its recorded inputs from a log, frame by frame with the recorded frame times.

    The frames are those of the module's context in the log, from ``start_s`` (log time) for
    ``seconds``. Each input is taken from the module's context in that frame, or, for a
    representation handed over from the other context, its newest recorded value at the frame's time,
    as the program would have seen it. Inputs the log lacks are an error naming them, unless listed
    in ``allow_missing`` (they keep their defaults). Returns the module's outputs next to what the
    log recorded of them.
    """
    from tafel.core.logs import LogReader
    from tafel.core.logs.serialization import deserialize

    declared = module.requirements()
    context = context or context_of(module)
    harness = ModuleHarness(module, parameters=parameters, context=context)
    with LogReader(path) as reader:
        topics = set(reader.channels)
        frame_topic = f"{context}/FrameInfo"
        if frame_topic not in topics:
            raise ValueError(f"{path} has no {frame_topic}: was {context} running when it was recorded? "
                             f"contexts in the log: {sorted({t.split('/')[0] for t in topics})}")
        sources: dict[type, str] = {}
        missing = []
        for rep in declared.reads():
            if rep is FrameInfo:
                continue
            own, other = f"{context}/{rep.__name__}", f"{'motion' if context == 'cognition' else 'cognition'}/{rep.__name__}"
            if own in topics:
                sources[rep] = own
            elif other in topics:
                sources[rep] = other
            elif rep not in set(allow_missing):
                missing.append(rep.__name__)
        if missing:
            raise ValueError(f"{path} does not hold {', '.join(missing)}, which {module.__name__} reads; record them "
                             f"(--record-reps) or pass allow_missing=[...] to keep their defaults")
        outputs = {rep: f"{context}/{rep.__name__}" for rep in declared.provides if f"{context}/{rep.__name__}" in topics}
        wanted = {frame_topic, *sources.values(), *outputs.values()}
        first_ns = None
        by_time: dict[int, dict[str, Any]] = {}
        order: list[int] = []
        for message in reader.messages(wanted):
            first_ns = message.time_ns if first_ns is None else min(first_ns, message.time_ns)
            if message.time_ns not in by_time:
                by_time[message.time_ns] = {}
                order.append(message.time_ns)
            by_time[message.time_ns][message.topic] = message
    if first_ns is None:
        raise ValueError(f"{path} holds no messages")
    begin = first_ns + int(start_s * 1e9)
    end = None if seconds is None else begin + int(seconds * 1e9)
    latest: dict[str, Any] = {}
    decoded: dict[int, Any] = {}
    frames = []

    def value(rep: type, message: Any) -> Any:
        key = id(message)
        if key not in decoded:
            decoded[key] = deserialize(rep, message.data)
        return decoded[key]

    for time_ns in sorted(order):
        messages = by_time[time_ns]
        for topic, message in messages.items():
            latest[topic] = message
        frame_message = messages.get(frame_topic)
        if frame_message is None or time_ns < begin or (end is not None and time_ns >= end):
            continue
        inputs = [value(rep, latest[topic]) for rep, topic in sources.items() if topic in latest]
        harness.set(*inputs)
        recorded_frame = deserialize(FrameInfo, frame_message.data)
        harness._step((recorded_frame.frame_number, recorded_frame.time_ns))
        frames.append(ReplayFrame(
            frame_number=recorded_frame.frame_number,
            time_ns=time_ns,
            outputs={rep: copy.deepcopy(harness[rep]) for rep in declared.provides},
            recorded={rep: value(rep, messages[topic]) for rep, topic in outputs.items() if topic in messages},
        ))
    if not frames:
        raise ValueError(f"{path}: no {context} frame between {start_s} s and "
                         f"{'the end' if seconds is None else f'{start_s + seconds} s'} of the log")
    return ReplayResult(module, Path(path), context, frames)
