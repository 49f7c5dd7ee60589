"""Values as clients see and type them: representations printed and as JSON, and text parsed into a
field's type with the same checks every other way in has (ranges, finiteness, shapes)."""

from __future__ import annotations

import dataclasses
import enum
from typing import Any

import numpy as np

from tafel.core.framework.errors import TafelError
from tafel.core.framework.frame_info import FrameInfo
from tafel.core.framework.manager import ModuleManager
from tafel.core.framework.representation import FieldInfo, fields_of
from tafel.core.framework.values import convert, refusal


class CommandError(TafelError):
    """A command that cannot be carried out; the message becomes ``error: ...``."""


def parse_bool(text: str, what: str) -> bool:
    """``on``/``off``, ``true``/``false``, ``yes``/``no``, ``1``/``0`` as a bool, else ``CommandError``."""
    return bool(convert(text, bool, where=what, text=True, error=CommandError))


#: arrays with more elements than this are summarized in JSON (an image is no list of 230 400 numbers)
JSON_ARRAY_LIMIT = 64


def json_value(value: Any) -> Any:
    """A representation (or any value in one) as plain JSON data: dataclasses as objects, enums by name,
    small arrays as lists, large ones as their shape and range, and non-finite numbers as null."""
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        return {info.name: json_value(getattr(value, info.name)) for info in fields_of(type(value))}
    if isinstance(value, (list, tuple)):
        return [json_value(v) for v in value]
    if isinstance(value, np.ndarray):
        if value.size > JSON_ARRAY_LIMIT:
            summary: dict[str, Any] = {"shape": list(value.shape), "dtype": str(value.dtype)}
            if value.size and value.dtype.kind in "biuf":
                summary.update(min=json_value(float(value.min())), max=json_value(float(value.max())))
            return summary
        return json_value(value.tolist())
    if isinstance(value, (float, np.floating)):
        return float(value) if np.isfinite(value) else None
    if isinstance(value, (bool, np.bool_)):
        return bool(value)
    if isinstance(value, (int, np.integer)):
        return int(value)
    if isinstance(value, enum.Enum):
        return value.name
    if isinstance(value, bytes):
        return f"{len(value)} bytes"
    if isinstance(value, dict):
        return {str(k): json_value(v) for k, v in value.items()}
    return value if value is None or isinstance(value, str) else str(value)


def pretty(value: Any, indent: str = "") -> str:
    """A representation (or any value in one) as readable, indented text."""
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        lines = []
        for info in fields_of(type(value)):
            field_value = getattr(value, info.name)
            if dataclasses.is_dataclass(field_value) or (isinstance(field_value, list) and field_value and dataclasses.is_dataclass(field_value[0])):
                lines.append(f"{indent}{info.name}:")
                lines.append(pretty(field_value, indent + "  "))
            else:
                lines.append(f"{indent}{info.name}: {_short(field_value)}")
        return "\n".join(lines)
    if isinstance(value, list):
        return "\n".join(f"{indent}[{i}]\n{pretty(v, indent + '  ')}" for i, v in enumerate(value))
    return f"{indent}{_short(value)}"


def _short(value: Any) -> str:
    if isinstance(value, np.ndarray):
        if value.size > 32:
            return f"array(shape={value.shape}, dtype={value.dtype}, min={value.min():.4g}, max={value.max():.4g})"
        return np.array2string(value, precision=4, separator=", ", max_line_width=200)
    if isinstance(value, float):
        return f"{value:.6g}"
    if isinstance(value, enum.Enum):
        return value.name
    if isinstance(value, bytes):
        return f"{len(value)} bytes" if len(value) > 32 else value.hex()
    return str(value)


def _coerce_like(current: Any, text: str, what: str) -> Any:
    """``text`` read as a value of ``current``'s kind and checked (for modify values): numbers finite and
    within their natural range, arrays of ``current``'s shape and dtype, lists as JSON."""
    if isinstance(current, np.ndarray):
        values = convert(text, list[Any], where=what, text=True, expected=f"a JSON array of finite numbers of shape {current.shape}",
                         error=CommandError)
        try:
            array = np.asarray(values, dtype=current.dtype)
        except (TypeError, ValueError, OverflowError):
            raise refusal(what, f"a JSON array of numbers ({current.dtype})", text, CommandError) from None
        if array.shape != current.shape:
            raise refusal(what, f"an array of shape {current.shape}", text, CommandError)
        if array.dtype.kind == "f" and array.size:
            convert(array.ravel().tolist(), list[float], where=what, text=False, error=CommandError)  # finite, natural range
        return array
    if isinstance(current, list):
        values = convert(text, list[Any], where=what, text=True, expected="a JSON array (of finite numbers) such as [1, 2]", error=CommandError)
        for element in values:
            if isinstance(element, (int, float)) and not isinstance(element, bool):
                convert(element, type(element), where=what, text=False, error=CommandError)
        return values
    kind = str if current is None else type(current)
    return convert(text, kind, where=what, text=kind is not str, error=CommandError)


def parse_field_text(info: FieldInfo, text: str, where: str) -> Any:
    """The text of ``-value`` read as the field's kind (numbers, on/off, enum names, JSON arrays); checked later."""
    if info.kind in ("bool", "int", "float", "enum", "str"):
        kind = info.type if info.kind == "enum" else {"bool": bool, "int": int, "float": float, "str": str}[info.kind]
        return convert(text, kind, where=where, text=kind is not str, error=CommandError)
    if info.kind == "list" and info.element is not None and info.element.kind == "nested":
        raise CommandError(f"{where} holds a list of {info.element.type.__name__}; set it with +data (protobuf bytes)")
    if info.kind in ("ndarray", "list"):
        numbers = info.kind == "ndarray" or (info.element is not None and info.element.kind in ("int", "float"))
        return convert(text, list[Any], where=where, text=True, error=CommandError,
                       expected="a JSON array of finite numbers such as [0.1, 0.2]" if numbers else 'a JSON array such as ["a", "b"]')
    raise CommandError(f"{where} is a {info.kind} field; set it with +data (protobuf bytes) or one of its fields (-field {where.split('.', 1)[-1]}.NAME)")


def frame_number(manager: ModuleManager) -> int:
    """The frame's number as ``FrameInfo`` says (a replayed log's recorded numbers), else as the
    manager counts."""
    blackboard = manager.blackboard
    return int(blackboard[FrameInfo].frame_number) if FrameInfo in blackboard else manager.frame


def frame_time_ns(manager: ModuleManager) -> int | None:
    """The frame's time on the program's clock (``FrameInfo``), or None without one."""
    blackboard = manager.blackboard
    return int(blackboard[FrameInfo].time_ns) if FrameInfo in blackboard else None


def representation_message(rep: Any, context: str, frame: int, time_ns: int | None = None) -> dict[str, Any]:
    """A representation as the JSON of ``representation:print -format json`` and of its web topic."""
    message = {"topic": type(rep).__name__, "context": context, "frame": frame, "value": json_value(rep)}
    if time_ns is not None:
        message["time_ns"] = time_ns
    return message


def jpeg_bytes(image: np.ndarray, quality: int = 80) -> bytes:
    """An RGB image as JPEG."""
    import cv2

    ok, data = cv2.imencode(".jpg", np.ascontiguousarray(image[:, :, ::-1]), [cv2.IMWRITE_JPEG_QUALITY, quality])
    if not ok:
        raise CommandError("the image could not be encoded as JPEG")
    return data.tobytes()
