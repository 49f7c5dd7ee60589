"""How wiring a run says the user asked for something wrong: ``tafel`` exits with status 2 and the message."""

from __future__ import annotations

from typing import NoReturn


class UsageError(Exception):
    """Wrong names or arguments: exit status 2 with a message saying what would have been right."""


def fail(message: str) -> NoReturn:
    raise UsageError(message)
