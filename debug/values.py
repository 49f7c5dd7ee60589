"""Values as clients see and type them: representations printed and as JSON, and text parsed into a
field's type with the same checks every other way in has (ranges, finiteness, shapes)."""

from __future__ import annotations

import dataclasses
import enum
import json
from typing import Any

import numpy as np

from tafel.core.framework.errors import TafelError
from tafel.core.framework.manager import ModuleManager
from tafel.core.framework.representation import FieldInfo, fields_of
from tafel.core.framework.validation import MAX_MAGNITUDE, check_number


class CommandError(TafelError):
    """A command that cannot be carried out; the message becomes ``error: ...``."""


def parse_bool(text: str, what: str) -> bool:
    lowered = text.lower()
    if lowered in ("on", "true", "1", "yes"):
        return True
    if lowered in ("off", "false", "0", "no"):
        return False
    raise CommandError(f"{what} takes on/off or true/false, got {text!r}")


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
    """``text`` converted to the type of ``current`` (for modify values and single fields)."""
    try:
        if isinstance(current, bool):
            return parse_bool(text, what)
        if isinstance(current, int):
            return int(text)
        if isinstance(current, float):
            return float(text)
        if isinstance(current, enum.Enum):
            return type(current)[text]
        if isinstance(current, str) or current is None:
            return text
        if isinstance(current, (list, np.ndarray)):
            values = json.loads(text)
            return np.asarray(values, dtype=current.dtype) if isinstance(current, np.ndarray) else list(values)
    except (ValueError, KeyError, json.JSONDecodeError):
        pass
    raise CommandError(f"{what} holds {type(current).__name__}; {text!r} is not one")


def parse_field_text(info: FieldInfo, text: str, where: str) -> Any:
    """The text of ``-value`` read as the field's kind (numbers, on/off, enum names, JSON arrays); checked later."""
    try:
        if info.kind == "bool":
            return parse_bool(text, where)
        if info.kind == "int":
            return int(text)
        if info.kind == "float":
            return float(text)
        if info.kind == "enum":
            return info.type[text]
        if info.kind == "str":
            return text
        if info.kind in ("ndarray", "list"):
            values = json.loads(text)
            if info.kind == "list" and info.element is not None and info.element.kind == "nested":
                raise CommandError(f"{where} holds a list of {info.element.type.__name__}; set it with +data (protobuf bytes)")
            return values
    except KeyError:
        raise CommandError(f"{where} takes one of {', '.join(m.name for m in info.type)}, got {text!r}") from None
    except (ValueError, json.JSONDecodeError):
        raise CommandError(f"{where} takes {'a JSON array such as [0.1, 0.2]' if info.kind in ('ndarray', 'list') else info.kind}, "
                           f"got {text!r}") from None
    raise CommandError(f"{where} is a {info.kind} field; set it with +data (protobuf bytes) or one of its fields (-field {where.split('.', 1)[-1]}.NAME)")


def _check_like(current: Any, value: Any, what: str) -> Any:
    """A pinned modify value must be of the published value's kind: finite numbers, the same array shape."""
    if isinstance(current, float):
        return check_number(value, what)
    if isinstance(current, int) and not isinstance(current, bool):
        return check_number(value, what, kind="int")  # 64 bits: a module may loop over it
    if isinstance(current, np.ndarray):
        if value.shape != current.shape:
            raise CommandError(f"{what} is an array of shape {current.shape}; got shape {value.shape}")
        if value.dtype.kind == "f" and not np.isfinite(value).all():
            raise CommandError(f"{what} takes finite numbers; got {value.tolist()}")
        if value.dtype.kind == "f" and value.size and np.abs(value).max() > MAX_MAGNITUDE:
            raise CommandError(f"{what} takes numbers of at most {MAX_MAGNITUDE:g} in size; got {np.abs(value).max():g}")
    if isinstance(current, list):
        for element in value:
            if isinstance(element, (int, float)) and not isinstance(element, bool):
                check_number(element, what, kind="int" if isinstance(element, int) else "float")
    return value


def frame_number(manager: ModuleManager) -> int:
    """The frame's number as the platform counts it (``FrameInfo``: a replayed log's recorded numbers),
    else as the manager does."""
    return int(getattr(manager.blackboard.find("FrameInfo"), "frame_number", manager.frame))


def frame_time_ns(manager: ModuleManager) -> int | None:
    """The frame's time on the program's clock (``FrameInfo``), or None without one."""
    info = manager.blackboard.find("FrameInfo")  # by name: debug knows no representation
    return None if info is None else int(info.time_ns)


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
