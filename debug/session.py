"""One client's connection to the debug server: its lines parsed and queued with their sequence numbers,
its answers written strictly in order, its limits (open commands, unsent bytes, bytes per frame, auth
attempts, idle time), and a connection that speaks HTTP closed before anything runs."""

from __future__ import annotations

import asyncio
import concurrent.futures
import hmac
import ipaddress
import logging
import queue
import threading
import time
from collections import deque
from dataclasses import dataclass
from typing import Any, Protocol

from tafel.debug.protocol import Command, ParseError, TelnetDecoder, answer_bytes, encode_answer, parse
from tafel.debug.router import DebugRouter

#: s between two log lines about the same kind of failure (descriptors running out, say)
RESOURCE_LOG_INTERVAL = 10.0
log = logging.getLogger("tafel.debug")

MAX_OUTSTANDING = 2000  # open commands per connection before it is read no more
MAX_OUTPUT = 8 << 20  # unsent answer bytes per connection before it is dropped
MAX_CONNECTIONS = 32  # connections served at once; more get one error line and are closed
MAX_BYTES_PER_FRAME = 64 * 1024  # bytes read from one client per frame; it waits for the next frame beyond
#: s of the network thread's time for handling lines, all clients together, per frame; beyond, they wait for the next
#: frame. Lines run there hold the interpreter lock the loops need: ping, help and refusals are answered at once.
NETWORK_S_PER_FRAME = 0.0005
FRAME_WAIT = 0.05  # s a throttled client waits at most when no frame comes (a paused or ended loop)
AUTH_PER_SECOND = 5  # auth attempts per connection and second; more are answered later
AUTH_FAILURES = 20  # wrong tokens before the connection is closed
IDLE_TIMEOUT = 30.0  # s a connection may stay without authenticating (without a token: without a command)
LOOPBACK_RESERVE = 1  # places under the connection limit only clients on this machine may take


@dataclass
class _Request:
    connection: Session
    sequence: int
    command: Command


HTTP_FIRST_WORDS = (b"GET ", b"POST ", b"PUT ", b"HEAD ", b"DELETE ", b"OPTIONS ", b"PATCH ", b"CONNECT ", b"TRACE ")


#: bytes at the start of a connection that tell whether it speaks HTTP (the longest method and a space fit)
HTTP_HEAD = 16


def looks_like_http(line: bytes) -> bool:
    """An HTTP request line or header (``POST / HTTP/1.1``, ``Host: ...``): no command ever looks like it."""
    head = line.lstrip()
    return head.startswith(HTTP_FIRST_WORDS) or head.lower().startswith((b"host:", b"user-agent:", b"content-")) \
        or b" HTTP/1." in head


def starts_like_http(head: bytes) -> bool:
    """The first bytes of a connection begin an HTTP request (``POST /...``), however long its line."""
    return head.lstrip().startswith(HTTP_FIRST_WORDS)


def is_loopback(peer: Any) -> bool:
    """Whether a peer (an address, or ``(address, port, ...)`` as sockets give it) is this machine."""
    host = peer[0] if isinstance(peer, tuple) and peer else peer
    try:
        address = ipaddress.ip_address(str(host).split("%")[0])
    except ValueError:
        return False
    mapped = getattr(address, "ipv4_mapped", None)  # ::ffff:127.0.0.1
    return address.is_loopback or (mapped is not None and mapped.is_loopback)


class SessionHost(Protocol):
    """What a session needs of the server that owns it (``DebugServer``): its limits, the router, the queue of
    commands for the thread that owns the data, and the network thread's loop. Sessions only call back."""

    router: DebugRouter
    token: str | None
    max_line: int
    max_output: int
    max_bytes_per_frame: int
    idle_timeout: float | None
    pending: queue.Queue[_Request]
    connections: set[Session]

    @property
    def loop(self) -> asyncio.AbstractEventLoop | None:
        """The network thread's event loop while the server runs."""

    async def next_frame_started(self) -> None:
        """Returns when the next frame of the owning thread starts (or after ``FRAME_WAIT``)."""

    def spend_network_time(self, seconds: float) -> bool:
        """Count ``seconds`` the network thread spent on lines this frame; True when the frame's share is used up."""


class Session:
    """One client of the debug server, whatever carries its lines (TCP, a WebSocket).

    It parses each line, checks the token, answers stateless commands at once and queues the rest for
    the thread that owns the data. Answers go out strictly in the order the commands came, through
    ``_write``, which each transport supplies. Runs in the network thread.
    """

    def __init__(self, server: SessionHost, peer: Any) -> None:
        self.server = server
        self.peer = peer
        self.authenticated = server.token is None
        self.next_sequence = 0
        self.next_answer = 0
        self.answers: dict[int, bytes] = {}
        self.outstanding = 0
        self.room = asyncio.Event()
        self.frame_bytes = 0  # read in the current frame
        self.closed = False
        self.reading_done = False
        self.auth_times: deque[float] = deque(maxlen=AUTH_PER_SECOND)
        self.auth_failures = 0
        #: authenticated with the token, or (without one) sent a command: only then may it stay idle
        self.proven = False

    # ------------------------------------------------------------------ what a transport supplies
    def _write(self, answers: list[bytes]) -> bool:
        """Send these answers (each as ``answer_bytes`` made it), in order; False when the client is gone
        or does not read (then it is dropped)."""
        raise NotImplementedError

    def _close_transport(self, abort: bool) -> None:
        raise NotImplementedError

    # ------------------------------------------------------------------ lines in
    async def wait_for_room(self) -> None:
        """Read no further while too many of this client's commands are open (back-pressure)."""
        while self.outstanding > MAX_OUTSTANDING and not self.closed:
            self.room.clear()
            await self.room.wait()

    async def handle_lines(self, lines: list[bytes | None], size: int) -> None:
        """The lines of one read of ``size`` bytes, then the read's pacing: wait while too many of this client's
        commands are open, and for the next frame when it used up its bytes for this frame or all clients
        together used up the network thread's share of it."""
        spent = 0.0
        for line in lines:
            await self.pace_auth(line)  # may sleep: not the network thread's time
            start = time.perf_counter()
            self.handle_line(line)
            spent += time.perf_counter() - start
        used_up = self.server.spend_network_time(spent)
        await self.wait_for_room()
        self.frame_bytes += size
        if used_up or self.frame_bytes > self.server.max_bytes_per_frame:
            await self.server.next_frame_started()  # read no further from it this frame
            self.frame_bytes = 0

    def handle_line(self, raw: bytes | None) -> None:
        """One line from the client (None: it was too long)."""
        if self.closed:
            return
        if raw is not None and not raw.strip():
            return  # an empty line is no command: telnet users press enter
        sequence = self.next_sequence
        self.next_sequence += 1
        if raw is None:
            self.deliver(sequence, answer_bytes(f"error: line too long (at most {self.server.max_line} bytes)"))
            return
        try:
            command = parse(raw.decode("utf-8").strip()).as_text()
        except UnicodeDecodeError as exc:
            self.deliver(sequence, answer_bytes(f"error: the line is not valid UTF-8 (byte {exc.start})"))
            return
        except ParseError as exc:
            self.deliver(sequence, answer_bytes(f"error: {exc}"))
            return
        if command.name == "auth":
            self._authenticate(sequence, command)
            return
        if not self.authenticated:
            self.deliver(sequence, answer_bytes("error: not authenticated (send: auth TOKEN)"))
            return
        self.proven = True
        local = self.local_command(command)
        if local is not None:
            self.deliver(sequence, answer_bytes(local))
            return
        if command.name in DebugRouter.IMMEDIATE:  # stateless: answer here, in order, without waiting a frame
            ((is_error, payload),) = self.server.router.handle_batch([command])
            self.deliver(sequence, encode_answer(command, is_error, payload))
            return
        self.outstanding += 1
        self.server.pending.put(_Request(self, sequence, command))

    def local_command(self, command: Command) -> str | None:
        """A command the transport answers itself (a WebSocket's subscriptions); None: not one."""
        return None

    def watch_idle(self) -> None:
        """Network thread, at connect: close this connection if it has not proven itself (``proven``)
        within the server's ``idle_timeout``. A deadline from connecting, not from its last byte: a
        client trickling bytes keeps no place either."""
        loop, timeout = self.server.loop, self.server.idle_timeout
        if loop is not None and timeout is not None:
            loop.call_later(timeout, self._idle_check)

    def _idle_check(self) -> None:
        if self.closed or self.proven:
            return
        what = "authenticating" if self.server.token is not None else "a command"
        log.info("debug server: closed %s: %g s without %s", self.peer, self.server.idle_timeout, what)
        self._write([answer_bytes(f"error: {self.server.idle_timeout:g} s without {what}; closing")])
        self.close()

    def _authenticate(self, sequence: int, command: Command) -> None:
        token = next((k for k, v in command.args.items() if v == ""), "") or command.args.get("token", "")
        if self.server.token is None or hmac.compare_digest(str(token).encode(), self.server.token.encode()):
            self.authenticated = self.proven = True
            self.deliver(sequence, answer_bytes("authenticated"))
            return
        self.auth_failures += 1
        if self.auth_failures >= AUTH_FAILURES:
            log.warning("debug server: closed %s after %d wrong tokens", self.peer, self.auth_failures)
            self.deliver(sequence, answer_bytes(f"error: wrong token; {AUTH_FAILURES} wrong tokens, closing"))
            self.close()
        else:
            self.deliver(sequence, answer_bytes("error: wrong token"))

    async def pace_auth(self, raw: bytes | None) -> None:
        """At most ``AUTH_PER_SECOND`` attempts a second: guessing a token takes forever."""
        if raw is None or raw.lstrip()[:4] != b"auth":
            return
        now = time.monotonic()
        if len(self.auth_times) == AUTH_PER_SECOND and now - self.auth_times[0] < 1.0:
            await asyncio.sleep(1.0 - (now - self.auth_times[0]))
        self.auth_times.append(time.monotonic())

    # ------------------------------------------------------------------ answers out
    def deliver(self, sequence: int, data: bytes) -> None:
        """Network thread: keep the answer and send every answer that is next in order."""
        self.deliver_many([(sequence, data)])

    def deliver_many(self, answers: list[tuple[int, bytes]]) -> None:
        """Network thread: keep the answers; send, in one write, all that are next in order."""
        if self.closed:
            return
        self.answers.update(answers)
        ready = []
        while self.next_answer in self.answers:
            ready.append(self.answers.pop(self.next_answer))
            self.next_answer += 1
        if ready and not self._write(ready):
            self.drop()
            return
        self._finish_if_done()

    def answered(self) -> None:
        self.outstanding -= 1
        if self.outstanding <= MAX_OUTSTANDING // 2:
            self.room.set()

    def _finish_if_done(self) -> None:
        if self.reading_done and self.outstanding <= 0 and not self.answers and not self.closed:
            self.close()  # graceful: what is buffered still goes out

    def close(self) -> None:
        """Close after what is already written has gone out; nothing more is read or answered."""
        self._end(abort=False)

    def drop(self) -> None:
        """Close at once, discarding unsent answers (a client that does not read, or is gone)."""
        self._end(abort=True)

    def _end(self, abort: bool) -> None:
        if not self.closed:
            self.closed = True
            self.room.set()
            self._close_transport(abort)
            self.server.connections.discard(self)


class _Connection(Session):
    """A TCP client (telnet, ``tafel console``, tools): lines in, NUL-terminated answers out."""

    def __init__(self, server: SessionHost, reader: asyncio.StreamReader, writer: asyncio.StreamWriter) -> None:
        super().__init__(server, writer.get_extra_info("peername"))
        self.reader, self.writer = reader, writer
        self.head = b""  # the connection's first bytes, until they tell whether it speaks HTTP
        self.head_checked = False

    async def serve(self) -> None:
        decoder = TelnetDecoder(self.server.max_line)
        self.watch_idle()
        try:
            while not self.closed:
                data = await self.reader.read(65536)
                if not data:
                    break
                if not self.head_checked and self._refuse_http(data):
                    return
                await self.handle_lines(list(decoder.feed(data)), len(data))
        except (ConnectionError, asyncio.IncompleteReadError):
            self.drop()
            return
        # The client sent everything (it may have half-closed): answer what is open, then close.
        self.reading_done = True
        self._finish_if_done()

    def _refuse_http(self, data: bytes) -> bool:
        """Look at the connection's first bytes before any line of them runs: a request line of any length
        (one over ``max_line`` would otherwise arrive as "too long" and the body's lines would run)."""
        self.head += data[: HTTP_HEAD - len(self.head)]
        if starts_like_http(self.head):
            self._refuse_as_http(self.head)
            return True
        self.head_checked = len(self.head) >= HTTP_HEAD or b"\n" in self.head
        return False

    def _refuse_as_http(self, line: bytes) -> None:
        # A web page can make a browser send a POST here; its body would run as commands. Never.
        log.warning("debug server: closed a connection from %s that speaks HTTP (%r); nothing was run", self.peer, line[:60])
        self.drop()

    def handle_line(self, raw: bytes | None) -> None:
        if self.next_sequence == 0 and raw is not None and looks_like_http(raw) and not self.closed:
            self._refuse_as_http(raw)
            return
        super().handle_line(raw)

    def _write(self, answers: list[bytes]) -> bool:
        if self.writer.transport.is_closing():  # the client is gone (reset): stop answering it
            return False
        self.writer.write(b"".join(answers))
        if self.writer.transport.get_write_buffer_size() > self.server.max_output:
            log.warning("dropping debug client %s: it does not read its answers", self.peer)
            return False
        return True

    def _close_transport(self, abort: bool) -> None:
        if abort:
            self.writer.transport.abort()
        else:
            self.writer.close()


class _InProcessClient:
    """A client in this process (the Foxglove bridge): its commands queue with everybody else's and run
    between frames like theirs; ``ask`` waits for the answer."""

    closed = False

    def __init__(self) -> None:
        self.waiting: dict[int, concurrent.futures.Future[bytes]] = {}
        self.next_sequence = 0
        self.lock = threading.Lock()

    def answered(self) -> None:
        pass

    def deliver_many(self, answers: list[tuple[int, bytes]]) -> None:
        for sequence, data in answers:
            future = self.waiting.pop(sequence, None)
            if future is not None:
                future.set_result(data)


