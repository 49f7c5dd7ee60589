"""Debugging for module authors and the debug server.

Module code uses ``request``, ``modify``, ``stopwatch``, ``plot`` and ``drawing``; the debug server
(``debug.server``) makes them, and the module graph, representations and parameters, available over
a telnet-friendly text protocol (``debug.protocol``).
"""

from tafel.debug.concepts import DebugDrawings, DebugPlots, drawing, modify, plot, request, stopwatch

__all__ = ["DebugDrawings", "DebugPlots", "drawing", "modify", "plot", "request", "stopwatch"]
