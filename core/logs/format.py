"""What writer and reader of Tafel's MCAP logs share: the profile, the magic bytes, the chunk span, the errors."""

from __future__ import annotations

import logging

from tafel.core.framework.errors import TafelError

PROFILE = "tafel"
MAGIC = b"\x89MCAP0\r\n"
#: ns of log time one chunk holds at the most, so a cut-off file loses at most this much
CHUNK_SPAN_NS = 1_000_000_000
log = logging.getLogger("tafel.log")


class LogError(TafelError, RuntimeError):
    """A log file that cannot be written, or read (with the file and the position)."""


class LogExistsError(LogError):
    """A log that must not replace a file already there (a client's ``log:start``) found one."""


#: topics of channels that are not representations (Foxglove's) start with this
EXTRA_TOPIC_PREFIX = "/"


