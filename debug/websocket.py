"""The debug protocol over a WebSocket, and the files of a web page, from the debug server's own thread.

A browser page speaks the very commands of the text protocol: each text message it sends is one
command line, and each answer comes back, in order, as ``{"answer": TEXT}`` (``TEXT`` exactly what a
telnet client reads, ``error: ...`` included). The same rules hold as for TCP clients: the token
(``auth TOKEN`` first), the connection limit, back-pressure, and commands run between frames.

Two commands belong to this transport, because only it can stream: ``subscribe NAME...`` and
``unsubscribe NAME...``. A subscribed topic's data arrives as it is produced, as a JSON text message
``{"topic": NAME, ...}`` or, for images, a binary message (a 4-byte big-endian header length, a JSON
header, then JPEG bytes). Streamed data is lossy on purpose: a client that reads slowly gets the newest
message of each topic and loses the ones in between; answers are never lost.

HTTP requests other than the WebSocket's are answered with the page's files, and only for a ``Host``
that names this machine or an address (no DNS rebinding); a WebSocket from a page of another origin
is refused (no cross-site hijacking).
"""

from __future__ import annotations

import asyncio
import ipaddress
import json
import logging
import mimetypes
import time
from collections import OrderedDict, deque
from collections.abc import Callable, Iterable
from pathlib import Path
from typing import Any
from urllib.parse import urlsplit

from websockets.asyncio.server import ServerConnection, serve
from websockets.datastructures import Headers
from websockets.exceptions import ConnectionClosed
from websockets.http11 import Request, Response

from tafel.core.framework.naming import did_you_mean
from tafel.debug.commands import CommandError
from tafel.debug.protocol import Command
from tafel.debug.server import DebugServer
from tafel.debug.session import Session

log = logging.getLogger("tafel.web")
WEBSOCKET_PATH = "/ws"
LOCAL_COMMANDS = ("subscribe", "unsubscribe")


def host_allowed(host_header: str, bound: str, names: bool = False) -> bool:
    """Whether an HTTP ``Host`` names this server: an address, ``localhost``, or the name it was bound to.

    Any other name may be an attacker's DNS name that resolves to this machine (DNS rebinding); with
    ``names`` (the program has a token, which such a page cannot know) every name is taken."""
    host = urlsplit(f"//{host_header}").hostname or ""
    if host in ("localhost", bound) or (names and host):
        return True
    try:
        ipaddress.ip_address(host)
    except ValueError:
        return False
    return True


def origin_allowed(origin: str | None, host_header: str, allowed: Iterable[str] = ()) -> bool:
    """Whether a WebSocket with this ``Origin`` may connect: none (not a browser page), a page of this very
    server (same host and port as ``Host``), or one of the ``allowed`` origins; any other site's page is refused
    (cross-site WebSocket hijacking). Shared by every server the program opens to WebSockets."""
    return origin is None or urlsplit(origin).netloc == host_header or origin.rstrip("/") in {a.rstrip("/") for a in allowed}


class WebSocketSession(Session):
    """One page over a WebSocket: command lines in, answers and subscribed data out."""

    def __init__(self, server: DebugServer, web: WebServer, connection: ServerConnection) -> None:
        super().__init__(server, connection.remote_address)
        self.web = web
        self.connection = connection
        self.topics: set[str] = set()
        self.queued_bytes = 0
        self.out: deque[str] = deque()  # answers: never dropped
        self.latest: OrderedDict[str, str | bytes] = OrderedDict()  # streamed: the newest per topic
        self.intervals: dict[str, float] = {}  # topic -> s between its messages at least (subscribe -hz)
        self.next_send: dict[str, float] = {}  # topic -> loop time its next message may go
        self.timers: dict[str, asyncio.TimerHandle] = {}
        self.dropped = 0  # streamed messages replaced before they went out, because the page reads slowly
        self.skipped = 0  # streamed messages replaced before they went out, because of the topic's -hz
        self.sent = 0
        self.wake = asyncio.Event()

    async def serve(self) -> None:
        writer = asyncio.create_task(self._pump())
        try:
            async for message in self.connection:
                data = message.encode() if isinstance(message, str) else message
                await self.handle_lines([line if len(line) <= self.server.max_line else None
                                         for line in data.splitlines() or [b""]], len(data))
        except ConnectionClosed:
            pass
        finally:
            self.web.unsubscribe(self, set(self.topics))
            self.closed = True
            self.server.connections.discard(self)
            self.wake.set()
            await writer

    def local_command(self, command: Command) -> str | None:
        if command.name not in LOCAL_COMMANDS:
            return None
        names = [k for k, v in command.args.items() if v == ""]
        names += [n for n in str(command.args.get("topics", "")).split(",") if n]
        if not names:
            return f"error: usage: {command.name} NAME [NAME...] [-hz N]; the topics are {', '.join(self.web.topics())}"
        if command.name == "unsubscribe":
            for name in names:
                self.intervals.pop(name, None)
                self.latest.pop(name, None)
            self.web.unsubscribe(self, set(names) & self.topics)
            return f"unsubscribed {' '.join(names)}"
        known = self.web.topics()
        unknown = [n for n in names if n not in known]
        if unknown:
            return f"error: there is no topic {unknown[0]!r}; {did_you_mean(unknown[0], known)}"
        hz = str(command.args.get("hz", "")) or "0"
        try:
            rate = float(hz)
        except ValueError:
            rate = -1.0
        if not (rate == 0 or 0.1 <= rate <= 1000):
            return f"error: -hz takes messages a second from 0.1 to 1000 (leave it out for every one), got {hz!r}"
        for name in names:
            if rate:
                self.intervals[name] = 1.0 / rate
            else:
                self.intervals.pop(name, None)
        self.web.subscribe(self, set(names) - self.topics)
        return f"subscribed {' '.join(names)}" + (f" at most {rate:g} a second" if rate else "")

    # ------------------------------------------------------------------ out
    def _write(self, answers: list[bytes]) -> bool:
        for answer in answers:
            text = json.dumps({"answer": answer.rstrip(b"\0").decode("utf-8", "replace").rstrip("\n")})
            self.out.append(text)
            self.queued_bytes += len(text)
        self.wake.set()
        if self.queued_bytes > self.server.max_output:
            log.warning("dropping web client %s: it does not read its answers", self.peer)
            return False
        return True

    def stream(self, topic: str, message: str | bytes) -> None:
        """Network thread: the newest message of a subscribed topic; an unsent older one is dropped."""
        if self.closed:
            return
        if self.latest.pop(topic, None) is not None:
            if self.next_send.get(topic, 0.0) > time.monotonic():  # the loop's clock (asyncio uses monotonic)
                self.skipped += 1  # the page asked for fewer (subscribe -hz)
            else:
                self.dropped += 1  # the page reads too slowly
        self.latest[topic] = message
        self.wake.set()

    async def _pump(self) -> None:
        """Send answers first, then the newest message of each topic that is due; waits while the browser is slow."""
        try:
            while not self.closed:
                await self.wake.wait()
                self.wake.clear()
                while not self.closed:
                    if self.out:
                        message: str | bytes = self.out.popleft()
                        self.queued_bytes -= len(message)
                    else:
                        topic = self._due()
                        if topic is None:
                            break
                        message = self.latest.pop(topic)
                        if topic in self.intervals:
                            self.next_send[topic] = asyncio.get_running_loop().time() + self.intervals[topic]
                        self.sent += 1
                    await self.connection.send(message)
                if self.reading_done and not self.out:
                    break
        except ConnectionClosed:
            pass
        finally:
            for timer in self.timers.values():
                timer.cancel()

    def _due(self) -> str | None:
        """The first topic whose newest message may go now; for the others, a wake-up when they may."""
        loop = asyncio.get_running_loop()
        now = loop.time()
        for topic in self.latest:
            when = self.next_send.get(topic, 0.0)
            if when <= now:
                return topic
            if topic not in self.timers:
                self.timers[topic] = loop.call_later(when - now, self._timer_fired, topic)
        return None

    def _timer_fired(self, topic: str) -> None:
        self.timers.pop(topic, None)
        self.wake.set()

    def _close_transport(self, abort: bool) -> None:
        asyncio.ensure_future(self.connection.close(1008 if abort else 1000))


class WebServer:
    """The page's files and its WebSocket, served in the debug server's event loop.

    ``topics`` lists what may be subscribed; ``on_subscriptions`` hears the set of subscribed topics
    whenever it changes (the feed encodes nothing else); ``publish`` hands a topic's message to every
    subscriber, from any thread.
    """

    def __init__(self, debug: DebugServer, static: Path, *, host: str = "127.0.0.1", port: int = 5480,
                 topics: Callable[[], list[str]] = lambda: [],
                 on_subscriptions: Callable[[frozenset[str]], None] = lambda topics: None) -> None:
        self.debug = debug
        self.static = static.resolve()
        self.host, self.port = host, port
        self.topics = topics
        self.on_subscriptions = on_subscriptions
        self.subscribers: dict[str, set[WebSocketSession]] = {}
        self.refused_origin = 0
        self.gone = {"sent": 0, "dropped": 0, "skipped": 0}  # counts of pages that closed

    def start(self) -> tuple[str, int]:
        """Listen (in the debug server's thread); raises ``OSError`` when the port cannot be had."""
        for name, summary in (("subscribe", "stream representations as they are produced (WebSocket clients only)"),
                              ("unsubscribe", "stop streaming representations (WebSocket clients only)")):
            self.debug.router.register(name, summary, f"{name} NAME [NAME...]" + (" [-hz N]" if name == "subscribe" else ""),
                                       self._streams_only)
        async def listen() -> Any:
            return await serve(self._session, self.host, self.port, process_request=self._http,
                               max_size=self.debug.max_line, compression=None)

        server = self.debug.run_in_loop(listen())
        self.debug.listeners.append(server)
        self.port = server.sockets[0].getsockname()[1]
        return self.host, self.port

    def _streams_only(self, command: Command) -> str:
        raise CommandError(f"{command.name} streams over the web page's WebSocket (ws://{self.host}:{self.port}{WEBSOCKET_PATH}); "
                           "here, ask representation:print -name NAME (or -format json) when you want a value")

    # ------------------------------------------------------------------ subscriptions
    def subscribe(self, session: WebSocketSession, topics: Iterable[str]) -> None:
        for topic in topics:
            self.subscribers.setdefault(topic, set()).add(session)
            session.topics.add(topic)
        self._tell()

    def unsubscribe(self, session: WebSocketSession, topics: Iterable[str]) -> None:
        for topic in topics:
            self.subscribers.get(topic, set()).discard(session)
            session.topics.discard(topic)
            if not self.subscribers.get(topic):
                self.subscribers.pop(topic, None)
        self._tell()

    def _tell(self) -> None:
        try:
            self.on_subscriptions(self.subscribed())
        except Exception:  # noqa: BLE001 - the feed's bug must not cost the page its connection
            log.exception("web: the feed could not take the new subscriptions")

    def sessions(self) -> list[WebSocketSession]:
        return [s for s in list(self.debug.connections) if isinstance(s, WebSocketSession)]

    def subscribed(self) -> frozenset[str]:
        return frozenset(self.subscribers)

    def publish(self, topic: str, message: str | bytes) -> None:
        """Any thread: send ``message`` to the topic's subscribers (dropping for slow ones)."""
        loop = self.debug._loop
        if loop is not None and not loop.is_closed():
            loop.call_soon_threadsafe(self._distribute, topic, message)

    def _distribute(self, topic: str, message: str | bytes) -> None:
        for session in list(self.subscribers.get(topic, ())):
            session.stream(topic, message)

    # ------------------------------------------------------------------ connections
    async def _session(self, connection: ServerConnection) -> None:
        refusal = self.debug.refusal(connection.remote_address)
        if refusal is not None:
            await connection.send(json.dumps({"answer": refusal}))
            await connection.close(1013)
            return
        session = WebSocketSession(self.debug, self, connection)
        self.debug.connections.add(session)
        await session.serve()
        for key in self.gone:
            self.gone[key] += getattr(session, key)

    def _http(self, connection: ServerConnection, request: Request) -> Response | None:
        host = request.headers.get("Host", "")
        if not host_allowed(host, self.host, names=self.debug.token is not None):
            log.warning("web: refused a request for host %r (only addresses and localhost are served)", host)
            return connection.respond(403, f"this program answers requests for its address, not for {host!r} "
                                           "(with --debug-token, names are taken too)\n")
        path = urlsplit(request.path).path
        if path == WEBSOCKET_PATH:
            origin = request.headers.get("Origin")
            if not origin_allowed(origin, host):
                self.refused_origin += 1
                log.warning("web: refused a WebSocket from a page of %s", origin)
                return connection.respond(403, "a page of another site may not steer this program\n")
            return None
        return self._file(connection, path)

    def _file(self, connection: ServerConnection, path: str) -> Response:
        relative = "index.html" if path in ("", "/") else path.lstrip("/")
        target = (self.static / relative).resolve()
        if not target.is_relative_to(self.static) or not target.is_file():
            return connection.respond(404, f"no such file: {path}\n")
        body = target.read_bytes()
        kind = mimetypes.guess_type(target.name)[0] or "application/octet-stream"
        if kind.startswith("text/") or kind == "application/javascript":
            kind += "; charset=utf-8"
        headers = Headers([("Content-Type", kind), ("Content-Length", str(len(body))), ("Cache-Control", "no-cache"),
                           ("X-Content-Type-Options", "nosniff"), ("Connection", "close")])
        return Response(200, "OK", headers, body)
