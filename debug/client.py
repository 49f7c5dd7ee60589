"""A client of the debug protocol: one connection, pipelined commands, answers split on NUL."""

from __future__ import annotations

import socket
from collections.abc import Sequence


class DebugClient:
    """``with DebugClient(port=5401) as client: print(client.ask("modules:list"))``"""

    def __init__(self, host: str = "127.0.0.1", port: int = 5401, timeout: float = 10.0) -> None:
        self.socket = socket.create_connection((host, port), timeout=timeout)
        self.buffer = b""

    def __enter__(self) -> DebugClient:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def close(self) -> None:
        self.socket.close()

    def send(self, line: str | bytes) -> None:
        data = line.encode("utf-8") if isinstance(line, str) else line
        self.socket.sendall(data if data.endswith(b"\n") else data + b"\n")

    def receive(self) -> str:
        """The next answer (without its trailing newline)."""
        while b"\0" not in self.buffer:
            chunk = self.socket.recv(1 << 16)
            if not chunk:
                raise ConnectionError("the debug server closed the connection")
            self.buffer += chunk
        answer, _, self.buffer = self.buffer.partition(b"\0")
        return answer.decode("utf-8").removesuffix("\n")

    def ask(self, line: str) -> str:
        self.send(line)
        return self.receive()

    def ask_many(self, lines: Sequence[str]) -> list[str]:
        """Send all commands at once (pipelined), then read all answers in order."""
        self.socket.sendall("".join(line + "\n" for line in lines).encode("utf-8"))
        return [self.receive() for _ in lines]
