"""``tafel log compare A.mcap B.mcap``: where two recordings of the same program differ.

This is the tool for regression work: replay a log with a changed module, record the replay, and
compare it with the original. Frames are matched by context, representation and frame number. For
each channel the report gives how many frames were compared and differ, and the first differing
frame with the field and both values. Floats are compared to the last bit: equal messages have equal
bytes, so most frames cost one byte comparison and only differing ones are decoded.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from dataclasses import dataclass, field
from itertools import zip_longest
from typing import Any

import numpy as np

from tafel.core.framework.naming import did_you_mean
from tafel.core.logs import LogError, LogMessage, LogReader
from tafel.tools.logs.decoding import message_class, to_python


@dataclass
class ChannelDifference:
    """What one channel (context and representation) looks like in both logs."""

    topic: str
    compared: int = 0
    differing: int = 0
    only_first: int = 0
    only_second: int = 0
    first_frame: int | None = None
    #: the first differing frame's differences: (field path, value in A, value in B)
    fields: list[tuple[str, Any, Any]] = field(default_factory=list)

    @property
    def differs(self) -> bool:
        return bool(self.differing or self.only_first or self.only_second)


def is_timing(reader: LogReader, topic: str) -> bool:
    """A channel of a representation declared ``state=False`` (its metadata says so; ``ModuleTimes`` and
    debug output in logs written before it did): timing, which equal runs do not share, or debug output."""
    channel = reader.channels.get(topic)
    if channel is None:
        return False
    return channel.metadata.get("state") == "false" or channel.schema_name.split(".")[-1] in LEGACY_TIMING


#: representations that were not state before channels said so
LEGACY_TIMING = frozenset({"ModuleTimes", "DebugDrawings", "DebugPlots"})


def compare_logs(first: LogReader, second: LogReader, reps: list[str] | None = None, *,
                 timing: bool = False) -> dict[str, ChannelDifference]:
    """Topic -> how the two logs differ on it (channels in only one log included), in one streaming pass.

    Timing channels (``is_timing``) are left out unless ``timing`` or ``reps`` names them."""
    topics = sorted(set(first.channels) | set(second.channels))
    if not timing and not reps:
        topics = [t for t in topics if not (is_timing(first, t) or is_timing(second, t))]
    if reps:
        known = sorted({t.split("/", 1)[-1] for t in topics})
        unknown = [r for r in reps if r not in known]
        if unknown:
            raise LogError(f"neither log holds {', '.join(unknown)}; {did_you_mean(unknown[0], known)}")
        topics = [t for t in topics if t.split("/", 1)[-1] in reps]
    wanted = set(topics)
    result = {topic: ChannelDifference(topic) for topic in topics}
    pending: tuple[dict[tuple[str, int], bytes], dict[tuple[str, int], bytes]] = ({}, {})
    classes: dict[tuple[int, str], Any] = {}
    for pair in zip_longest(first.messages(wanted), second.messages(wanted)):
        for side, message in enumerate(pair):
            if message is None:
                continue
            key = (message.topic, message.sequence)
            other = pending[1 - side].pop(key, None)
            if other is None:
                pending[side][key] = message.data
                continue
            a, b = (message.data, other) if side == 0 else (other, message.data)
            _compare(result[message.topic], message, a, b, (first, second), classes)
    for side, leftovers in enumerate(pending):
        for topic, _sequence in leftovers:
            difference = result[topic]
            if side == 0:
                difference.only_first += 1
            else:
                difference.only_second += 1
    return result


def _compare(difference: ChannelDifference, message: LogMessage, a: bytes, b: bytes,
             readers: tuple[LogReader, LogReader], classes: dict[tuple[int, str], Any]) -> None:
    difference.compared += 1
    if a == b:
        return
    fields = decoded_differences(message.topic, a, b, readers, classes)
    if not fields:  # the same values, encoded differently (field order): not a difference
        return
    difference.differing += 1
    if difference.first_frame is None or message.sequence < difference.first_frame:
        difference.first_frame = message.sequence
        difference.fields = fields


def decoded_differences(topic: str, a: bytes, b: bytes, readers: tuple[LogReader, LogReader],
                        classes: dict[tuple[int, str], Any]) -> list[tuple[str, Any, Any]]:
    values = []
    for index, (reader, data) in enumerate(zip(readers, (a, b))):
        if (index, topic) not in classes:
            classes[(index, topic)] = message_class(reader, topic)
        values.append(to_python(classes[(index, topic)].FromString(data)))
    return field_differences(values[0], values[1])


def field_differences(a: Any, b: Any, path: str = "") -> list[tuple[str, Any, Any]]:
    """Every leaf where ``a`` and ``b`` differ, as (dotted path, value in a, value in b); bit-exact floats."""
    if isinstance(a, dict) and isinstance(b, dict):
        found = []
        for key in sorted(set(a) | set(b)):
            found += field_differences(a.get(key), b.get(key), f"{path}.{key}" if path else key)
        return found
    if isinstance(a, np.ndarray) or isinstance(b, np.ndarray):
        if not (isinstance(a, np.ndarray) and isinstance(b, np.ndarray)) or a.shape != b.shape or a.dtype != b.dtype \
                or a.tobytes() != b.tobytes():
            return [(path, _short(a), _short(b))]
        return []
    if isinstance(a, list) and isinstance(b, list):
        if len(a) != len(b):
            return [(f"{path} (length)", len(a), len(b))]
        found = []
        for index, (x, y) in enumerate(zip(a, b)):
            found += field_differences(x, y, f"{path}[{index}]")
        return found
    if isinstance(a, float) and isinstance(b, float):
        same = (math.isnan(a) and math.isnan(b)) or (a == b and math.copysign(1, a) == math.copysign(1, b))
        return [] if same else [(path, a, b)]
    return [] if a == b else [(path, a, b)]


def _short(value: Any) -> Any:
    if isinstance(value, np.ndarray):
        return f"array{value.shape} {value.dtype}" + (f" {value.ravel()[:6].tolist()}" if value.size else "")
    return value


def run_compare(args: argparse.Namespace) -> int:
    reps = [r.strip() for r in args.rep.split(",") if r.strip()] if args.rep else None
    try:
        with LogReader(args.first) as first, LogReader(args.second) as second:
            result = compare_logs(first, second, reps, timing=args.timing)
            skipped = [] if reps else sorted(t for t in set(first.channels) | set(second.channels)
                                             if t not in result and (is_timing(first, t) or is_timing(second, t)))
            problems = first.problems + second.problems
    except LogError as exc:
        print(f"tafel log compare: error: {exc}", file=sys.stderr)
        return 2
    differing = [d for d in result.values() if d.differs]
    if args.json:
        print(json.dumps({topic: {**d.__dict__, "fields": [list(f) for f in d.fields]} for topic, d in result.items()},
                         default=str, indent=2))
    else:
        for difference in result.values():
            print(_line(difference))
            for path, a, b in difference.fields[:10]:
                print(f"      {path}: {a!r} != {b!r}")
            if len(difference.fields) > 10:
                print(f"      ... and {len(difference.fields) - 10} more fields")
        for topic in skipped:
            print(f"  skipped  {topic}: not compared (not state: timing or debug output; --all compares it)")
        verdict = f"{len(differing)} of {len(result)} channels differ" if differing else f"no difference in {len(result)} channels"
        print(verdict)
    for problem in problems:
        print(f"note: {problem}", file=sys.stderr)
    return 1 if differing else 0


def _line(d: ChannelDifference) -> str:
    if not d.differs:
        return f"  same     {d.topic}: {d.compared} frames"
    parts = [f"{d.differing} of {d.compared} frames differ"]
    if d.first_frame is not None:
        parts.append(f"first at frame {d.first_frame}")
    if d.only_first:
        parts.append(f"{d.only_first} frames only in A")
    if d.only_second:
        parts.append(f"{d.only_second} frames only in B")
    return f"  DIFFERS  {d.topic}: " + ", ".join(parts)
