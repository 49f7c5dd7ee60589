"""The logs wing: representations as protobuf (``serialization.py``), MCAP files written in the background
(``writer.py``) and read back, damaged and hostile ones included (``reader.py``), pieces of them
(``slice.py``), what a program records (``recording.py``) and the black box that keeps the last seconds
of everything (``blackbox.py``). The log file API is importable from here: ``from tafel.core.logs
import LogReader, LogWriter, read_log, write_slice``.
"""

from __future__ import annotations

import importlib
from typing import Any

#: module of each name this package hands out, loaded when first asked for
_PARTS = ("format", "writer", "reader", "slice")


def __getattr__(name: str) -> Any:
    for part in _PARTS:
        module = importlib.import_module(f"tafel.core.logs.{part}")
        if hasattr(module, name):
            value = getattr(module, name)
            globals()[name] = value
            return value
    raise AttributeError(f"module 'tafel.core.logs' has no attribute {name!r}")
