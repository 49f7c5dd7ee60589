"""The black-box recorder: the last seconds of every representation, always, in memory; saved on a trigger.

A fall or a crash at a competition is rarely recorded, because nobody recorded the whole game. The
``BlackBox`` is a sink for a ``Recorder`` that records every representation of both contexts all the
time: it keeps the serialized messages (the log's own form) of the last ``seconds`` in a ring, bounded
by ``max_bytes``; heavy messages (camera images) are kept at most once per ``heavy_period_s`` per
channel. ``save(trigger)`` writes the ring to a new MCAP file in ``folder`` while the program goes on
(a background thread), with the trigger and its time in the file's metadata (``blackbox``); the file
replays like any log.

Triggers (``Triggers``) watch the stream itself: a fall (``FallState``), a GameController penalty of
this robot (``GameState``), the chest button pressed three times within two seconds (``ChestButton``),
and conditions from configuration (``[[blackbox.triggers]]``: a representation's field ``equals``,
``at_least`` or ``at_most`` a value for ``for_s`` seconds). The runtimes add module exceptions and
missed frames (``note``); ``blackbox:save`` saves by hand.
"""

from __future__ import annotations

import collections
import logging
import math
import threading
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from tafel.core.framework.config import ConfigError
from tafel.core.framework.contexts import Context
from tafel.core.framework.values import Range, convert
from tafel.core.logs.serialization import deserialize
from tafel.core.logs.writer import LogWriter, PendingMessage

log = logging.getLogger("tafel.blackbox")

#: defaults of ``[blackbox]``
SECONDS = 20.0
MAX_MB = 200.0
HEAVY_BYTES = 64 * 1024
HEAVY_PERIOD_S = 0.5
#: s after a save in which further triggers are counted but save nothing (a failure every frame)
COOLDOWN_S = 10.0


@dataclass(frozen=True)
class Condition:
    """``[[blackbox.triggers]]``: ``name``'s ``field`` (dotted) equals / is at least / at most a value for ``for_s``."""

    name: str
    field: str
    equals: Any = None
    at_least: float | None = None
    at_most: float | None = None
    for_s: float = 0.0
    context: str = ""

    def holds(self, value: Any) -> bool:
        if self.equals is not None:
            actual = value.name if hasattr(value, "name") and isinstance(self.equals, str) else value
            return bool(actual == self.equals)
        number = float(value)
        return (self.at_least is None or number >= self.at_least) and (self.at_most is None or number <= self.at_most)

    def describe(self) -> str:
        test = (f"== {self.equals!r}" if self.equals is not None else
                " and ".join(p for p in (f">= {self.at_least:g}" if self.at_least is not None else "",
                                         f"<= {self.at_most:g}" if self.at_most is not None else "") if p))
        return f"{self.name}.{self.field} {test}" + (f" for {self.for_s:g} s" if self.for_s else "")


def conditions_from_config(table: Any) -> list[Condition]:
    """The ``[[blackbox.triggers]]`` tables; ``ConfigError`` with what would be right."""
    if table is None:
        return []
    convert(table, list[dict[str, Any]], where="blackbox.triggers", text=False, error=ConfigError,
            expected="tables: [[blackbox.triggers]] with name, field and equals, at_least or at_most")
    known = {"name", "field", "equals", "at_least", "at_most", "for_s", "context"}
    result = []
    for index, entry in enumerate(table, 1):
        where = f"[[blackbox.triggers]] number {index}"
        unknown = sorted(set(entry) - known)
        if unknown:
            raise ConfigError(f"{where}: unknown keys {', '.join(unknown)}; a trigger takes {', '.join(sorted(known))}")
        for key, what in (("name", "a representation's name"), ("field", "a field's name (dotted for nested ones)")):
            convert(entry.get(key), str, where=f"{where}: {key}", text=False, expected=what, error=ConfigError)
        tests = [key for key in ("equals", "at_least", "at_most") if key in entry]
        if not tests:
            raise ConfigError(f"{where}: give equals, at_least or at_most")
        at_least, at_most = (convert(entry.get(key), float | None, where=f"{where}: {key}", text=False, error=ConfigError)
                             for key in ("at_least", "at_most"))
        for_s = convert(entry.get("for_s", 0.0), float, where=f"{where}: for_s", bounds=Range(0.0), unit="seconds",
                        text=False, error=ConfigError)
        context = "" if "context" not in entry else Context.of(entry["context"], f"{where}: context", ConfigError).value
        result.append(Condition(entry["name"], entry["field"], entry.get("equals"), at_least, at_most, for_s, context))
    return result


class Triggers:
    """Watches the recorded stream for the events that save the black box; calls ``fire(reason, time_ns)``."""

    def __init__(self, conditions: Sequence[Condition], fire: Callable[[str, int], object]) -> None:
        self.conditions = list(conditions)
        self.fire = fire
        self.since: dict[Condition, int | None] = dict.fromkeys(self.conditions)
        self.fired: set[Condition] = set()
        self.was_down = False
        self.was_penalized = False
        self.presses: collections.deque[tuple[int, int]] = collections.deque()
        self.last_presses: int | None = None
        wanted = {"FallState", "GameState", "ChestButton", *(c.name for c in self.conditions)}
        self.wanted = frozenset(wanted)

    def see(self, message: PendingMessage) -> None:
        name = message.topic.split("/", 1)[-1]
        if name not in self.wanted:
            return
        try:
            value = deserialize(message.cls, message.data)
        except Exception:  # noqa: BLE001 - a trigger never takes the stream down
            return
        context = message.topic.split("/", 1)[0]
        if name == "FallState":
            down = value.phase.name in ("falling", "lying_front", "lying_back", "lying_side")
            if down and not self.was_down:
                self.fire(f"fall ({value.phase.name})", message.time_ns)
            self.was_down = down
        elif name == "GameState":
            penalized = bool(value.penalized)
            if penalized and not self.was_penalized:
                self.fire("GameController penalty", message.time_ns)
            self.was_penalized = penalized
        elif name == "ChestButton":
            if self.last_presses is not None and value.presses > self.last_presses:
                self.presses.append((message.time_ns, value.presses - self.last_presses))
            self.last_presses = value.presses
            while self.presses and message.time_ns - self.presses[0][0] > 2_000_000_000:
                self.presses.popleft()
            if sum(count for _, count in self.presses) >= 3:
                self.presses.clear()
                self.fire("chest button pressed three times", message.time_ns)
        for condition in self.conditions:
            if condition.name == name and (not condition.context or condition.context == context):
                self._check(condition, value, message.time_ns)

    def _check(self, condition: Condition, value: Any, time_ns: int) -> None:
        try:
            for part in condition.field.split("."):
                value = getattr(value, part)
            holds = condition.holds(value)
        except (AttributeError, TypeError, ValueError):
            holds = False
        if not holds:
            self.since[condition] = None
            self.fired.discard(condition)
            return
        start = self.since.get(condition)
        if start is None:
            self.since[condition] = start = time_ns
        if condition not in self.fired and time_ns - start >= condition.for_s * 1e9:
            self.fired.add(condition)  # once per time it holds
            self.fire(condition.describe(), time_ns)


class BlackBox:
    """A ``Recorder`` sink that keeps the last ``seconds`` in memory and saves them on a trigger."""

    def __init__(self, folder: Path, *, seconds: float = SECONDS, max_bytes: int = int(MAX_MB * 1e6),
                 heavy_period_s: float = HEAVY_PERIOD_S, metadata: Mapping[str, str] | None = None,
                 conditions: Sequence[Condition] = (), cooldown_s: float = COOLDOWN_S) -> None:
        self.folder = folder
        self.seconds = seconds
        self.max_bytes = max_bytes
        self.heavy_period_ns = int(heavy_period_s * 1e9)
        self.metadata = dict(metadata or {})
        self.cooldown_s = cooldown_s
        self.ring: collections.deque[PendingMessage] = collections.deque()
        self.bytes = 0
        self.last_heavy: dict[str, int] = {}
        self.lock = threading.Lock()
        self.triggers = Triggers(conditions, self.save)
        #: (trigger, path or why not) of each save, newest last
        self.saves: list[tuple[str, str]] = []
        self.last_save = -math.inf
        self.suppressed = 0
        self.on_save: list[Callable[[str, Path], None]] = []
        self.writers: list[threading.Thread] = []

    # -------------------------------------------------------------------------------------- the sink
    def write(self, topic: str, cls: type, time_ns: int, sequence: int, data: bytes,
              metadata: Mapping[str, str] | None = None) -> bool:
        if len(data) > HEAVY_BYTES:
            if time_ns - self.last_heavy.get(topic, -self.heavy_period_ns) < self.heavy_period_ns:
                return True
            self.last_heavy[topic] = time_ns
        message = PendingMessage(topic, cls, time_ns, sequence, data, metadata or {}, time.time_ns())
        with self.lock:
            self.ring.append(message)
            self.bytes += len(data)
            oldest = time_ns - int(self.seconds * 1e9)
            while self.ring and (self.ring[0].time_ns < oldest or self.bytes > self.max_bytes):
                self.bytes -= len(self.ring.popleft().data)
        self.triggers.see(message)
        return True

    # -------------------------------------------------------------------------------------- saving
    def note(self, reason: str, time_ns: int) -> None:
        """A trigger seen by the runtime (a module exception, missed frames)."""
        self.save(reason, time_ns)

    def save(self, trigger: str, time_ns: int | None = None) -> Path | None:
        """Write what the ring holds to a new file, in a background thread; None during the cooldown."""
        now = time.monotonic()
        if now - self.last_save < self.cooldown_s:
            self.suppressed += 1
            return None
        self.last_save = now
        with self.lock:
            messages = list(self.ring)
        at_ns = time_ns if time_ns is not None else (messages[-1].time_ns if messages else 0)
        slug = "".join(c if c.isalnum() else "-" for c in trigger.lower()).strip("-")[:40]
        self.folder.mkdir(parents=True, exist_ok=True)
        path = self.folder / f"blackbox-{time.strftime('%Y%m%d-%H%M%S')}-{slug}.mcap"
        suffix = 1
        while path.exists():
            suffix += 1
            path = path.with_name(f"{path.stem.rsplit('~', 1)[0]}~{suffix}.mcap")
        metadata = {**self.metadata, "blackbox_trigger": trigger, "blackbox_time_s": f"{at_ns * 1e-9:.3f}",
                    "blackbox_seconds": f"{self.seconds:g}"}
        log.warning("black box: %s at %.2f s; writing the last %g s to %s", trigger, at_ns * 1e-9, self.seconds, path)
        writer = threading.Thread(target=self._write, args=(path, messages, metadata, trigger), name="tafel-blackbox", daemon=True)
        self.writers.append(writer)
        writer.start()
        return path

    def finish(self, timeout_s: float = 30.0) -> None:
        """Wait for the saves under way (the program is ending: a file cut off would be half a log)."""
        deadline = time.monotonic() + timeout_s
        for writer in self.writers:
            writer.join(max(0.0, deadline - time.monotonic()))

    def _write(self, path: Path, messages: list[PendingMessage], metadata: dict[str, str], trigger: str) -> None:
        try:
            writer = LogWriter(path, metadata=metadata, exclusive=True)
            writer.blocking = True
            for m in messages:
                writer.write(m.topic, m.cls, m.time_ns, m.sequence, m.data, m.metadata)
            writer.close()
            error = writer.error if writer.failed else ""
        except Exception as exc:  # noqa: BLE001 - a full disk must not end the program
            error = f"{type(exc).__name__}: {exc}"
        self.saves.append((trigger, f"not written: {error}" if error else str(path)))
        if error:
            log.error("black box: %s could not be written: %s", path, error)
            return
        for callback in self.on_save:
            callback(trigger, path)

    def status(self) -> str:
        with self.lock:
            span = (self.ring[-1].time_ns - self.ring[0].time_ns) * 1e-9 if self.ring else 0.0
            count = len(self.ring)
        saved = "; ".join(f"{trigger}: {where}" for trigger, where in self.saves[-5:]) or "none yet"
        return (f"black box: {count} messages, {self.bytes / 1e6:.1f} MB of {self.max_bytes / 1e6:g} MB, {span:.1f} s of "
                f"{self.seconds:g} s; saves: {saved}" + (f"; {self.suppressed} triggers within a cooldown" if self.suppressed else ""))
