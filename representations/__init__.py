"""Representations: the data that modules exchange, grouped by area.

Coordinate convention (the only one in Tafel):
- Robot frame: origin on the ground between the feet, x forward, y left, z up (right-handed).
- Field frame: origin at the centre spot, x towards the opponent goal, y left.
- Lengths in millimetres (mm), angles in radians (rad), time in seconds (s) unless a field name says
  otherwise (``time_ns``). Image coordinates in pixels (px), origin at the top-left corner, x right,
  y down.

Every shipped representation (and the enums and helper classes its fields use) is importable from
here as well as from its file: ``from tafel.representations import BallModel, BallPercept, FrameInfo``.
The names resolve on first use, which imports the representation files (they are small); importing
the package alone imports none of them.
"""

from __future__ import annotations

from typing import Any

#: name -> the file that defines it, filled on the first name asked for
_INDEX: dict[str, str] = {}


def load_all() -> None:
    """Import every representation file, so that all of them are registered by name (logs need that)."""
    import importlib
    import pkgutil

    for info in pkgutil.walk_packages(__path__, prefix=__name__ + "."):
        importlib.import_module(info.name)


def _files() -> list[str]:
    """The short names of the representation files (``perception``, ``field``, ...), without importing them."""
    import pkgutil

    return [info.name for info in pkgutil.iter_modules(__path__)]


def _index() -> dict[str, str]:
    """Every public class defined in a representation file (representations, their enums), by name."""
    if _INDEX:
        return _INDEX
    import importlib

    index: dict[str, str] = {}
    complete = True
    for short in _files():
        module = importlib.import_module(f"{__name__}.{short}")
        # a file still being imported (it asked for a name from here) is indexed again next time
        complete = complete and not getattr(module.__spec__, "_initializing", False)
        exported = set(getattr(module, "__all__", ()))  # what a file re-exports (FrameInfo, defined in core)
        for name, value in vars(module).items():
            if isinstance(value, type) and (value.__module__ == module.__name__ or name in exported) and not name.startswith("_"):
                index.setdefault(name, short)
    if complete:
        _INDEX.update(index)
    return index


def __getattr__(name: str) -> Any:
    """``tafel.representations.BallModel`` and ``from tafel.representations import BallModel``."""
    import importlib

    if name.startswith("_"):
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    if name in _files():  # a file of this package: ``from tafel.representations import field``
        return importlib.import_module(f"{__name__}.{name}")
    index = _index()
    if name in index:
        return getattr(importlib.import_module(f"{__name__}.{index[name]}"), name)
    from tafel.core.framework.naming import did_you_mean

    raise AttributeError(f"tafel.representations has no representation {name!r}; {did_you_mean(name, index)}")


def __dir__() -> list[str]:
    return sorted({*globals(), *_index()})
