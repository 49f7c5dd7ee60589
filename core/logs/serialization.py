"""Automatic protobuf serialization of representations: no .proto files, no protoc, no hand-written code.

Each representation class gets a protobuf message derived from its field descriptions at run time:

- ``bool``, ``int`` (sint64), ``float`` (double), ``str``, ``bytes``: proto3 ``optional`` scalars, so a
  field missing from older data takes the class's default rather than zero;
- ``Enum``: the member's name as a string (readable in Foxglove, stable when members are reordered);
- nested dataclasses: nested messages; ``list[T]``: repeated fields;
- ``numpy.ndarray``: a nested ``NDArray`` message with dtype, shape and the raw bytes (images stay
  bytes, never repeated scalars).

Field numbers are derived from field names (a stable hash), so adding, removing and reordering fields
keeps old data readable, as protobuf's rules require. A field whose type changed is reported by name
(``check_compatible``) instead of being silently misread.

Encoders and decoders are generated per class: they make the same assignments a hand-written
serializer would, which keeps automatic serialization close to the cost of hand-built messages.
"""

from __future__ import annotations

import dataclasses
import zlib
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np
from google.protobuf import descriptor_pb2, descriptor_pool, message_factory
from google.protobuf.message import Message
from google.protobuf.unknown_fields import UnknownFieldSet

from tafel.core.framework.errors import TafelError
from tafel.core.framework.representation import FieldInfo, fields_of

PACKAGE = "tafel"
MAX_FIELD_NUMBER = 536_870_911
RESERVED = range(19000, 20000)

FDP = descriptor_pb2.FieldDescriptorProto
_SCALAR_TYPES = {
    "bool": FDP.TYPE_BOOL,
    "int": FDP.TYPE_SINT64,
    "float": FDP.TYPE_DOUBLE,
    "str": FDP.TYPE_STRING,
    "bytes": FDP.TYPE_BYTES,
    "enum": FDP.TYPE_STRING,
}
_TYPE_NAMES = {value: name.removeprefix("TYPE_").lower() for name, value in FDP.Type.items()}


class SerializationError(TafelError, ValueError):
    """A value cannot be serialized, data cannot be decoded, or a schema does not fit the class."""


def field_number(name: str) -> int:
    """Stable protobuf field number of a field name (1 .. 2^29-1, skipping protobuf's reserved range)."""
    number = zlib.crc32(name.encode()) % (MAX_FIELD_NUMBER - len(RESERVED)) + 1
    return number + len(RESERVED) if number >= RESERVED.start else number


@dataclass
class MessageCodec:
    """Everything generated for one representation class."""

    cls: type
    full_name: str
    file: descriptor_pb2.FileDescriptorProto
    message_class: type[Message]
    encode: Callable[[Any], bytes]
    decode: Callable[[bytes], Any]
    fill: Callable[[Any, Any], None]
    read: Callable[[Any], Any]


_POOL = descriptor_pool.DescriptorPool()
_CODECS: dict[type, MessageCodec] = {}


def codec(cls: type) -> MessageCodec:
    """The (cached) codec of a representation class."""
    found = _CODECS.get(cls)
    if found is None:
        found = _CODECS[cls] = _build(cls)
    return found


_ENCODERS: dict[type, Callable[[Any], bytes]] = {}


def serialize(rep: Any) -> bytes:
    """Protobuf bytes of a representation instance."""
    cls = type(rep)
    encode = _ENCODERS.get(cls)
    if encode is None:
        encode = _ENCODERS[cls] = codec(cls).encode
    try:
        return encode(rep)
    except (TypeError, ValueError, AttributeError) as exc:
        raise SerializationError(_explain(cls, rep, exc)) from None


def deserialize(cls: type, data: bytes, *, schema: descriptor_pb2.FileDescriptorProto | None = None) -> Any:
    """A representation instance from protobuf bytes.

    ``schema`` is the schema the data was written with (a log's); when given, it is checked against
    the class first, so that a field whose type changed is reported by name.
    """
    found = codec(cls)
    if schema is not None:
        check_compatible(cls, schema)
    try:
        message = found.message_class.FromString(data)
    except Exception as exc:  # noqa: BLE001 - protobuf raises its own DecodeError
        raise SerializationError(f"cannot decode {cls.__name__} from {len(data)} bytes: {exc}") from None
    _check_unknown(found, message)
    try:
        return found.read(message)
    except (KeyError, ValueError, TypeError) as exc:
        raise SerializationError(f"cannot decode {cls.__name__}: {exc}") from None


def schema_of(cls: type) -> descriptor_pb2.FileDescriptorProto:
    """The protobuf schema of a representation class, as a FileDescriptorProto (a copy)."""
    result = descriptor_pb2.FileDescriptorProto()
    result.CopyFrom(codec(cls).file)
    return result


def message_name(cls: type) -> str:
    """Full protobuf message name of a representation class (``tafel.BallModel``)."""
    return codec(cls).full_name


def file_descriptor_set(cls: type) -> bytes:
    """Serialized FileDescriptorSet holding the schema: what MCAP and Foxglove expect for protobuf."""
    fds = descriptor_pb2.FileDescriptorSet()
    fds.file.append(codec(cls).file)
    return fds.SerializeToString()


def check_compatible(cls: type, written: descriptor_pb2.FileDescriptorProto) -> None:
    """Raise ``SerializationError`` naming the first field whose type differs between schemas."""
    current = codec(cls).file
    written_messages = _messages_by_path(written)
    for path, message in _messages_by_path(current).items():
        old = written_messages.get(path)
        if old is None:
            continue
        old_fields = {f.name: f for f in old.field}
        for field in message.field:
            before = old_fields.get(field.name)
            if before is None:
                continue
            if (before.type, before.label, before.type_name.rsplit(".", 1)[-1]) != (
                field.type, field.label, field.type_name.rsplit(".", 1)[-1]
            ):
                where = ".".join([cls.__name__, *path[1:], field.name])  # path[0] is the top message
                raise SerializationError(
                    f"{where} was written as {_describe_field(before)} but is {_describe_field(field)} now; "
                    "this is not a compatible change (rename the field to start afresh, or convert the log)"
                )


def _describe_field(field: descriptor_pb2.FieldDescriptorProto) -> str:
    kind = field.type_name.rsplit(".", 1)[-1] if field.type == FDP.TYPE_MESSAGE else _TYPE_NAMES[field.type]
    return f"repeated {kind}" if field.label == FDP.LABEL_REPEATED else kind


def _messages_by_path(file: descriptor_pb2.FileDescriptorProto) -> dict[tuple[str, ...], Any]:
    result: dict[tuple[str, ...], Any] = {}

    def walk(message: Any, path: tuple[str, ...]) -> None:
        result[path] = message
        for nested in message.nested_type:
            walk(nested, (*path, nested.name))

    for message in file.message_type[:1]:  # the representation itself, whatever it was called then
        walk(message, ("",))
    return result


def _check_unknown(found: MessageCodec, message: Any) -> None:
    """Data whose field numbers match ours with another wire type means a field changed its type."""
    unknown = UnknownFieldSet(message)
    if len(unknown) == 0:
        return
    numbers = {f.number: f.name for f in found.file.message_type[0].field}
    for item in (unknown[i] for i in range(len(unknown))):  # the stubs know indexing, not iteration
        if item.field_number in numbers:
            raise SerializationError(
                f"{found.cls.__name__}.{numbers[item.field_number]}: the data holds this field with another "
                "type than the class declares (an incompatible change); decode it with the schema it was "
                "written with to find out more"
            )


# ------------------------------------------------------------------------------------- generation
class _Builder:
    """Builds the descriptor and the generated code of one top-level representation."""

    def __init__(self, cls: type) -> None:
        self.cls = cls
        self.full_name = f"{PACKAGE}.{cls.__name__}"
        self.file = descriptor_pb2.FileDescriptorProto(name=f"{PACKAGE}/{cls.__name__}.proto", package=PACKAGE, syntax="proto3")
        self.top = self.file.message_type.add(name=cls.__name__)
        self.nested_names: dict[type, str] = {}
        self.uses_arrays = False
        self.namespace: dict[str, Any] = {"np": np, "_array": _read_array}
        self.order: list[type] = []

    def message_name_of(self, nested: type) -> str:
        if nested not in self.nested_names:
            base = nested.__name__
            taken = set(self.nested_names.values()) | {"NDArray", self.cls.__name__}
            name = base
            while name in taken:
                name += "_"
            self.nested_names[nested] = name
            self.describe(self.top.nested_type.add(name=name), nested)
        return f".{self.full_name}.{self.nested_names[nested]}"

    def describe(self, message: Any, cls: type) -> None:
        numbers: dict[int, str] = {}
        for info in fields_of(cls):
            number = field_number(info.name)
            if number in numbers:
                raise SerializationError(
                    f"{cls.__name__}: fields {numbers[number]!r} and {info.name!r} hash to the same protobuf "
                    "field number; rename one of them"
                )
            numbers[number] = info.name
            field = message.field.add(name=info.name, number=number)
            element = info.element if info.kind == "list" else info
            assert element is not None
            field.label = FDP.LABEL_REPEATED if info.kind == "list" else FDP.LABEL_OPTIONAL
            if element.kind in _SCALAR_TYPES:
                field.type = _SCALAR_TYPES[element.kind]
                if info.kind != "list":  # proto3 optional: a synthetic oneof gives presence
                    field.proto3_optional = True
                    field.oneof_index = len(message.oneof_decl)
                    message.oneof_decl.add(name=f"_{info.name}")
            elif element.kind == "ndarray":
                self.uses_arrays = True
                field.type = FDP.TYPE_MESSAGE
                field.type_name = f".{self.full_name}.NDArray"
            else:  # nested dataclass
                field.type = FDP.TYPE_MESSAGE
                field.type_name = self.message_name_of(element.type)
        self.order.append(cls)

    def finish(self) -> None:
        if self.uses_arrays:
            array = self.top.nested_type.add(name="NDArray")
            array.field.add(name="dtype", number=1, type=FDP.TYPE_STRING, label=FDP.LABEL_OPTIONAL)
            array.field.add(name="shape", number=2, type=FDP.TYPE_INT64, label=FDP.LABEL_REPEATED)
            array.field.add(name="data", number=3, type=FDP.TYPE_BYTES, label=FDP.LABEL_OPTIONAL)

    # code generation: one fill_N(message, obj) and read_N(message) per dataclass type
    def fill_lines(self, info: FieldInfo, ids: dict[type, int]) -> list[str]:
        n = info.name
        if info.kind in ("bool", "int", "float", "str", "bytes"):
            return [f"    m.{n} = obj.{n}"]
        if info.kind == "enum":
            return [f"    m.{n} = obj.{n}.name"]
        if info.kind == "ndarray":
            return [f"    a = obj.{n}", f"    t = m.{n}", *_ARRAY_LINES]
        if info.kind == "nested":
            return [f"    fill_{ids[info.type]}(m.{n}, obj.{n})"]
        element = info.element
        assert element is not None
        if element.kind in ("bool", "int", "float", "str", "bytes"):
            return [f"    m.{n}.extend(obj.{n})"]
        if element.kind == "enum":
            return [f"    m.{n}.extend([e.name for e in obj.{n}])"]
        if element.kind == "ndarray":
            return [f"    for a in obj.{n}:", f"        t = m.{n}.add()", *("    " + line for line in _ARRAY_LINES)]
        return [f"    for e in obj.{n}:", f"        fill_{ids[element.type]}(m.{n}.add(), e)"]

    def read_expression(self, info: FieldInfo, ids: dict[type, int], default: str, owner: int) -> str:
        n = info.name
        i = ids.get(info.type) if info.kind == "nested" else None
        present = f"m.HasField({n!r})"
        if info.kind in ("bool", "int", "float", "str", "bytes"):
            return f"(m.{n} if {present} else {default}())"
        if info.kind == "enum":
            return f"(Enum_{owner}_{n}[m.{n}] if {present} else {default}())"
        if info.kind == "ndarray":
            return f"(_array(m.{n}) if {present} else {default}())"
        if info.kind == "nested":
            return f"(read_{i}(m.{n}) if {present} else {default}())"
        element = info.element
        assert element is not None
        if element.kind in ("bool", "int", "float", "str", "bytes"):
            return f"list(m.{n})"
        if element.kind == "enum":
            return f"[Enum_{owner}_{n}[e] for e in m.{n}]"
        if element.kind == "ndarray":
            return f"[_array(e) for e in m.{n}]"
        return f"[read_{ids[element.type]}(e) for e in m.{n}]"


#: generated code that fills NDArray message ``t`` from array ``a``
_ARRAY_LINES = ("    t.dtype = a.dtype.str", "    t.shape.extend(a.shape)", "    t.data = a.tobytes()")


def _read_array(message: Any) -> np.ndarray:
    dtype = np.dtype(message.dtype)
    return np.frombuffer(message.data, dtype=dtype).reshape(tuple(message.shape)).copy()


def _has_dict(cls: type) -> bool:
    return "__slots__" not in cls.__dict__


def _default_of(cls: type, name: str) -> Callable[[], Any]:
    for f in dataclasses.fields(cls):
        if f.name == name:
            if f.default_factory is not dataclasses.MISSING:
                return f.default_factory
            value = f.default
            return lambda: value
    raise SerializationError(f"{cls.__name__} has no field {name}")


def _build(cls: type) -> MessageCodec:
    builder = _Builder(cls)
    builder.describe(builder.top, cls)
    builder.finish()
    ids = {c: i for i, c in enumerate(builder.order)}
    try:
        _POOL.Add(builder.file)
    except TypeError as exc:
        raise SerializationError(f"cannot register the schema of {cls.__name__}: {exc}") from None
    message_class = message_factory.GetMessageClass(_POOL.FindMessageTypeByName(builder.full_name))
    top = ids[cls]
    builder.namespace[f"Message{top}"] = message_class
    _generate(builder, ids)
    fill, read, encode = builder.namespace[f"fill_{top}"], builder.namespace[f"read_{top}"], builder.namespace[f"encode_{top}"]

    def decode(data: bytes) -> Any:
        return read(message_class.FromString(data))

    return MessageCodec(cls, builder.full_name, builder.file, message_class, encode, decode, fill, read)


def _generate(builder: _Builder, ids: dict[type, int]) -> None:
    """Generate and compile the fill/read functions (enum placeholders resolved per class)."""
    source: list[str] = []
    for cls, i in ids.items():
        builder.namespace[f"Cls{i}"] = cls
        fill = [f"def fill_{i}(m, obj):"]
        values = []
        for info in fields_of(cls):
            fill += builder.fill_lines(info, ids)
            default = f"default_{i}_{info.name}"
            builder.namespace[default] = _default_of(cls, info.name)
            expression = builder.read_expression(info, ids, default, i)
            values.append(f"{info.name!r}: {expression}")
            element = info.element if info.kind == "list" else info
            if element is not None and element.kind == "enum":
                builder.namespace[f"Enum_{i}_{info.name}"] = element.type
        fill.append("    return m")
        encode = [f"def encode_{i}(obj):", f"    m = Message{i}()", *fill[1:-1], "    return m.SerializeToString()"]
        body = "{" + ", ".join(values) + "}"
        if _has_dict(cls):
            read = [f"def read_{i}(m):", f"    obj = Cls{i}.__new__(Cls{i})", f"    obj.__dict__.update({body})", "    return obj"]
        else:
            read = [f"def read_{i}(m):", f"    return Cls{i}(**{body})"]
        source += fill + [""] + read + [""] + (encode + [""] if cls is builder.cls else [])
    exec(compile("\n".join(source), f"<tafel serializer {builder.cls.__name__}>", "exec"), builder.namespace)  # noqa: S102


#: what a scalar field of each kind may hold
_PYTHON_TYPES: dict[str, type | tuple[type, ...]] = {"bool": bool, "int": int, "float": (int, float), "str": str, "bytes": bytes}


def _explain(cls: type, rep: Any, exc: Exception) -> str:
    """Find the field that could not be serialized, for an error message that names it."""
    for info in fields_of(cls):
        value = getattr(rep, info.name, None)
        if info.kind == "int" and isinstance(value, int) and not -(2**63) <= value < 2**63:
            return f"{cls.__name__}.{info.name} = {value} is outside the 64-bit range that can be stored"
        expected = _PYTHON_TYPES.get(info.kind)
        if expected is not None and not isinstance(value, expected) and not isinstance(value, np.generic):
            return f"{cls.__name__}.{info.name} holds {value!r} ({type(value).__name__}), but is declared {info.kind}"
        if info.kind == "ndarray" and not isinstance(value, np.ndarray):
            return f"{cls.__name__}.{info.name} holds {type(value).__name__}, but is declared numpy.ndarray"
        if info.kind == "ndarray" and isinstance(value, np.ndarray) and value.dtype.hasobject:
            return f"{cls.__name__}.{info.name} is an array of Python objects, which cannot be serialized"
    return f"cannot serialize {cls.__name__}: {exc}"
