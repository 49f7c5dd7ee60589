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
import queue
import threading
import time
from collections import deque
from typing import Any

from tafel.core.runtime import name_os_thread
from tafel.debug.protocol import ParseError, answer_bytes, encode_answer, parse
from tafel.debug.router import DebugRouter
from tafel.debug.session import (
    FRAME_WAIT,
    IDLE_TIMEOUT,
    LOOPBACK_RESERVE,
    MAX_BYTES_PER_FRAME,
    MAX_CONNECTIONS,
    MAX_OUTPUT,
    NETWORK_S_PER_FRAME,
    RESOURCE_LOG_INTERVAL,
    Session,
    _Connection,
    _InProcessClient,
    _Request,
    is_loopback,
    log,
)


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
        self._frames = 0  # frames started: the owning thread counts, the network thread reads
        self._spent_frame = 0  # the frame ``_spent_s`` belongs to
        self._spent_s = 0.0  # network thread's time on lines in that frame
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
            data = encode_answer(command, is_error, payload)
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

    @property
    def loop(self) -> asyncio.AbstractEventLoop | None:
        """The network thread's event loop while the server runs (None before and after)."""
        return self._loop

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

    def spend_network_time(self, seconds: float) -> bool:
        """Network thread: count ``seconds`` spent on lines in this frame; True once its share (``NETWORK_S_PER_FRAME``)
        is used up, and the client should wait for the next frame."""
        if self._spent_frame != self._frames:
            self._spent_frame, self._spent_s = self._frames, 0.0
        self._spent_s += seconds
        return self._spent_s > NETWORK_S_PER_FRAME

    def next_frame(self) -> None:
        """A frame starts: clients that used up their bytes may be read again. Costs nothing when none did."""
        self._frames += 1
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
            data = encode_answer(request.command, is_error, payload)
            if not request.connection.closed:
                per_connection.setdefault(request.connection, []).append((request.sequence, data))
        if loop is not None and per_connection:
            loop.call_soon_threadsafe(self._deliver, per_connection)  # one wake-up of the network thread per batch
        self.answered += len(requests)

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
