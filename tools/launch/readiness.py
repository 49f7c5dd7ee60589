"""Telling whoever started the program that it runs, so that a deploy or a service manager need not
guess from a timer: on a slow robot, or a busy machine, a broken release may take longer to fail than
any fixed wait.

The program counts as running once each of its contexts has run a frame. Then it writes the file
given with ``tafel run --ready-file`` and, under systemd (a ``Type=notify`` unit), sends ``READY=1``
to ``$NOTIFY_SOCKET`` (the sd_notify protocol: one datagram on a Unix socket, ``@`` for an
abstract name).
"""

from __future__ import annotations

import os
import socket
from collections.abc import Mapping
from pathlib import Path


class Readiness:
    """Reports the program's start once; ``check`` is called after frames with each context's count."""

    def __init__(self, ready_file: Path | None, notify_socket: str | None = None) -> None:
        self.ready_file = ready_file
        self.notify_socket = notify_socket if notify_socket is not None else os.environ.get("NOTIFY_SOCKET", "")
        self.reported = False

    @property
    def wanted(self) -> bool:
        return self.ready_file is not None or bool(self.notify_socket)

    def check(self, frames: Mapping[str, int]) -> None:
        """Report once every context in ``frames`` has run at least one frame."""
        if self.reported or not frames or min(frames.values()) < 1:
            return
        self.reported = True
        if self.ready_file is not None:
            temporary = self.ready_file.with_name(self.ready_file.name + ".part")
            temporary.write_text(f"{os.getpid()}\n")
            temporary.replace(self.ready_file)  # whoever waits for it never reads half a file
        if self.notify_socket:
            notify(self.notify_socket, "READY=1")

    def clear(self) -> None:
        """A stale file from an earlier run must not announce this one."""
        if self.ready_file is not None:
            self.ready_file.unlink(missing_ok=True)


def notify(address: str, message: str) -> None:
    """Send one sd_notify message; a socket that is gone only loses the message."""
    target = "\0" + address[1:] if address.startswith("@") else address
    try:
        with socket.socket(socket.AF_UNIX, socket.SOCK_DGRAM) as sender:
            sender.sendto(message.encode(), target)
    except OSError:
        pass
