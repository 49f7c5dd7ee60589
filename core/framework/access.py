"""Access control between modules and the blackboard.

A module sees a representation it requires or uses through a *read-only view*: reading fields is cheap,
nested dataclasses come back as views too, numpy arrays as non-writeable ``ReadOnlyArray`` views and
lists as read-only sequences, so a write at any depth raises ``ReadOnlyRepresentationError`` naming the
module and the representation. A module sees what it provides through a *writer view*, which forwards
everything to the real object. Both views note that they were touched, which is how the manager knows
who read and who wrote each representation in the last frame.
"""

from __future__ import annotations

import copy
import dataclasses
from collections.abc import Iterator, Sequence
from typing import Any

import numpy as np

from tafel.core.framework.errors import ReadOnlyRepresentationError, TafelError
from tafel.core.framework.representation import ArraySpec, fields_of


class ArrayFieldError(TafelError, ValueError):
    """A module wrote an array of the wrong shape or dtype into a field that declares both."""

    def __init__(self, owner: str, rep: str, field: str, spec: ArraySpec, value: np.ndarray) -> None:
        expected = "(" + ", ".join("any" if n is None else str(n) for n in spec.shape) + ("," if len(spec.shape) == 1 else "") + ")"
        who = f"module {owner}" if owner else "a module"
        super().__init__(f"{who} wrote {rep}.{field} as an array of shape {value.shape} and dtype {value.dtype}; "
                         f"the field declares shape {expected} and dtype {spec.dtype}")

_SCALAR_KINDS = frozenset({"bool", "int", "float", "str", "bytes", "enum"})


class AccessMark:
    """Set by a view when its module touches the representation; reset by the manager every frame."""

    __slots__ = ("touched",)

    def __init__(self) -> None:
        self.touched = False


class ReadOnlyArray(np.ndarray):
    """A non-writeable numpy view whose writes raise ``ReadOnlyRepresentationError``.

    Results of computations on it are plain arrays; slices of it stay read-only.
    """

    _tafel_owner: str = "?"
    _tafel_rep: str = "?"
    _tafel_path: str = ""

    def __array_finalize__(self, obj: Any) -> None:
        if obj is not None:
            self._tafel_owner = getattr(obj, "_tafel_owner", "?")
            self._tafel_rep = getattr(obj, "_tafel_rep", "?")
            self._tafel_path = getattr(obj, "_tafel_path", "")

    def _refuse(self) -> None:
        raise ReadOnlyRepresentationError(self._tafel_owner, self._tafel_rep, self._tafel_path + "[...]")

    def __setitem__(self, key: Any, value: Any) -> None:
        if not self.flags.writeable:
            self._refuse()
        super().__setitem__(key, value)

    def __array_ufunc__(self, ufunc: np.ufunc, method: str, *inputs: Any, **kwargs: Any) -> Any:
        out = kwargs.get("out")
        if out:
            for target in out:
                if isinstance(target, ReadOnlyArray) and not target.flags.writeable:
                    target._refuse()
            kwargs["out"] = tuple(t.view(np.ndarray) if isinstance(t, ReadOnlyArray) else t for t in out)
        plain = tuple(x.view(np.ndarray) if isinstance(x, ReadOnlyArray) else x for x in inputs)
        return getattr(ufunc, method)(*plain, **kwargs)

    def __reduce__(self) -> Any:  # pickling or deep-copying yields a plain, writeable array
        return np.asarray(self).copy().__reduce__()

    def __deepcopy__(self, memo: Any) -> np.ndarray:  # type: ignore[override]  # a copy is a plain array on purpose: writeable
        return np.array(self, copy=True).view(np.ndarray)


def _refusing_method(name: str) -> Any:
    def method(self: ReadOnlyArray, *args: Any, **kwargs: Any) -> Any:
        if not self.flags.writeable:
            self._refuse()
        return getattr(np.ndarray, name)(self, *args, **kwargs)

    method.__name__ = name
    return method


for _name in ("fill", "sort", "put", "partition", "resize", "setfield", "byteswap"):
    setattr(ReadOnlyArray, _name, _refusing_method(_name))


def read_only_array(array: np.ndarray, owner: str, rep: str, path: str) -> ReadOnlyArray:
    view = array.view(ReadOnlyArray)
    view.flags.writeable = False
    view._tafel_owner, view._tafel_rep, view._tafel_path = owner, rep, path
    return view


class ReadOnlySequence(Sequence):
    """A live, read-only window on a list field; its elements are protected like the fields."""

    __slots__ = ("_items", "_owner", "_rep", "_path", "_kind")

    def __init__(self, items: list, owner: str, rep: str, path: str, kind: str) -> None:
        self._items, self._owner, self._rep, self._path, self._kind = items, owner, rep, path, kind

    def __len__(self) -> int:
        return len(self._items)

    def __getitem__(self, index: Any) -> Any:
        if isinstance(index, slice):
            return [self._wrap(v, f"[{i}]") for i, v in zip(range(*index.indices(len(self._items))), self._items[index])]
        return self._wrap(self._items[index], f"[{index}]")

    def __iter__(self) -> Iterator[Any]:
        for i, v in enumerate(self._items):
            yield self._wrap(v, f"[{i}]")

    def _wrap(self, value: Any, suffix: str) -> Any:
        return protect(value, self._kind, self._owner, self._rep, self._path + suffix, None)

    def __setitem__(self, index: Any, value: Any) -> None:
        raise ReadOnlyRepresentationError(self._owner, self._rep, self._path + "[...]")

    def _refuse(self, *args: Any, **kwargs: Any) -> None:
        raise ReadOnlyRepresentationError(self._owner, self._rep, self._path)

    __delitem__ = append = extend = insert = pop = remove = clear = sort = reverse = __iadd__ = _refuse

    def __eq__(self, other: Any) -> bool:
        other_items = other._items if isinstance(other, ReadOnlySequence) else other
        return self._items == other_items

    def __repr__(self) -> str:
        return f"ReadOnlySequence({self._items!r})"

    def __deepcopy__(self, memo: Any) -> list:
        return copy.deepcopy(self._items, memo)

    def __reduce__(self) -> Any:  # a pickle copy is the plain list too (``private_copy``)
        return list, (self._items,)


def protect(value: Any, kind: str, owner: str, rep: str, path: str, mark: AccessMark | None) -> Any:
    """Wrap one field value for read-only access."""
    if kind in _SCALAR_KINDS:
        return value
    if kind == "ndarray" or isinstance(value, np.ndarray):
        return read_only_array(value, owner, rep, path)
    if kind == "list" or isinstance(value, list):
        element_kind = "nested" if value and dataclasses.is_dataclass(value[0]) else "any"
        return ReadOnlySequence(value, owner, rep, path, element_kind)
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        return read_view_class(type(value))(value, owner, rep, path, mark or AccessMark())
    return value


class ReadOnlyView:
    """Base of the generated read-only view classes; one subclass per dataclass type."""

    __slots__ = ("_t", "_owner", "_rep", "_path", "_mark", "_cache")
    _t: Any
    _owner: str
    _rep: str
    _path: str
    _mark: AccessMark
    _cache: dict[str, tuple[Any, Any]]

    def __init__(self, target: Any, owner: str, rep: str, path: str, mark: AccessMark) -> None:
        object.__setattr__(self, "_t", target)
        object.__setattr__(self, "_owner", owner)
        object.__setattr__(self, "_rep", rep)
        object.__setattr__(self, "_path", path)
        object.__setattr__(self, "_mark", mark)
        object.__setattr__(self, "_cache", {})

    def _protect(self, name: str, kind: str, value: Any) -> Any:
        view = protect(value, kind, self._owner, self._rep, f"{self._path}.{name}", self._mark)
        self._cache[name] = (value, view)
        return view

    def __setattr__(self, name: str, value: Any) -> None:
        raise ReadOnlyRepresentationError(self._owner, self._rep, f"{self._path}.{name}")

    def __delattr__(self, name: str) -> None:
        raise ReadOnlyRepresentationError(self._owner, self._rep, f"{self._path}.{name}")

    def __eq__(self, other: Any) -> bool:
        if isinstance(other, ReadOnlyView):
            other = other._t
        return self._t == other

    __hash__ = None  # type: ignore[assignment]

    def __repr__(self) -> str:
        return repr(self._t)

    def __copy__(self) -> Any:
        return copy.copy(self._t)

    def __deepcopy__(self, memo: Any) -> Any:
        """``copy.deepcopy(self.ball_percept)`` gives a private, writeable copy."""
        return copy.deepcopy(self._t, memo)

    def __reduce_ex__(self, protocol: Any) -> Any:  # a pickle copy is the plain value too (``private_copy``)
        return self._t.__reduce_ex__(protocol)


def _compile(source: str, name: str, globals_: dict[str, Any] | None = None) -> Any:
    """Compile a generated accessor; direct attribute access is three times faster than getattr()."""
    namespace: dict[str, Any] = dict(globals_ or {})
    exec(source, namespace)  # noqa: S102 - generated from validated field identifiers
    return namespace[name]


def _read_property(name: str, kind: str) -> property:
    if kind in _SCALAR_KINDS:
        return property(_compile(
            f"def get(self):\n    self._mark.touched = True\n    return self._t.{name}\n", "get"))
    return property(_compile(
        f"def get(self):\n"
        f"    self._mark.touched = True\n"
        f"    value = self._t.{name}\n"
        f"    cached = self._cache.get({name!r})\n"
        f"    if cached is not None and cached[0] is value:\n"
        f"        return cached[1]\n"
        f"    return self._protect({name!r}, {kind!r}, value)\n",
        "get",
    ))


def _behaviour(cls: type) -> dict[str, Any]:
    """Methods, properties and constants of a representation class, for its views.

    They run against the view, so a method of a required representation cannot write through it.
    """
    names: dict[str, Any] = {}
    for klass in reversed(cls.__mro__[:-1]):
        for name, value in vars(klass).items():
            if name.startswith("__") or name in _DATACLASS_INTERNALS:
                continue
            names[name] = value
    for info in fields_of(cls):
        names.pop(info.name, None)
    return names


_DATACLASS_INTERNALS = frozenset({"_FIELDS", "_PARAMS"})
_READ_VIEWS: dict[type, type] = {}


def read_view_class(cls: type) -> type:
    """The generated read-only view class of a dataclass type (cached)."""
    view_cls = _READ_VIEWS.get(cls)
    if view_cls is None:
        namespace: dict[str, Any] = {**_behaviour(cls), "__slots__": ()}
        for info in fields_of(cls):
            namespace[info.name] = _read_property(info.name, info.kind)
        view_cls = type(f"ReadOnly{cls.__name__}", (ReadOnlyView,), namespace)
        _READ_VIEWS[cls] = view_cls
    return view_cls


def read_view(target: Any, owner: str, mark: AccessMark) -> ReadOnlyView:
    """A read-only view of a representation for module ``owner``."""
    return read_view_class(type(target))(target, owner, type(target).__name__, "", mark)


class WriterView:
    """Base of the generated writer views: full access, forwarded to the representation.

    Every assignment is noted in ``undo`` (object, field, previous value), so that the manager can
    restore the previous values when the module fails in the middle of a frame. Nested dataclasses are
    reached through writer views too; in-place changes to arrays and lists are not noted.
    """

    __slots__ = ("_t", "_mark", "_undo", "_cache", "_owner")
    _t: Any
    _mark: AccessMark
    _undo: list[tuple[Any, str, Any]]
    _cache: dict[str, tuple[Any, Any]]
    _owner: str

    def __init__(self, target: Any, mark: AccessMark, undo: list, owner: str = "") -> None:
        object.__setattr__(self, "_t", target)
        object.__setattr__(self, "_mark", mark)
        object.__setattr__(self, "_undo", undo)
        object.__setattr__(self, "_cache", {})
        object.__setattr__(self, "_owner", owner)

    def _nested(self, name: str, value: Any) -> Any:
        view = writer_view(value, self._mark, self._undo, self._owner)
        self._cache[name] = (value, view)
        return view

    def __eq__(self, other: Any) -> bool:
        if isinstance(other, (WriterView, ReadOnlyView)):
            other = other._t
        return self._t == other

    __hash__ = None  # type: ignore[assignment]

    def __repr__(self) -> str:
        return repr(self._t)

    def __deepcopy__(self, memo: Any) -> Any:
        return copy.deepcopy(self._t, memo)

    def __reduce_ex__(self, protocol: Any) -> Any:  # a pickle copy is the plain value too (``private_copy``)
        return self._t.__reduce_ex__(protocol)


def undo_writes(undo: list) -> None:
    """Restore the values noted by writer views, newest first, and empty the list."""
    for target, name, previous in reversed(undo):
        target.__dict__[name] = previous
    undo.clear()


def check_array(value: Any, spec: ArraySpec, owner: str, rep: str, name: str) -> Any:
    """``value`` as an array of the declared dtype and shape, or ``ArrayFieldError`` saying what is wrong.

    Lists and numbers convert when they fit the dtype without loss (``[1, 2, 3]`` for a float array);
    a wrong shape, or a dtype that would lose information, is refused.
    """
    array = value if isinstance(value, np.ndarray) else np.asarray(value)
    if array.dtype != spec.dtype:
        if not np.can_cast(array.dtype, spec.dtype, casting="same_kind") or (
                array.dtype.kind == "f" and spec.dtype.kind in "iub"):
            raise ArrayFieldError(owner, rep, name, spec, array)
        array = array.astype(spec.dtype)
    if len(array.shape) != len(spec.shape) or any(n is not None and n != m for n, m in zip(spec.shape, array.shape)):
        raise ArrayFieldError(owner, rep, name, spec, array)
    return array


def _write_property(name: str, kind: str, spec: ArraySpec | None = None, rep: str = "") -> property:
    check = (f"    value = _check(value, _spec, self._owner, {rep!r}, {name!r})\n" if kind == "ndarray" and spec is not None and spec.declared else "")
    setter = _compile(
        f"def set_(self, value):\n"
        f"    target = self._t\n"
        f"    self._mark.touched = True\n"
        f"{check}"
        f"    self._undo.append((target, {name!r}, target.{name}))\n"
        f"    target.{name} = value\n",
        "set_",
        {"_check": check_array, "_spec": spec},
    )
    if kind != "nested":
        return property(_compile(
            f"def get(self):\n    self._mark.touched = True\n    return self._t.{name}\n", "get"), setter)
    getter = _compile(
        f"def get(self):\n"
        f"    self._mark.touched = True\n"
        f"    value = self._t.{name}\n"
        f"    cached = self._cache.get({name!r})\n"
        f"    if cached is not None and cached[0] is value:\n"
        f"        return cached[1]\n"
        f"    return self._nested({name!r}, value)\n",
        "get",
    )
    return property(getter, setter)


_WRITE_VIEWS: dict[type, type] = {}


def writer_view(target: Any, mark: AccessMark, undo: list, owner: str = "") -> WriterView:
    """A writer view of a representation (or nested dataclass) for the module ``owner`` that provides it.

    Array fields with a declared dtype and shape (``core.array``) are checked on every assignment.
    """
    cls = type(target)
    view_cls = _WRITE_VIEWS.get(cls)
    if view_cls is None:
        namespace: dict[str, Any] = {**_behaviour(cls), "__slots__": ()}
        for info in fields_of(cls):
            namespace[info.name] = _write_property(info.name, info.kind, info.array, cls.__name__)
        view_cls = type(f"Writable{cls.__name__}", (WriterView,), namespace)
        _WRITE_VIEWS[cls] = view_cls
    return view_cls(target, mark, undo, owner)

