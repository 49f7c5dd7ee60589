"""``write_slice``: a piece of a log (some representations, some seconds) copied into a new one, schemas and
metadata with it, for module tests of recorded situations."""

from __future__ import annotations

import os
from collections.abc import Iterable
from pathlib import Path

from mcap.writer import CompressionType, Writer

from tafel.core.logs.format import PROFILE, LogError
from tafel.core.logs.reader import LogReader
from tafel.core.logs.writer import Translate, _ExtraChannels


def write_slice(source: str | Path, target: str | Path, *, representations: Iterable[str] | None = None,
                start_s: float = 0.0, seconds: float | None = None, translate: Translate | None = None) -> dict[str, int]:
    """Copy part of a log into a new one: the chosen representations (all without a choice), from
    ``start_s`` after the log's first message for ``seconds``. Schemas, channel metadata and the
    recording's metadata travel along, so the slice replays and decodes like the original.

    ``translate`` adds channels made from the copied messages (``tafel log convert``: Foxglove's). A log
    from before wall-clock log times gets them: its frame times moved to end when the file was last
    written. Returns messages per topic. Raises ``LogError`` when nothing would be copied.
    """
    from tafel.core.framework.representation import get_representation

    wanted = set(representations) if representations else None
    with LogReader(source) as reader:
        topics = [t for t, c in reader.channels.items() if wanted is None or c.representation in wanted]
        if wanted is not None and (unknown := wanted - {reader.channels[t].representation for t in topics}):
            from tafel.core.framework.naming import did_you_mean

            names = sorted({c.representation for c in reader.channels.values()})
            name = sorted(unknown)[0]
            raise LogError(f"{source} holds no representation {name!r}; {did_you_mean(name, names)}")
        first = next(iter(reader.messages(topics)), None)
        if first is None:
            raise LogError(f"{source} holds no messages of {', '.join(sorted(wanted)) if wanted else 'any channel'}")
        begin = first.time_ns + int(start_s * 1e9)
        end = None if seconds is None else begin + int(seconds * 1e9)
        last_ns = max((c.end_ns for c in reader.chunks), default=0)
        anchor_ns = os.stat(source).st_mtime_ns - last_ns  # for logs whose log times are frame times
        counts: dict[str, int] = {}
        with open(target, "wb") as stream:
            writer = Writer(stream, compression=CompressionType.ZSTD)
            writer.start(profile=PROFILE, library="tafel")
            if reader.metadata:
                writer.add_metadata(PROFILE, {**reader.metadata, "sliced_from": Path(source).name,
                                              "slice_start_s": f"{start_s:g}"})
            schema_ids: dict[str, int] = {}
            channel_ids: dict[str, int] = {}
            extras = _ExtraChannels(writer)
            for message in reader.messages(topics, start_ns=begin):
                if message.time_ns < begin or (end is not None and message.time_ns >= end):
                    continue
                channel = reader.channels[message.topic]
                if message.topic not in channel_ids:
                    if channel.schema_name not in schema_ids:
                        schema_ids[channel.schema_name] = writer.register_schema(
                            name=channel.schema_name, encoding="protobuf", data=channel.schema_data)
                    channel_ids[message.topic] = writer.register_channel(
                        topic=message.topic, message_encoding="protobuf", schema_id=schema_ids[channel.schema_name],
                        metadata=dict(channel.metadata))
                wall_ns = message.log_time_ns if message.log_time_ns != message.time_ns else anchor_ns + message.time_ns
                writer.add_message(channel_ids[message.topic], log_time=wall_ns, data=message.data,
                                   publish_time=message.time_ns, sequence=message.sequence)
                counts[message.topic] = counts.get(message.topic, 0) + 1
                if translate is not None:
                    try:
                        cls = get_representation(channel.representation)
                    except KeyError:
                        continue
                    for extra in translate(message.topic, cls, message.time_ns, wall_ns, message.data):
                        extras.add(extra)
                        counts[extra.topic] = counts.get(extra.topic, 0) + 1
            writer.finish()
    if not counts:
        Path(target).unlink(missing_ok=True)
        raise LogError(f"{source}: no message between {start_s:g} s and {'the end' if seconds is None else f'{start_s + seconds:g} s'}")
    return counts


