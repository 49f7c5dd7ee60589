"""The door in front of the live Foxglove server (``foxglove_live``): the SDK's server listens on a loopback
port of its own, and only the connections the ``Gate`` lets through reach it: ``Host`` and ``Origin`` by
the web view's rules, the token when there is one, and both names of the protocol
(``foxglove.sdk.v1`` and the older ``foxglove.websocket.v1``, which the gate translates).
"""

from __future__ import annotations

import asyncio
import hmac
import http.client
import io
import logging
import re
import threading
from collections.abc import Iterable
from typing import Any
from urllib.parse import parse_qs, urlsplit

from tafel.debug.websocket import host_allowed, origin_allowed

log = logging.getLogger("tafel.foxglove")


#: what the SDK logs for each message it could not send to, or read from, one of its clients
PER_CLIENT_ERRORS = ("Error sending message to client", "Error receiving from client")


class PerClientErrors(logging.Filter):
    """Drops the SDK's errors about single connections: its clients are the gate's connections on loopback, and
    a client that goes away cost one line per queued message (hundreds a second). The gate says it once,
    naming the real client."""

    def filter(self, record: logging.LogRecord) -> bool:
        return not str(record.msg).startswith(PER_CLIENT_ERRORS)


def quiet_per_client_errors() -> None:
    logger = logging.getLogger("foxglove.websocket.connected_client.poller")
    if not any(isinstance(f, PerClientErrors) for f in logger.filters):
        logger.addFilter(PerClientErrors())


class Gate:
    """The door in front of the SDK's server, which listens on loopback inside: a connection is let through
    (its bytes passed on unchanged) only when

    - its ``Host`` is an address, ``localhost`` or the name listened on (any name with a token), and its
      ``Origin`` is none (desktop apps, scripts), the same as ``Host`` or one of ``origins``: the web view's
      rules, so that no web page and no DNS-rebinding name reaches the program;
    - with a token: ``?token=T`` in its URL or an ``Authorization: Bearer T`` header;
    - it asks for the protocol by either name: ``foxglove.sdk.v1`` or the older ``foxglove.websocket.v1``
      (older Lichtblick, third-party clients), which the SDK does not know and the gate translates.

    Every refusal is an HTTP answer that says what was wrong, and a warning in the log."""

    NEW_NAME, OLD_NAME = "foxglove.sdk.v1", "foxglove.websocket.v1"
    HEAD_LIMIT = 16 * 1024  # bytes of a handshake's head
    HEAD_TIMEOUT_S = 10.0
    DRAIN_TIMEOUT_S = 5.0  # after a client went away, how long the SDK's side is read before it is cut
    CHUNK = 1 << 16

    def __init__(self, host: str, port: int, inside_port: int, *, token: str | None = None, origins: Iterable[str] = ()) -> None:
        self.host, self.port, self.token, self.inside_port = host, port, token, inside_port
        self.origins = tuple(origins)
        self.loop: asyncio.AbstractEventLoop | None = None
        self.stopping: asyncio.Event | None = None
        self.ready = threading.Event()
        self.error: BaseException | None = None
        self.thread = threading.Thread(target=self._run, name="tafel-foxglove-gate", daemon=True)
        self.refused = 0

    def start(self) -> int:
        self.thread.start()
        self.ready.wait(10)
        if self.error is not None:
            raise OSError(f"cannot listen on {self.host}:{self.port}: {self.error}")
        return self.port

    def stop(self) -> None:
        if self.loop is not None and self.loop.is_running() and self.stopping is not None:
            self.loop.call_soon_threadsafe(self.stopping.set)
            self.thread.join(timeout=5)

    # ------------------------------------------------------------------------------- the rules
    def token_given(self, path: str, authorization: str | None) -> bool:
        assert self.token is not None
        given = parse_qs(urlsplit(path).query).get("token", [""])[0]
        if not given and authorization and authorization.startswith("Bearer "):
            given = authorization[len("Bearer "):]
        return bool(given) and hmac.compare_digest(given.encode(), self.token.encode())

    def refusal(self, path: str, headers: http.client.HTTPMessage) -> tuple[int, str] | None:
        """Why a handshake is refused, as (HTTP status, text saying what would be right); None: let it in."""
        if len(headers.get_all("Host") or ()) != 1:
            return 400, "a WebSocket handshake has exactly one Host header"
        host = headers.get("Host", "")
        if not host_allowed(host, self.host, names=self.token is not None):
            return 403, (f"this program answers requests for its address, not for {host!r}: connect to ws://ADDRESS:PORT "
                         "(with --debug-token, names are taken too)")
        origin = headers.get("Origin")
        if not origin_allowed(origin, host, self.origins):
            return 403, (f"a page of {origin} may not steer this program; if it is yours, allow it with "
                         f"[foxglove] origins = [\"{origin}\"]")
        if self.token is not None and not self.token_given(path, headers.get("Authorization")):
            return 401, "this program needs its token: connect to ws://HOST:PORT/?token=TOKEN"
        if headers.get("Upgrade", "").lower() != "websocket":
            return 426, "this is a Foxglove WebSocket server: open a Foxglove WebSocket connection to ws://HOST:PORT"
        if not self.offered(headers) & {self.NEW_NAME, self.OLD_NAME}:
            return 400, f"ask for the subprotocol {self.NEW_NAME} (or its older name {self.OLD_NAME}) in Sec-WebSocket-Protocol"
        return None

    @staticmethod
    def offered(headers: http.client.HTTPMessage) -> set[str]:
        return {name.strip() for value in headers.get_all("Sec-WebSocket-Protocol") or () for name in value.split(",")}

    # ------------------------------------------------------------------------------ the thread
    def _run(self) -> None:
        async def main() -> None:
            self.stopping = asyncio.Event()
            try:
                server = await asyncio.start_server(self._connection, self.host, self.port, limit=self.HEAD_LIMIT)
            except OSError as exc:
                self.error = exc
                self.ready.set()
                return
            self.port = server.sockets[0].getsockname()[1]
            self.ready.set()
            async with server:
                await self.stopping.wait()

        self.loop = asyncio.new_event_loop()
        try:
            self.loop.run_until_complete(main())
        finally:
            self.loop.close()

    async def _connection(self, reader: asyncio.StreamReader, writer: asyncio.StreamWriter) -> None:
        peer = writer.get_extra_info("peername")
        inside: asyncio.StreamWriter | None = None
        try:
            try:
                head = await asyncio.wait_for(reader.readuntil(b"\r\n\r\n"), self.HEAD_TIMEOUT_S)
            except asyncio.LimitOverrunError:
                return await self._refuse(writer, peer, 431, f"the handshake's head is over {self.HEAD_LIMIT} bytes")
            except (asyncio.IncompleteReadError, TimeoutError, ConnectionError):
                return
            request_line, _, rest = head.partition(b"\r\n")
            try:
                headers = http.client.parse_headers(io.BytesIO(rest))
            except http.client.HTTPException as exc:
                return await self._refuse(writer, peer, 431, f"the handshake's headers cannot be read: {exc}")
            parts = request_line.decode("latin-1").split()
            if len(parts) != 3 or parts[0] != "GET":
                return await self._refuse(writer, peer, 400, "this is a Foxglove WebSocket server: a WebSocket handshake (GET) was expected")
            refusal = self.refusal(parts[1], headers)
            if refusal is not None:
                return await self._refuse(writer, peer, *refusal)
            old_name = self.NEW_NAME not in self.offered(headers)
            if old_name:
                del headers["Sec-WebSocket-Protocol"]
                headers["Sec-WebSocket-Protocol"] = self.NEW_NAME
            upstream, inside = await asyncio.open_connection("127.0.0.1", self.inside_port, limit=self.CHUNK * 4)
            inside.write(request_line + b"\r\n" + "".join(f"{k}: {v}\r\n" for k, v in headers.items()).encode("latin-1") + b"\r\n")
            answer = await asyncio.wait_for(upstream.readuntil(b"\r\n\r\n"), self.HEAD_TIMEOUT_S)
            if old_name:  # the client hears the name it asked for
                answer = re.sub(rb"(?im)^(sec-websocket-protocol:[ \t]*)foxglove\.sdk\.v1", rb"\1" + self.OLD_NAME.encode(), answer)
            writer.write(answer)
            await self._relay(reader, writer, upstream, inside, peer)
        except (ConnectionError, OSError, asyncio.IncompleteReadError, asyncio.LimitOverrunError, TimeoutError) as exc:
            log.warning("foxglove: connection of %s ended: %s", _address(peer), exc or type(exc).__name__)
        finally:
            for side in (writer, inside):
                if side is not None:
                    side.close()

    async def _refuse(self, writer: asyncio.StreamWriter, peer: Any, status: int, text: str) -> None:
        self.refused += 1
        log.warning("foxglove: refused a connection from %s (%d so far): %s", _address(peer), self.refused, text)
        body = (text + "\n").encode()
        writer.write(f"HTTP/1.1 {status} {http.client.responses.get(status, 'Refused')}\r\nContent-Type: text/plain; charset=utf-8\r\n"
                     f"Content-Length: {len(body)}\r\nConnection: close\r\n\r\n".encode() + body)
        try:
            await writer.drain()
        except ConnectionError:
            pass

    async def _relay(self, reader: asyncio.StreamReader, writer: asyncio.StreamWriter, upstream: asyncio.StreamReader,
                     inside: asyncio.StreamWriter, peer: Any) -> None:
        """Both ways, byte for byte, until the SDK closes. When the client goes, the SDK hears an end of
        stream and is read to its end, so that it never writes into a dead connection."""
        gone: list[str] = []

        async def up() -> None:
            try:
                while data := await reader.read(self.CHUNK):
                    inside.write(data)
                    await inside.drain()
            except ConnectionError as exc:
                gone.append(str(exc) or type(exc).__name__)
            finally:
                try:
                    inside.write_eof()  # the SDK reads an end of stream and lets its client go
                except (OSError, RuntimeError):
                    pass

        async def down() -> None:
            try:
                while data := await upstream.read(self.CHUNK):
                    writer.write(data)
                    await writer.drain()
                return
            except ConnectionError as exc:
                gone.append(str(exc) or type(exc).__name__)
            inside.write_eof()
            while await upstream.read(self.CHUNK):  # the client is gone: what the SDK still sends goes nowhere
                pass

        sending, receiving = asyncio.create_task(down()), asyncio.create_task(up())
        try:
            await asyncio.wait({sending, receiving}, return_when=asyncio.FIRST_COMPLETED)
            if not sending.done():
                await asyncio.wait({sending}, timeout=self.DRAIN_TIMEOUT_S)
        finally:
            for task in (sending, receiving):
                task.cancel()
            await asyncio.gather(sending, receiving, return_exceptions=True)
        if gone:
            log.warning("foxglove: client %s went away without closing its connection (%s)", _address(peer), gone[0])


def _address(peer: Any) -> str:
    if isinstance(peer, tuple) and len(peer) >= 2:
        return f"[{peer[0]}]:{peer[1]}" if ":" in str(peer[0]) else f"{peer[0]}:{peer[1]}"
    return str(peer)
