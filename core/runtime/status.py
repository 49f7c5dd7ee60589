"""Representations the runtime itself provides."""

from __future__ import annotations

from tafel.core.framework.representation import representation


@representation
class CognitionStatus:
    """Whether cognition is running, as seen from motion.

    ``alive`` turns False when cognition has produced no frame for the stall timeout (1 s by default)
    or its process has died; motion modules fall back to a safe motion then. ``frame_number`` is the
    newest cognition frame motion has received, ``age`` the time since it was published (s).
    """

    alive: bool = True
    frame_number: int = 0
    age: float = 0.0
