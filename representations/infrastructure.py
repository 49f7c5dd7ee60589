"""Representations every context has: the frame clock (``FrameInfo``) and, in motion, ``CognitionStatus``.

Both are written by the runtime, so they are defined in core and re-exported here unchanged.
"""

from __future__ import annotations

# The runtime writes the frame clock every frame; defined in core for that reason.
from tafel.core.framework.frame_info import FrameInfo

# Provided by the runtime to motion; defined in core because the runtime fills it.
from tafel.core.runtime.status import CognitionStatus

__all__ = ["CognitionStatus", "FrameInfo"]
