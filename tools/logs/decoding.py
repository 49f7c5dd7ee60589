"""Log messages decoded to plain Python, with the protobuf schemas stored in the log itself: what ``tafel log``'s
export, ``tafel log compare`` and batch replay read logs with (no generated code needed, so a log stays readable
after the representations change)."""

from __future__ import annotations

import sys
from collections.abc import Iterator
from typing import Any

import numpy as np
from google.protobuf import descriptor_pool, message_factory

from tafel.core.framework.naming import did_you_mean
from tafel.core.logs import LogError, LogReader


def message_class(reader: LogReader, topic: str) -> Any:
    """The protobuf class of a channel, built from the schema stored in the log."""
    channel = reader.channels[topic]
    if channel.schema is None:
        raise LogError(f"{reader.path}: channel {topic} has no protobuf schema")
    pool = descriptor_pool.DescriptorPool()
    pool.Add(channel.schema)
    return message_factory.GetMessageClass(pool.FindMessageTypeByName(channel.schema_name))


def topics_of(reader: LogReader, rep: str, context: str | None = None) -> list[str]:
    """The channels holding ``rep`` (in ``context``); ``LogError`` with the closest names otherwise."""
    topics = [t for t, c in reader.channels.items() if c.representation == rep and (context is None or c.context == context)]
    if not topics:
        names = sorted({c.representation for c in reader.channels.values()})
        raise LogError(f"{reader.path} holds no representation {rep!r}" + (f" in {context}" if context else "") + f"; {did_you_mean(rep, names)}")
    return topics


def decoded_messages(reader: LogReader, rep: str, context: str | None) -> Iterator[tuple[str, int, int, dict[str, Any]]]:
    """(context, frame, time_ns, fields) for every message of ``rep``, decoded with the log's schema."""
    classes = {topic: message_class(reader, topic) for topic in topics_of(reader, rep, context)}
    for message in reader.messages(classes):
        try:
            decoded = classes[message.topic].FromString(message.data)
        except Exception as exc:  # noqa: BLE001 - a damaged message is skipped, named
            print(f"\nskipping {message.topic} frame {message.sequence}: {exc}", file=sys.stderr)
            continue
        yield reader.channels[message.topic].context, message.sequence, message.time_ns, to_python(decoded)


def to_python(message: Any) -> dict[str, Any]:
    """A protobuf message as plain Python values; ``NDArray`` messages become numpy arrays."""
    result: dict[str, Any] = {}
    for field in message.DESCRIPTOR.fields:
        value = getattr(message, field.name)
        if field.message_type is not None:
            convert = _array if field.message_type.name == "NDArray" else to_python
            if field.is_repeated:
                result[field.name] = [convert(v) for v in value]
            elif message.HasField(field.name):
                result[field.name] = convert(value)
            else:
                result[field.name] = None
        else:
            result[field.name] = list(value) if field.is_repeated else value
    return result


def _array(message: Any) -> np.ndarray:
    return np.frombuffer(message.data, dtype=np.dtype(message.dtype)).reshape(tuple(message.shape))
