"""What a run records: the recorder of --record and log:start (with Foxglove's channels), and the black box."""

from __future__ import annotations

import argparse
import re
from collections.abc import Callable, Mapping, Sequence
from typing import Any

from tafel.core.framework.values import Range, convert, refusal
from tafel.core.logs.blackbox import MAX_MB, SECONDS, BlackBox, conditions_from_config
from tafel.core.logs.recording import Recorder, select
from tafel.core.runtime import (
    ContextStats,
)
from tafel.core.runtime.platform import Platform
from tafel.core.runtime.program import ContextPlan
from tafel.debug.executors import (
    DEBUG_REPRESENTATIONS,
)
from tafel.tools.launch.debugging import ProgramDebug
from tafel.tools.launch.errors import UsageError, fail
from tafel.tools.launch.status import status_print


def debug_recorded(recorder: Recorder | None, web_contexts: Sequence[str] = ()) -> dict[str, list[type]]:
    """Per context, the debug representations that must be filled every frame: those the recorder takes,
    and with the web view all of them (its page subscribes to them)."""
    recorded = {} if recorder is None else \
        {context: [s.rep for s in selections if s.source == "debug"] for context, selections in recorder.by_context.items()}
    for context in web_contexts:
        recorded[context] = list(dict.fromkeys([*recorded.get(context, []), *DEBUG_REPRESENTATIONS]))
    return recorded



def make_recorder(args: argparse.Namespace, plans: dict[str, ContextPlan], config: dict[str, Any], platform: Platform) -> Recorder | None:
    """The recorder of this run, started with --record; ready for log:start when the debug server runs."""
    if args.record is None and args.no_debug:
        if args.record_reps:
            fail("--record-reps needs --record FILE.mcap (or the debug server's log:start)")
        return None
    names = [n.strip() for n in args.record_reps.split(",") if n.strip()] if args.record_reps else None
    # Without a beat to keep (lockstep at --speed max) recording waits for the writer rather than drop.
    recorder = program_recorder(plans, config, platform, names, blocking=args.speed is None and not args.concurrent)
    if args.record is not None:
        recorder.start(args.record)
    return recorder


def blackbox_triggers(box: BlackBox) -> Callable[[int, Mapping[str, ContextStats] | None], None]:
    """What the runtime sees that the stream does not say: module exceptions, missed frames, a stalled
    cognition (from the contexts' statistics; None: nothing new to look at)."""
    seen: dict[tuple[str, str], int] = {}

    def check(time_ns: int, stats: Mapping[str, ContextStats] | None) -> None:
        if stats is None:
            return
        for name, s in stats.items():
            for module, count in s.errors_by_module.items():
                if count > seen.get((name, module), 0):
                    box.note(f"module exception in {module}", time_ns)
                seen[(name, module)] = count
            for what, count in (("missed frames", s.missed_periods), ("frames without cognition", s.frames_without_cognition)):
                if count > seen.get((name, what), 0) + 9:  # a few late frames (a start, a busy moment) are no event
                    box.note(f"{name} {what}", time_ns)
                    seen[(name, what)] = count

    return check


def add_blackbox_commands(debug: ProgramDebug | None, box: tuple[BlackBox, Recorder] | None) -> None:
    if debug is None or box is None:
        return
    blackbox = box[0]

    def save(_command: Any) -> str:
        path = blackbox.save("blackbox:save")
        return f"saving the last {blackbox.seconds:g} s to {path}" if path else "not saved: a save happened less than 10 s ago"

    debug.router.register("blackbox:save", "write the black box's last seconds to a log file now", "blackbox:save", save)
    debug.router.register("blackbox:status", "what the black box holds and what it saved", "blackbox:status",
                          lambda _command: blackbox.status())


#: what ``[blackbox]``'s numbers may be (seconds, MB): above 0 and at most a million
BLACKBOX_RANGE = Range(0.0, 1e6, low_open=True)
#: a JPEG quality
JPEG_QUALITY = (1, 100)


def make_blackbox(args: argparse.Namespace, plans: dict[str, ContextPlan], config: dict[str, Any],
                  platform: Platform) -> tuple[BlackBox, Recorder] | None:
    """The black-box recorder (``[blackbox]``, on by default) and the recorder that feeds it everything."""
    table = config.get("blackbox", {})
    known = {"enabled", "seconds", "max_mb", "image_period_s", "triggers"}
    unknown = sorted(set(table) - known)
    if unknown:
        fail(f"[blackbox] {unknown[0]} is not a setting; [blackbox] takes {', '.join(sorted(known))}")
    if not convert(table.get("enabled", True), bool, where="blackbox.enabled", text=False, error=UsageError):
        return None
    numbers = {key: convert(table.get(key, default), float, where=f"blackbox.{key}", bounds=BLACKBOX_RANGE, unit=unit,
                            text=False, error=UsageError)
               for key, default, unit in (("seconds", SECONDS, "seconds"), ("max_mb", MAX_MB, "MB"), ("image_period_s", 0.5, "seconds"))}
    feeder = program_recorder(plans, config, platform, ["all"], blocking=False)
    feeder.translate_factory = None
    box = BlackBox(args.record_dir, seconds=float(numbers["seconds"]), max_bytes=int(numbers["max_mb"] * 1e6),
                   heavy_period_s=float(numbers["image_period_s"]), metadata=feeder.metadata,
                   conditions=conditions_from_config(table.get("triggers")))
    box.on_save.append(lambda trigger, path: status_print(f"black box saved ({trigger}): {path}"))
    feeder.attach(box)
    return box, feeder


def program_recorder(plans: dict[str, ContextPlan], config: dict[str, Any], platform: Platform, names: list[str] | None = None,
                     blocking: bool = True) -> Recorder:
    """A recorder of ``names`` (default: the configuration's ``[recording]`` list and all sensor data), not started.

    The log's metadata names the platform and its configuration layers, so that a replay runs the
    program that was recorded (an orange ball's detector, say).
    """
    wanted = names if names is not None else list(config.get("recording", {}).get("representations", []))
    selections = select(plans, wanted, extra=DEBUG_REPRESENTATIONS, strict=names is not None)
    metadata = {"platform": type(platform).name, "config_layers": ",".join(platform.config_layers()),
                **{f"{c}_hz": str(p.rate_hz) for c, p in plans.items()}}
    recorder = Recorder(selections, metadata)
    if config.get("foxglove", {}).get("channels_in_recordings", True):
        recorder.translate_factory = foxglove_recording(recorder, jpeg_quality(config))
    recorder.blocking = blocking
    return recorder


def jpeg_quality(config: dict[str, Any]) -> int:
    """``[foxglove] jpeg_quality`` (1 to 100); anything else exits with status 2 and says so."""
    value: int = convert(config.get("foxglove", {}).get("jpeg_quality", 80), int, where="foxglove.jpeg_quality",
                         bounds=JPEG_QUALITY, text=False, error=UsageError)
    return value


def foxglove_origins(config: dict[str, Any]) -> list[str]:
    """``[foxglove] origins``: web pages (``"https://app.foxglove.dev"``) whose WebSockets the live server takes besides
    clients that send no Origin (desktop apps); anything but a list of such origins exits with status 2."""
    value = config.get("foxglove", {}).get("origins", [])
    expected = 'a list of web origins such as ["https://app.foxglove.dev"]'
    origins: list[str] = convert(value, list[str], where="foxglove.origins", text=False, expected=expected, error=UsageError)
    if not all(re.fullmatch(r"https?://[^/\s]+/?", o) for o in origins):
        raise refusal("foxglove.origins", expected, value, UsageError)
    return origins


def foxglove_recording(recorder: Recorder, quality: int) -> Callable[[], Any]:
    """The hook that gives each recorded file Foxglove's channels; their code loads with the first recording."""
    channels: list[Any] = []

    def new_file() -> Any:
        if not channels:
            from tafel.tools.viewers.foxglove_channels import RecordingChannels

            channels.append(RecordingChannels(recorder, quality))
        return channels[0].new_file()

    return new_file


def recording_notices(recorder: Recorder | None) -> list[str]:
    """What the status line says about recording when it stopped by itself (a full disk, say)."""
    return [f"RECORDING STOPPED: {recorder.failed}"] if recorder is not None and recorder.failed else []


def report_recording(recorder: Recorder | None) -> None:
    if recorder is None or recorder.path is None:
        return
    status = recorder.status()
    print(f"recorded {recorder.path}: {status['messages']} messages; {recorder.dropped_total()} dropped"
          + (f"; problems: {status['error']}" if status["error"] else ""))


