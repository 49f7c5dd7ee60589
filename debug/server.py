"""The debug server: the command protocol over TCP, answered between frames.

A network thread runs an asyncio server. Each connection's lines are parsed there and queued, with
their sequence number, for the thread that owns the data; ``process_pending`` (called between frames,
or by a dispatcher thread for contexts in other processes) executes everything queued in one go and
hands the answers back. A connection writes its answers strictly in the order its commands arrived.

Nothing a client sends can stop a loop or another client: malformed lines get ``error:`` answers,
overlong lines are cut off and reported, a client that floods commands is slowed down (it is not read
while too many of its commands are open), and a client that does not read its answers is dropped once
its output buffer is full. A connection that speaks HTTP (a web page's POST) is closed before anything
runs, however long its first line; one that has not authenticated (without a token: sent no command)
within ``idle_timeout`` is closed, and the last place under the connection limit is kept for clients
on this machine, so that held-open connections from elsewhere cannot lock its user out.
"""

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
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

from tafel.core.framework.naming import did_you_mean
from tafel.core.runtime import name_os_thread
from tafel.debug.commands import SPECS, CommandError, merge_answers
from tafel.debug.protocol import Command, ParseError, TelnetDecoder, answer_bytes, parse

#: s between two log lines about the same kind of failure (descriptors running out, say)
RESOURCE_LOG_INTERVAL = 10.0
log = logging.getLogger("tafel.debug")

MAX_OUTSTANDING = 2000  # open commands per connection before it is read no more
MAX_OUTPUT = 8 << 20  # unsent answer bytes per connection before it is dropped
MAX_CONNECTIONS = 32  # connections served at once; more get one error line and are closed
MAX_BYTES_PER_FRAME = 64 * 1024  # bytes read from one client per frame; it waits for the next frame beyond
FRAME_WAIT = 0.05  # s a throttled client waits at most when no frame comes (a paused or ended loop)
AUTH_PER_SECOND = 5  # auth attempts per connection and second; more are answered later
AUTH_FAILURES = 20  # wrong tokens before the connection is closed
IDLE_TIMEOUT = 30.0  # s a connection may stay without authenticating (without a token: without a command)
LOOPBACK_RESERVE = 1  # places under the connection limit only clients on this machine may take


class Executor:
    """Something that answers context commands in batches: a ``ContextDebug`` or a remote process.

    ``start`` hands a batch over and ``finish`` collects its answers, so that contexts in other
    processes work on their batches at the same time.
    """

    def start(self, commands: Sequence[Command]) -> Any:
        return self.execute_batch(commands)

    def finish(self, started: Any) -> list[tuple[str, str | bytes]]:
        return started

    def execute_batch(self, commands: Sequence[Command]) -> list[tuple[str, str | bytes]]:
        raise NotImplementedError


@dataclass
class GlobalCommand:
    summary: str
    usage: str
    handler: Callable[[Command], str | bytes]


class DebugRouter:
    """Runs commands: globals itself, context commands on every context, answers combined."""

    def __init__(self) -> None:
        self.contexts: dict[str, Executor] = {}
        self.globals: dict[str, GlobalCommand] = {}
        #: context -> names of its modules and representations, to ask only the context that has a name
        self.index: dict[str, set[str]] = {}
        self.register("help", "the commands, or one command's arguments", "help [NAME]", self._help)
        self.register("ping", "answers pong", "ping", lambda command: "pong")
        self.register("auth", "authenticate with the server's token (--debug-token)", "auth TOKEN", lambda command: "authenticated")
        #: what ``hello`` answers: which program this is (platform, pid, start time)
        self.identity = "tafel"
        self.register("hello", "which program this is: platform, process id, start time", "hello", lambda command: self.identity)

    def add_context(self, name: str, executor: Executor, names: set[str] | None = None) -> None:
        self.contexts[name] = executor
        if names is not None:
            self.index[name] = set(names)

    #: commands that need no context and change nothing: answered by the network thread on arrival
    IMMEDIATE = frozenset({"ping", "help", "hello"})

    def targets(self, command: Command) -> list[str]:
        """The contexts to ask: the one that has the named module or representation, else all."""
        wanted = command.args.get("context")
        if isinstance(wanted, str) and wanted in self.contexts:
            return [wanted]
        if SPECS[command.name].routing != "merge" and self.index:
            names = {v for k, v in command.args.items() if k in ("module", "name", "representation") and isinstance(v, str)}
            names |= {k for k, v in command.args.items() if v == ""}
            having = [c for c in self.contexts if names & self.index.get(c, set())]
            if having:
                return having
        return list(self.contexts)

    def register(self, name: str, summary: str, usage: str, handler: Callable[[Command], str | bytes]) -> None:
        self.globals[name] = GlobalCommand(summary, usage, handler)

    def names(self) -> list[str]:
        return sorted({*self.globals, *SPECS})

    def _help(self, command: Command) -> str:
        name = next((k for k, v in command.args.items() if v == ""), "") or str(command.args.get("name", ""))
        if name:
            if name in self.globals:
                return f"{name}: {self.globals[name].summary}\nusage: {self.globals[name].usage}"
            if name in SPECS:
                return f"{name}: {SPECS[name].summary}\nusage: {SPECS[name].usage}"
            raise CommandError(f"unknown command {name!r}: {did_you_mean(name, self.names())}")
        lines = [f"{n:<24} {self.globals[n].summary if n in self.globals else SPECS[n].summary}" for n in self.names()]
        return "\n".join(lines)

    def handle_batch(self, commands: Sequence[Command]) -> list[tuple[bool, str | bytes]]:
        """(is_error, answer) per command, in order. Runs of context commands go out as one batch."""
        results: list[tuple[bool, str | bytes] | None] = [None] * len(commands)
        run: list[int] = []

        def flush() -> None:
            if not run:
                return
            wanted = {index: self.targets(commands[index]) for index in run}
            batches = {name: [i for i in run if name in wanted[i]] for name in self.contexts}
            started = {name: executor.start([commands[i] for i in batches[name]])
                       for name, executor in self.contexts.items() if batches[name]}
            per_context = {name: dict(zip(batches[name], self.contexts[name].finish(handle))) for name, handle in started.items()}
            for index in run:
                answers = {name: per_context[name][index] for name in wanted[index] if name in per_context}
                results[index] = merge_answers(commands[index], answers) if answers else (True, "no context is running")
            run.clear()

        for index, command in enumerate(commands):
            if command.name in SPECS:
                run.append(index)
                continue
            flush()
            handler = self.globals.get(command.name)
            if handler is None:
                results[index] = (True, f"unknown command {command.name!r}: {did_you_mean(command.name, self.names())}")
                continue
            try:
                results[index] = (False, handler.handler(command))
            except CommandError as exc:
                results[index] = (True, str(exc))
            except Exception as exc:  # noqa: BLE001 - a handler bug answers, never crashes the loop
                results[index] = (True, f"{command.name} failed: {type(exc).__name__}: {exc}")
        flush()
        return [r if r is not None else (True, "no answer") for r in results]


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


class Session:
    """One client of the debug server, whatever carries its lines (TCP, a WebSocket).

    It parses each line, checks the token, answers stateless commands at once and queues the rest for
    the thread that owns the data. Answers go out strictly in the order the commands came, through
    ``_write``, which each transport supplies. Runs in the network thread.
    """

    def __init__(self, server: DebugServer, peer: Any) -> None:
        self.server = server
        self.peer = peer
        self.authenticated = server.token is None
        self.next_sequence = 0
        self.next_answer = 0
        self.answers: dict[int, bytes] = {}
        self.outstanding = 0
        self.room = asyncio.Event()
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
            self.deliver(sequence, self.server.encode(command, is_error, payload))
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
        loop, timeout = self.server._loop, self.server.idle_timeout
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

    def __init__(self, server: DebugServer, reader: asyncio.StreamReader, writer: asyncio.StreamWriter) -> None:
        super().__init__(server, writer.get_extra_info("peername"))
        self.reader, self.writer = reader, writer
        self.frame_bytes = 0  # read in the current frame
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
                for line in decoder.feed(data):
                    await self.pace_auth(line)
                    self.handle_line(line)
                await self.wait_for_room()
                self.frame_bytes += len(data)
                if self.frame_bytes > self.server.max_bytes_per_frame:
                    await self.server.next_frame_started()  # read no further from it this frame
                    self.frame_bytes = 0
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


class DebugServer:
    """The debug server; ``start`` binds and prints nothing, ``address`` says where it listens."""

    def __init__(self, router: DebugRouter, host: str = "127.0.0.1", port: int = 5401, *, token: str | None = None,
                 max_line: int = 64 * 1024, max_output: int = MAX_OUTPUT, max_connections: int = MAX_CONNECTIONS,
                 max_bytes_per_frame: int = MAX_BYTES_PER_FRAME, idle_timeout: float | None = IDLE_TIMEOUT) -> None:
        if token is not None and not token:
            raise ValueError("an empty debug token would let anybody in; give a token or none")
        self.router = router
        self.host, self.port = host, port
        self.token = token
        self.max_line = max_line
        self.max_output = max_output
        self.max_connections = max_connections
        self.max_bytes_per_frame = max_bytes_per_frame
        #: s a connection may stay without authenticating (without a token: without a command); None: forever
        self.idle_timeout = idle_timeout
        self.refused = 0  # connections refused over the limit
        self._frame: asyncio.Event | None = None  # set (and replaced) when a frame starts, for throttled clients
        self._throttled = 0
        self._resource_errors = 0
        self._resource_logged_at = 0.0  # monotonic s of the last line about them
        # queue.Queue, not SimpleQueue: in Python 3.11 a signal that arrives during SimpleQueue.get(timeout)
        # can leave it waiting forever (the loop thread then never sees its stop flag)
        self.pending: queue.Queue[_Request] = queue.Queue()
        self._queues: dict[Session, deque[_Request]] = {}
        self._turns: deque[Session] = deque()  # connections with queued commands, in rotation
        self.connections: set[Session] = set()
        self.answered = 0
        self._loop: asyncio.AbstractEventLoop | None = None
        self._server: asyncio.base_events.Server | None = None
        self._thread: threading.Thread | None = None
        self._ready = threading.Event()
        self._error: BaseException | None = None
        self._local = _InProcessClient()
        #: further listeners in this loop (the web page's), closed with the server
        self.listeners: list[Any] = []

    @property
    def address(self) -> tuple[str, int]:
        return self.host, self.port

    def ask(self, line: str, timeout: float = 5.0) -> str:
        """Run one command line for a client in this process (authenticated: it is the program itself)
        and return its answer as text; ``error: ...`` as any client gets it. Raises ``TimeoutError``."""
        try:
            command = parse(line.strip()).as_text()
        except ParseError as exc:
            return f"error: {exc}"
        if command.name in DebugRouter.IMMEDIATE:
            ((is_error, payload),) = self.router.handle_batch([command])
            data = self.encode(command, is_error, payload)
        else:
            client = self._local
            future: concurrent.futures.Future[bytes] = concurrent.futures.Future()
            with client.lock:
                sequence = client.next_sequence
                client.next_sequence += 1
                client.waiting[sequence] = future
            self.pending.put(_Request(client, sequence, command))  # type: ignore[arg-type]
            data = future.result(timeout)
        return data.rstrip(b"\0").decode("utf-8", "replace").rstrip("\n")

    def start(self) -> tuple[str, int]:
        self._thread = threading.Thread(target=self._run, name="tafel-debug-server", daemon=True)
        self._thread.start()
        self._ready.wait(timeout=10)
        if self._error is not None:
            code = getattr(self._error, "errno", None) or 0
            raise OSError(code, f"debug server cannot listen on {self.host}:{self.port}: {self._error}")
        return self.address

    def _run(self) -> None:
        name_os_thread("tafel-debug")
        loop = asyncio.new_event_loop()
        self._loop = loop
        asyncio.set_event_loop(loop)

        async def accept(reader: asyncio.StreamReader, writer: asyncio.StreamWriter) -> None:
            refusal = self.refusal(writer.get_extra_info("peername"))
            if refusal is not None:
                writer.write(answer_bytes(refusal))
                writer.close()
                return
            connection = _Connection(self, reader, writer)
            self.connections.add(connection)
            await connection.serve()

        loop.set_exception_handler(self._loop_error)
        self._frame = asyncio.Event()

        try:
            self._server = loop.run_until_complete(asyncio.start_server(accept, self.host, self.port, limit=self.max_line * 2))
            self.port = self._server.sockets[0].getsockname()[1]
        except OSError as exc:
            self._error = exc
            self._ready.set()
            return
        self._ready.set()
        try:
            loop.run_forever()
        finally:
            loop.run_until_complete(loop.shutdown_asyncgens())
            loop.close()

    def refusal(self, peer: Any = None) -> str | None:
        """Network thread: why a new client from ``peer`` cannot be served (every transport counts), or None.

        The last ``LOOPBACK_RESERVE`` places are for clients on this machine (a peer not known counts as
        from elsewhere): connections held open from elsewhere never lock the robot's own user out."""
        reserve = LOOPBACK_RESERVE if self.max_connections > LOOPBACK_RESERVE else 0
        local = is_loopback(peer)
        if len(self.connections) < self.max_connections - (0 if local else reserve):
            return None
        self.refused += 1
        if self.refused == 1 or self.refused % 100 == 0:
            log.warning("debug server: refused %d connection(s) over the limit of %d", self.refused, self.max_connections)
        kept = "" if local or not reserve else f", the last {reserve} kept for clients on the robot itself"
        return f"error: too many debug connections ({self.max_connections} at most{kept}); close another one and connect again"

    def run_in_loop(self, coroutine: Any, timeout: float = 10.0) -> Any:
        """Run a coroutine in the network thread's event loop and return its result (another transport
        starts its listener this way, so that all clients share one thread and one set of rules)."""
        if self._loop is None:
            raise RuntimeError("the debug server is not running; start() it first")
        return asyncio.run_coroutine_threadsafe(coroutine, self._loop).result(timeout)

    def _loop_error(self, loop: asyncio.AbstractEventLoop, context: dict[str, Any]) -> None:
        """asyncio's errors as one line each, never a traceback per failed accept.

        When file descriptors run out, asyncio retries ``accept`` (for every waiting connection, often
        hundreds of times a second) and would log a traceback each time: here the first is one line,
        and after it at most one line every ``RESOURCE_LOG_INTERVAL`` seconds, with the count.
        """
        self._resource_errors += 1
        now = time.monotonic()
        if self._resource_errors == 1 or now - self._resource_logged_at >= RESOURCE_LOG_INTERVAL:
            self._resource_logged_at = now
            exc = context.get("exception")
            log.error("debug server: %s%s (%d so far; the program goes on)", context.get("message", "error"),
                      f": {exc}" if exc else "", self._resource_errors)

    async def next_frame_started(self) -> None:
        """Network thread: wait until the next frame starts (or ``FRAME_WAIT``, if none comes)."""
        event = self._frame
        if event is None:
            return
        self._throttled += 1
        try:
            await asyncio.wait_for(event.wait(), FRAME_WAIT)
        except asyncio.TimeoutError:
            pass
        finally:
            self._throttled -= 1

    def next_frame(self) -> None:
        """A frame starts: clients that used up their bytes may be read again. Costs nothing when none did."""
        loop = self._loop
        if self._throttled and loop is not None:
            loop.call_soon_threadsafe(self._wake_throttled)

    def _wake_throttled(self) -> None:
        if self._frame is not None:
            self._frame.set()
            self._frame = asyncio.Event()

    def stop(self) -> None:
        loop = self._loop
        if loop is None or not loop.is_running():
            return

        async def shutdown() -> None:
            for connection in list(self.connections):
                connection.drop()
            for server in (self._server, *self.listeners):
                if server is not None:
                    server.close()
            # let every connection's task end (a WebSocket says goodbye), then cancel what is left
            for server in self.listeners:
                try:
                    await asyncio.wait_for(server.wait_closed(), 2.0)
                except (asyncio.TimeoutError, OSError):
                    pass
            tasks = [task for task in asyncio.all_tasks() if task is not asyncio.current_task()]
            for task in tasks:
                task.cancel()
            await asyncio.gather(*tasks, return_exceptions=True)
            loop.stop()

        asyncio.run_coroutine_threadsafe(shutdown(), loop)
        if self._thread is not None:
            self._thread.join(timeout=5)

    def _collect(self, wait: float = 0.0) -> None:
        """Move what the network thread queued into per-connection queues (processing thread only)."""
        try:
            if wait > 0 and not self._queues:
                self._take(self.pending.get(timeout=wait))
            while True:
                self._take(self.pending.get_nowait())
        except queue.Empty:
            pass

    def _take(self, request: _Request) -> None:
        waiting = self._queues.get(request.connection)
        if waiting is None:
            waiting = self._queues[request.connection] = deque()
            self._turns.append(request.connection)
        waiting.append(request)

    def _next_batch(self, limit: int) -> list[_Request]:
        """Up to ``limit`` requests, one connection after the other in rotation (in order within each).

        A client with one command waits for at most one command of each other client, however many
        those have queued.
        """
        batch: list[_Request] = []
        while len(batch) < limit and self._turns:
            connection = self._turns.popleft()
            waiting = self._queues.get(connection)
            if connection.closed or not waiting:
                self._queues.pop(connection, None)  # a closed client's commands are not worth running
                continue
            batch.append(waiting.popleft())
            if waiting:
                self._turns.append(connection)
            else:
                del self._queues[connection]
        return batch

    def process_pending(self, budget_s: float = 0.001, chunk: int = 8) -> int:
        """Between frames: answer queued commands for at most about ``budget_s`` (at least one batch of
        ``chunk``, so that nobody waits forever); the rest next frame."""
        start = time.perf_counter()
        self.next_frame()
        self._collect()
        answered = 0
        while True:
            batch = self._next_batch(chunk)
            if not batch:
                break
            self._answer(batch)
            answered += len(batch)
            if time.perf_counter() - start >= budget_s:
                break
        return answered

    def _answer(self, requests: list[_Request]) -> None:
        try:
            results = self.router.handle_batch([r.command for r in requests])
        except Exception as exc:  # noqa: BLE001 - a bug in a handler answers errors, the program goes on
            log.exception("debug commands failed")
            results = [(True, f"internal error in the debug server: {type(exc).__name__}: {exc}")] * len(requests)
        loop = self._loop
        per_connection: dict[Session, list[tuple[int, bytes]]] = {}
        for request, (is_error, payload) in zip(requests, results):
            data = self.encode(request.command, is_error, payload)
            if not request.connection.closed:
                per_connection.setdefault(request.connection, []).append((request.sequence, data))
        if loop is not None and per_connection:
            loop.call_soon_threadsafe(self._deliver, per_connection)  # one wake-up of the network thread per batch
        self.answered += len(requests)

    @staticmethod
    def encode(command: Command, is_error: bool, payload: str | bytes) -> bytes:
        """The bytes of one answer."""
        if is_error:
            return answer_bytes(f"error: {payload}")
        if isinstance(payload, bytes) and not command.base64_answer:
            return answer_bytes(f"error: {command.name} answers with bytes; send +{command.name} for base64")
        return answer_bytes(payload, base64_answer=command.base64_answer)

    @staticmethod
    def _deliver(per_connection: dict[Session, list[tuple[int, bytes]]]) -> None:
        for connection, answers in per_connection.items():
            for _ in answers:
                connection.answered()
            connection.deliver_many(answers)

    def dispatch_forever(self, stop: Any, timeout: float = 0.1, chunk: int = 32) -> None:
        """For contexts in other processes: answer batches as they come until ``stop`` is set."""
        while not stop.is_set():
            self.next_frame()
            self._collect(wait=timeout)
            batch = self._next_batch(chunk)
            if batch:
                self._answer(batch)

    def serve_while_idle(self, seconds: float, reserve: float = 0.002, share: float = 0.25) -> None:
        """Between frames, while the loop would sleep anyway: answer commands as they arrive.

        Works in small batches for at most ``share`` of the idle time and stops ``reserve`` seconds
        before the next frame, so frames keep their rate however hard clients push: a flooding client
        gets its answers more slowly instead.
        """
        start = time.perf_counter()
        deadline = start + seconds
        work_until = min(deadline - reserve, start + seconds * share)
        while True:
            now = time.perf_counter()
            if now >= deadline:
                return
            if now >= work_until or not self._queues:
                self._collect(wait=max(0.0, min(deadline - now, 0.05)))
                if time.perf_counter() >= work_until:
                    time.sleep(max(0.0, deadline - time.perf_counter()))
                    return
            batch = self._next_batch(8)
            if batch:
                self._answer(batch)
            self._collect()
