"""Recording representations while a program runs, switchable at run time.

Which representations: per context, always those the platform provides (sensor data, which replay
needs) and the frame clock the runtime writes (``FrameInfo``: replay runs each frame at its recorded
number and time), plus the names chosen in configuration (``[recording] representations``) or with
``--record-reps`` (which replaces the configured names; ``all`` records every representation). Each is
recorded in the context that owns it (the platform's or the provider module's), not where it was
handed over to. Serialization happens in the loop (a few microseconds a message); writing happens in
the background.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any, Protocol

from tafel.core.framework.contexts import Context
from tafel.core.framework.errors import UnknownModuleError
from tafel.core.framework.frame_info import FrameInfo
from tafel.core.framework.manager import Blackboard
from tafel.core.framework.naming import did_you_mean
from tafel.core.framework.representation import is_state
from tafel.core.logs import LogWriter, Translate
from tafel.core.logs.serialization import SerializationError, serialize

if TYPE_CHECKING:  # plans only for their type: logs sit below the runtime
    from tafel.core.runtime.program import ContextPlan

#: the name that selects every representation of the program
ALL = "all"


class Sink(Protocol):
    def write(self, topic: str, cls: type, time_ns: int, sequence: int, data: bytes,
              metadata: Mapping[str, str] | None = None) -> bool: ...


@dataclass(frozen=True)
class Selection:
    """One recorded representation of one context, with who writes it (channel metadata)."""

    context: str
    rep: type
    source: str
    provider: str = ""

    @property
    def topic(self) -> str:
        return f"{self.context}/{self.rep.__name__}"

    @property
    def metadata(self) -> dict[str, str]:
        return {"source": self.source, **({"provider": self.provider} if self.provider else {}),
                **({} if is_state(self.rep) else {"state": "false"})}


def select(plans: Mapping[str, ContextPlan], names: Iterable[str] | None, *, include_sensors: bool = True,
           extra: Iterable[type] = (), strict: bool = True) -> list[Selection]:
    """The representations to record; with ``strict``, unknown names fail with the closest known ones
    (names a user typed), otherwise names that this program does not have are skipped (defaults from
    configuration that another platform's modules provide). A name may be a topic, ``motion/FrameInfo``:
    then only that context's (a context that is none, ``Motion/FrameInfo``, is an error either way).

    ``extra`` are representations every running context can fill besides its modules (debug data).
    """
    owners: dict[str, list[Selection]] = {}
    for context, plan in plans.items():
        if not plan.runs:
            continue
        for rep in extra:
            owners.setdefault(rep.__name__, []).append(Selection(context, rep, "debug"))
        owners.setdefault(FrameInfo.__name__, []).append(Selection(context, FrameInfo, "runtime"))
        for rep in plan.platform_provides:
            owners.setdefault(rep.__name__, []).append(Selection(context, rep, "platform"))
        providers = {rep: m for m in plan.active_modules() for rep in m.requirements().provides}
        for rep, module in providers.items():
            provider = plan.providers.get(rep.__name__) or module.__name__
            owners.setdefault(rep.__name__, []).append(Selection(context, rep, "module", provider))
    #: name -> the contexts it is chosen in (None: every context that has it); "motion/FrameInfo" chooses one
    chosen: dict[str, set[str] | None] = {}
    for entry in dict.fromkeys(names or []):
        prefix, slash, name = entry.rpartition("/")
        if slash:
            context = Context.of(prefix, f"{entry!r}: the context before /", UnknownModuleError).value
            if context not in plans or not plans[context].runs:
                if strict:
                    raise UnknownModuleError(f"cannot record {entry!r}: this program runs no {context} context")
                continue
            if name in owners and all(o.context != context for o in owners[name]) and strict:
                raise UnknownModuleError(f"cannot record {entry!r}: {name} is in "
                                         f"{' and '.join(sorted({o.context for o in owners[name]}))}, not in {context}")
            here = chosen.setdefault(name, set())
            if here is not None:
                here.add(context)
        else:
            chosen[entry] = None
    if ALL in chosen:  # every representation of the program; debug data only when named
        chosen = {**{n: None for n, owned in owners.items() if any(o.source != "debug" for o in owned)}, **chosen}
    for name in chosen:
        if name not in owners and name != ALL and strict:
            raise UnknownModuleError(f"cannot record {name!r}: no context has it; {did_you_mean(name, owners)}")
    result: list[Selection] = []
    for name, selections in owners.items():
        for selection in selections:
            sensor = selection.source == "platform" or selection.rep is FrameInfo  # replay needs both
            contexts = chosen.get(name, set())
            if (name in chosen and (contexts is None or selection.context in contexts)) or (include_sensors and sensor):
                result.append(selection)
    return list(dict.fromkeys(result))


class Recorder:
    """Serializes the selected representations after every frame into a sink (a ``LogWriter``)."""

    def __init__(self, selections: list[Selection], metadata: Mapping[str, str] | None = None) -> None:
        self.by_context: dict[str, list[Selection]] = {}
        for selection in selections:
            self.by_context.setdefault(selection.context, []).append(selection)
        self.metadata = dict(metadata or {})
        self.sink: Sink | None = None
        self.writer: LogWriter | None = None
        self.path: Path | None = None
        self.frames_recorded: dict[str, int] = {}
        self.errors: dict[str, str] = {}
        #: messages dropped before they reached the writer (the concurrent runtime's forwarding)
        self.forward_dropped = 0
        self._last_writer: LogWriter | None = None
        self.blocking = False
        #: records only while this returns True (set in context processes of the concurrent runtime)
        self.gate: Any = None
        #: called with True on start and False on stop
        self.listeners: list[Any] = []
        #: makes the hook that adds channels to each new file (tools sets it: Foxglove's channels)
        self.translate_factory: Callable[[], Translate] | None = None

    @property
    def recording(self) -> bool:
        return self.sink is not None and not self.failed

    @property
    def failed(self) -> str:
        """Why recording stopped by itself (the file could not be written), or ''."""
        writer = self.writer or self._last_writer
        return writer.error if writer is not None and writer.failed else ""

    def start(self, path: str | Path, *, blocking: bool | None = None, exclusive: bool = False) -> None:
        """Start writing to a new file (stops the current one first).

        ``blocking`` makes a full queue wait instead of dropping: for runs without a beat to keep.
        ``exclusive`` refuses to replace an existing file (``LogExistsError``): for names a client chose.
        """
        self.stop()
        if blocking is not None:
            self.blocking = blocking
        self.writer = LogWriter(path, metadata=self.metadata, exclusive=exclusive,
                                translate=self.translate_factory() if self.translate_factory is not None else None)
        self.writer.blocking = self.blocking
        for listener in self.listeners:
            listener(True)
        self.sink = self.writer
        self.path = Path(path)
        self.frames_recorded = {}

    def attach(self, sink: Sink) -> None:
        """Record into an existing sink (the concurrent runtime forwards to one writer)."""
        self.sink = sink

    def stop(self) -> dict[str, Any]:
        """Stop recording and finish the file; returns the final status."""
        status = self.status()
        if self.writer is not None:
            self.writer.close()
            status = self.status()
            self._last_writer = self.writer
        if self.sink is not None:
            for listener in self.listeners:
                listener(False)
        self.sink = None
        self.writer = None
        return status

    def status(self) -> dict[str, Any]:
        writer = self.writer or self._last_writer
        return {
            "recording": self.recording,
            "file": str(self.path) if self.path else "",
            "frames": dict(self.frames_recorded),
            "messages": writer.written if writer else 0,
            "dropped": writer.dropped if writer else 0,
            "bytes": writer.bytes_written if writer else 0,
            "error": (writer.error if writer else "") or "; ".join(f"{k}: {v}" for k, v in self.errors.items()),
            "failed": bool(writer and writer.failed),
        }

    def dropped_total(self) -> int:
        return self.status()["dropped"] + self.forward_dropped

    def record(self, context: str, blackboard: Blackboard, frame_number: int, time_ns: int) -> None:
        sink = self.sink
        if sink is None or (self.gate is not None and not self.gate()) or (self.writer is not None and self.writer.failed):
            return
        for selection in self.by_context.get(context, ()):
            if selection.rep not in blackboard:  # debug data of a program without the debug server
                continue
            try:
                data = serialize(blackboard[selection.rep])
            except SerializationError as exc:  # report once per topic, keep recording the rest
                self.errors.setdefault(selection.topic, str(exc))
                continue
            sink.write(selection.topic, selection.rep, time_ns, frame_number, data, selection.metadata)
        self.frames_recorded[context] = self.frames_recorded.get(context, 0) + 1


class QueueSink:
    """Forwards recorded messages to another process's writer without ever blocking."""

    def __init__(self, target: Any) -> None:
        self.target = target
        self.dropped = 0

    def write(self, topic: str, cls: type, time_ns: int, sequence: int, data: bytes,
              metadata: Mapping[str, str] | None = None) -> bool:
        import queue

        try:
            self.target.put_nowait((topic, cls, time_ns, sequence, data, dict(metadata or {})))
            return True
        except queue.Full:
            self.dropped += 1
            return False
