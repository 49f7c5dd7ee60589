"""``tafel log info``, ``export`` and ``compare``: look into recorded MCAP logs.

All of them stream through the file chunk by chunk, so logs of any length can be read. Export and
compare decode with the schemas stored in the log itself, so they work for logs written by older
versions of the code too.
"""

from __future__ import annotations

import argparse
import csv
import json
import logging
import sys
from collections.abc import Iterator
from typing import Any

import numpy as np

from tafel.core.framework.values import Range, ValueCheckError, convert
from tafel.core.logs import LogError, LogReader, write_slice
from tafel.tools.logs.decoding import decoded_messages, topics_of


def run_log_command(args: argparse.Namespace) -> int:
    if args.log_command == "compare":
        from tafel.tools.logs.log_compare import run_compare

        return run_compare(args)
    if args.log_command in ("slice", "convert"):
        return run_slice(args)
    logging.getLogger("tafel.log").setLevel(logging.ERROR)  # the commands print the problems themselves
    try:
        reader = LogReader(args.file)
    except LogError as exc:
        print(f"tafel log: error: {exc}", file=sys.stderr)
        return 1
    with reader:
        if args.log_command == "info":
            return print_info(reader, args.json)
        return export(reader, args)


def run_slice(args: argparse.Namespace) -> int:
    """``tafel log slice`` and ``tafel log convert`` (a whole copy with Foxglove's channels added)."""
    name = f"tafel log {args.log_command}"
    converting = args.log_command == "convert"
    try:
        start, seconds = (0.0, None) if converting else (
            convert(args.start, float, where="--start", bounds=Range(0.0), unit="seconds", text=False),
            convert(args.seconds, float | None, where="--seconds", bounds=Range(0.0, low_open=True), unit="seconds", text=False))
        if converting:
            convert(args.jpeg_quality, int, where="--jpeg-quality", bounds=(1, 100), text=False)
    except ValueCheckError as exc:
        print(f"{name}: error: {exc}", file=sys.stderr)
        return 2
    if args.out.resolve() == args.file.resolve():
        print(f"{name}: error: --out must be another file than the log it reads", file=sys.stderr)
        return 2
    translate = None
    if converting:
        from tafel.tools.launch.program import discover_modules
        from tafel.tools.viewers.foxglove_channels import FoxgloveTranslator

        discover_modules()  # every representation class, to decode what the log holds
        translate = FoxgloveTranslator(args.jpeg_quality).translate
    try:
        counts = write_slice(args.file, args.out, representations=None if converting or not args.rep else args.rep.split(","),
                             start_s=start, seconds=seconds, translate=translate)
    except LogError as exc:
        print(f"{name}: error: {exc}", file=sys.stderr)
        return 1
    print(f"wrote {args.out}: {sum(counts.values())} messages in {len(counts)} channels ({_size(args.out.stat().st_size)})")
    return 0


def print_info(reader: LogReader, as_json: bool) -> int:
    info = reader.summary()
    if as_json:
        print(json.dumps(info, indent=2))
        return 0
    state = "complete" if info["complete"] else "recovered what was complete"
    print(f"file: {info['file']} ({state})")
    if info["problem"]:
        print(f"problem: {info['problem']}")
    print(f"duration: {info['duration_s']:.3f} s")
    print("frames: " + (", ".join(f"{c} {n}" for c, n in info["frames"].items()) or "none"))
    if info["metadata"]:
        print("recorded: " + ", ".join(f"{k}={v}" for k, v in sorted(info["metadata"].items())))
    print("channels:")
    for topic, channel in info["channels"].items():
        source = channel.get("source", "?") + (f" {channel['provider']}" if channel.get("provider") else "")
        print(f"  {topic:<36} {channel['messages']:>7} messages {_size(channel['bytes']):>10}  ({source})")
    if info["extra_channels"]:
        print("for Foxglove: " + ", ".join(f"{topic} ({schema})" for topic, schema in info["extra_channels"].items()))
    return 0


def _size(n: int) -> str:
    for unit in ("B", "kB", "MB", "GB"):
        if n < 1000 or unit == "GB":
            return f"{n:.0f} {unit}" if unit == "B" else f"{n:.1f} {unit}"
        n /= 1000
    return str(n)


# ----------------------------------------------------------------------------------------- export
def _jsonable(value: Any) -> Any:
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, dict):
        return {k: _jsonable(v) for k, v in value.items()}
    if isinstance(value, list):
        return [_jsonable(v) for v in value]
    if isinstance(value, bytes):
        return value.hex()
    return value


def _flatten(fields: dict[str, Any], prefix: str = "") -> dict[str, Any]:
    flat: dict[str, Any] = {}
    for key, value in fields.items():
        name = f"{prefix}{key}"
        if isinstance(value, dict):
            flat.update(_flatten(value, name + "."))
        elif isinstance(value, (list, np.ndarray)):
            flat[name] = json.dumps(_jsonable(value))
        else:
            flat[name] = _jsonable(value)
    return flat


class Progress:
    """A progress bar on stderr for long exports (over 200 messages), drawn only on a terminal:
    carriage returns in a file or a pipe are noise."""

    def __init__(self, label: str, total: int, stream: Any = None) -> None:
        self.label, self.total, self.shown = label, total, -1
        self.stream = stream or sys.stderr
        self.enabled = total >= 200 and bool(getattr(self.stream, "isatty", lambda: False)())

    def update(self, done: int) -> None:
        if not self.enabled:
            return
        percent = done * 100 // self.total
        if percent != self.shown:
            self.shown = percent
            bar = "#" * (percent // 5) + "-" * (20 - percent // 5)
            print(f"\r{self.label} [{bar}] {percent:3d}% ({done}/{self.total})", end="", file=self.stream, flush=True)

    def close(self) -> None:
        if self.enabled:
            print(file=self.stream)


def export(reader: LogReader, args: argparse.Namespace) -> int:
    try:
        total = _message_count(reader, topics_of(reader, args.rep, args.context))
        rows = decoded_messages(reader, args.rep, args.context)
        progress = Progress(f"exporting {args.rep}", total)
        written = _write(rows, args, progress)
        progress.close()
    except LogError as exc:
        print(f"tafel log: error: {exc}", file=sys.stderr)
        return 1
    except OSError as exc:
        print(f"tafel log: error: cannot write {args.out}: {exc.strerror}", file=sys.stderr)
        return 1
    print(f"exported {written} {args.rep} {'images' if args.format == 'png' else 'rows'} to {args.out}")
    for problem in reader.problems:
        print(f"note: {problem}", file=sys.stderr)
    return 0


def _message_count(reader: LogReader, topics: list[str]) -> int:
    """How many messages the topics hold, from the summary's statistics where the file has trusted ones (else 0: no bar)."""
    counts = reader.message_counts or {}
    return sum(counts.get(topic, 0) for topic in topics)


def _write(rows: Iterator[tuple[str, int, int, dict[str, Any]]], args: argparse.Namespace, progress: Progress) -> int:
    count = 0
    if args.format == "png":
        import cv2

        args.out.mkdir(parents=True, exist_ok=True)
        for done, (context, frame, _time, fields) in enumerate(rows, start=1):
            if done == 1 and not any(isinstance(v, np.ndarray) and _is_image(v) for v in fields.values()):
                raise LogError(f"{args.rep} holds no image (a uint8 array of height x width, with 1, 3 or 4 channels); "
                               "export it with --format csv or --format jsonl")
            for name, value in fields.items():
                if isinstance(value, np.ndarray) and _is_image(value):
                    image = cv2.cvtColor(value, cv2.COLOR_RGB2BGR) if value.ndim == 3 and value.shape[2] == 3 else value
                    path = args.out / f"{context}_{args.rep}_{name}_{frame:06d}.png"
                    if not cv2.imwrite(str(path), image):
                        raise OSError(0, f"OpenCV could not write {path}")
                    count += 1
            progress.update(done)
        return count
    args.out.parent.mkdir(parents=True, exist_ok=True)
    with open(args.out, "w", newline="") as handle:
        writer = None
        for done, (context, frame, time_ns, fields) in enumerate(rows, start=1):
            row = {"context": context, "frame": frame, "time_ns": time_ns}
            if args.format == "jsonl":
                handle.write(json.dumps({**row, **_jsonable(fields)}) + "\n")
            else:
                row.update(_flatten(fields))
                if writer is None:
                    writer = csv.DictWriter(handle, fieldnames=list(row))
                    writer.writeheader()
                writer.writerow(row)
            count += 1
            progress.update(done)
    return count


def _is_image(array: np.ndarray) -> bool:
    return array.dtype == np.uint8 and (array.ndim == 2 or (array.ndim == 3 and array.shape[2] in (1, 3, 4))) and array.size > 0
