"""Debugging for module authors and the debug server.

Module classes declare their debug outputs (``DebugRequest``, ``Plot``, ``Stopwatch``, ``ModifyValue``,
``ModifyParameters``; drawings on a ``Canvas`` under a request); each context keeps its own state of them
(``debug.concepts.DebugState``). The debug server (``debug.server``) makes them, and the module graph,
representations and parameters, available over a telnet-friendly text protocol (``debug.protocol``).
The free functions ``request``, ``modify``, ``plot``, ``stopwatch`` and ``drawing`` are deprecated
(``debug.legacy``).
"""

from tafel.debug.concepts import Canvas, DebugDrawings, DebugPlots, DebugState
from tafel.debug.legacy import drawing, modify, plot, request, stopwatch
from tafel.debug.outputs import DebugRequest, ModifyParameters, ModifyValue, Plot, Stopwatch, declared_outputs

__all__ = ["Canvas", "DebugDrawings", "DebugPlots", "DebugRequest", "DebugState", "ModifyParameters", "ModifyValue", "Plot",
           "Stopwatch", "declared_outputs", "drawing", "modify", "plot", "request", "stopwatch"]
