"""A debug-server attack as the security issue describes it, for the stress test and ``benchmarks/debug_attack.py``.

All at once against one running program on loopback: clients pipelining commands, one client
streaming bytes without a newline, connections beyond the limit, an HTTP POST whose body would
record over a file, and one whose request line is longer than a command line may be (it once arrived
as "too long" and its body ran); with a Foxglove server, a page of another site and a DNS-rebinding
host asking for its WebSocket; and log bombs read beside the program. Every loop is bounded in count
and time, and everything stops by itself.
"""

from __future__ import annotations

import re
import socket
import subprocess
import sys
import threading
import time
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path

import pytest

from tests.support.cpu_use import CpuUse

#: commands the pipelining clients send, round and round
PIPELINED = ("ping", "modules:list", "representation:print FrameInfo", "stopwatch:list", "debug_request:list", "help")


@dataclass
class AttackReport:
    answers: int = 0  # answers the pipelining clients received
    streamed_bytes: int = 0  # bytes the streaming client got through
    refused: int = 0  # connections over the limit that were answered with an error and closed
    over_limit_open: int = 0  # connections over the limit that stayed open (should be none)
    http_answered: bool = False  # the POST got anything back (it should not)
    long_http_answered: bool = False  # the POST with a request line over 64 KiB got anything back (it should not)
    #: a page of another origin and a DNS-rebinding host asking the Foxglove server for a WebSocket: how each
    #: was answered ("refused 403" and the like; "connected" would be a hole); empty without a Foxglove server
    foxglove: dict[str, str] = field(default_factory=dict)
    #: each log bomb read by ``tafel log info`` while the attack ran: exit status and peak memory (MB)
    bombs: list[tuple[int, float]] = field(default_factory=list)
    errors: list[str] = field(default_factory=list)


class Attack:
    """Start with ``start()``, end with ``stop()``, which returns what happened."""

    def __init__(self, host: str, port: int, *, pipelining_clients: int = 20, stream_bytes: int = 50 << 20,
                 extra_connections: int = 40, limit: int = 32, http_victim: str = "/tmp/tafel-attack-victim.txt",
                 foxglove_port: int | None = None, bombs: Sequence[Path] = ()) -> None:
        self.host, self.port = host, port
        self.foxglove_port = foxglove_port
        self.bombs = list(bombs)
        self.pipelining_clients = pipelining_clients
        self.stream_bytes = stream_bytes
        self.extra_connections = extra_connections
        self.limit = limit
        self.http_victim = http_victim
        self.report = AttackReport()
        self._stop = threading.Event()
        self._lock = threading.Lock()
        self._threads: list[threading.Thread] = []
        self._held: list[socket.socket] = []

    def _connect(self) -> socket.socket:
        return socket.create_connection((self.host, self.port), timeout=10)

    def start(self) -> None:
        targets = [self._pipeline] * self.pipelining_clients + [self._stream]
        for target in targets:
            thread = threading.Thread(target=target, daemon=True)
            thread.start()
            self._threads.append(thread)
        time.sleep(0.5)  # the attack's own clients are in
        self._http_post()
        self._long_http_post()
        if self.foxglove_port is not None:
            self._foreign_foxglove_clients()
        for bomb in self.bombs:
            thread = threading.Thread(target=self._read_bomb, args=(bomb,), daemon=True)
            thread.start()
            self._threads.append(thread)
        self._fill_to_limit(self.limit - self.pipelining_clients - 1)
        self._over_limit()

    def stop(self) -> AttackReport:
        self._stop.set()
        for thread in self._threads:
            thread.join(timeout=15)
        for held in self._held:
            held.close()
        return self.report

    def _pipeline(self) -> None:
        try:
            with self._connect() as connection:
                connection.settimeout(5)
                burst = "".join(f"{c}\n" for c in PIPELINED * 5).encode()
                buffer = b""
                while not self._stop.is_set():
                    connection.sendall(burst)
                    wanted = len(PIPELINED) * 5
                    while wanted and not self._stop.is_set():
                        chunk = connection.recv(1 << 16)
                        if not chunk:
                            return
                        buffer += chunk
                        count = buffer.count(b"\0")
                        if count:
                            buffer = buffer[buffer.rindex(b"\0") + 1:]
                            wanted -= count
                            with self._lock:
                                self.report.answers += count
        except OSError as exc:
            if not self._stop.is_set():
                self.report.errors.append(f"pipelining client: {exc}")

    def _stream(self) -> None:
        block = b"x" * (1 << 16)
        try:
            with self._connect() as connection:
                while self.report.streamed_bytes < self.stream_bytes and not self._stop.is_set():
                    connection.sendall(block)
                    self.report.streamed_bytes += len(block)
        except OSError as exc:
            if not self._stop.is_set():
                self.report.errors.append(f"streaming client: {exc}")

    def _fill_to_limit(self, count: int) -> None:
        """Idle connections up to the limit, held open: every further one is over it."""
        for _ in range(max(0, count)):
            try:
                connection = self._connect()
                connection.settimeout(0.3)
                connection.recv(1)  # an accepted connection says nothing
                connection.close()  # it said something: it was refused (someone else holds a place)
            except TimeoutError:
                self._held.append(connection)
            except OSError as exc:
                self.report.errors.append(f"connection up to the limit: {exc}")

    def _over_limit(self) -> None:
        for _ in range(self.extra_connections):
            try:
                connection = self._connect()
            except OSError as exc:
                self.report.errors.append(f"connection over the limit: {exc}")
                continue
            connection.settimeout(3)
            try:
                data = connection.recv(4096)
            except TimeoutError:
                self.report.over_limit_open += 1
                self._held.append(connection)
                continue
            except OSError:
                data = b""
            if data.startswith(b"error:"):
                self.report.refused += 1
            connection.close()

    def _http_post(self) -> None:
        body = f"\nlog:start -file {self.http_victim}\n".encode()
        request = (b"POST / HTTP/1.1\r\nHost: 127.0.0.1\r\nContent-Type: text/plain\r\n"
                   + f"Content-Length: {len(body)}\r\n\r\n".encode() + body)
        try:
            with self._connect() as connection:
                connection.settimeout(3)
                connection.sendall(request)
                try:
                    self.report.http_answered = bool(connection.recv(4096))
                except TimeoutError:
                    self.report.http_answered = True  # kept open: it was not closed at once
                except OSError:
                    pass
        except OSError as exc:
            self.report.errors.append(f"http client: {exc}")


    def _long_http_post(self) -> None:
        """A browser's POST from a page of another origin, its request line over 64 KiB; the body would record."""
        body = b"\nlog:start -file posted.mcap\n"
        request = (b"POST /?" + b"a" * (70 * 1024) + b" HTTP/1.1\r\nHost: 127.0.0.1\r\nOrigin: http://evil.example\r\n"
                   + f"Content-Type: text/plain\r\nContent-Length: {len(body)}\r\n\r\n".encode() + body)
        try:
            with self._connect() as connection:
                connection.settimeout(3)
                try:
                    connection.sendall(request)
                    self.report.long_http_answered = bool(connection.recv(4096))
                except TimeoutError:
                    self.report.long_http_answered = True  # kept open: it was not closed at once
                except OSError:
                    pass  # reset while sending or reading: closed, as it should be
        except OSError as exc:
            self.report.errors.append(f"long http client: {exc}")


    def _foreign_foxglove_clients(self) -> None:
        """A page of another site, and a page that rebinds its DNS name to 127.0.0.1, asking for the Foxglove
        server's WebSocket (which runs /tafel/command): both must be refused before the handshake ends."""
        from websockets.exceptions import InvalidStatus
        from websockets.sync.client import connect

        url = f"ws://{self.host}:{self.foxglove_port}/"
        for name, headers in (("foreign_origin", {"Origin": "http://evil.example"}),
                              ("rebinding_host", {"Host": f"evil.example:{self.foxglove_port}", "Origin": f"http://evil.example:{self.foxglove_port}"})):
            try:
                with connect(url, subprotocols=["foxglove.sdk.v1"], additional_headers=headers, open_timeout=5):
                    self.report.foxglove[name] = "connected"
            except InvalidStatus as exc:
                self.report.foxglove[name] = f"refused {exc.response.status_code}"
            except (OSError, TimeoutError) as exc:
                self.report.foxglove[name] = f"closed ({type(exc).__name__})"

    def _read_bomb(self, bomb: Path) -> None:
        """``tafel log info`` on a log bomb, beside the program: it must not take the machine's memory."""
        script = ("import resource, subprocess, sys; r = subprocess.run([sys.executable, '-m', 'tafel.tools.cli', 'log', 'info', "
                  f"{str(bomb)!r}], capture_output=True); "
                  "print(r.returncode, resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss)")
        try:
            done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=120)
            code, peak_kb = done.stdout.split()
            with self._lock:
                self.report.bombs.append((int(code), int(peak_kb) / 1024))
        except (subprocess.TimeoutExpired, ValueError) as exc:
            self.report.errors.append(f"bomb {bomb.name}: {exc}")


STATUS_RATE = re.compile(r"(cognition|motion) ([\d.]+) Hz")


def status_rates(lines: list[str]) -> dict[str, list[float]]:
    """Each context's rates from the program's status lines (its own count over each interval)."""
    rates: dict[str, list[float]] = {"cognition": [], "motion": []}
    for line in lines:
        if line.startswith("[tafel]"):
            for name, value in STATUS_RATE.findall(line):
                rates[name].append(float(value))
    return rates


def rates_during(errors: list[str], seconds: float, forgive: int = 0) -> dict[str, float]:
    """The lowest rate of each context over the status lines printed in the next ``seconds``, leaving
    out the ``forgive`` lowest (one slow second of a noisy machine is not a slowdown).

    The first line after the start is skipped: its interval began before.
    """
    start = len(errors)
    time.sleep(seconds)
    rates = status_rates(errors[start:])
    return {name: sorted(values[1:])[forgive] if len(values) > 1 + forgive else float("nan") for name, values in rates.items()}


def loop_frames(stopwatches: str) -> dict[str, int]:
    """Each context's frame count from ``stopwatch:list``'s answer (its ``[context]`` headings and ``loop:`` lines)."""
    return {context: int(frame) for context, frame in re.findall(r"\[(\w+)\]\nloop: [\d.]+ Hz, frame (\d+)", stopwatches)}


#: cores a machine must have idle, on average, under a load for the program's rates under it to say something
MIN_IDLE_CORES = 0.25
#: share of its core the program's busiest process may use without a load for its rates under one to say something
MAX_BUSY_CORES = 0.8

#: Hz each loop keeps on a machine with room for the program: the beats (100 and 30 Hz) less a little slack
BEATS = {"motion": 95.0, "cognition": 28.0}


def skip_without_headroom(unloaded: dict[str, float], load: str, unloaded_use: CpuUse | None = None,
                          loaded_use: CpuUse | None = None) -> None:
    """Skip what is left of a test that judges whether ``load`` slows the loops where the machine leaves the
    program no room for it, with the reason and figures:

    - the program missed its beat without the load (``unloaded``: rates measured just before, in the same run);
    - its busiest process used more than ``MAX_BUSY_CORES`` of its core without the load (``unloaded_use``): a
      load bounded to a share of the loops' time (the debug server's budgets) would still push it over;
    - the machine had less than ``MIN_IDLE_CORES`` idle under the load (``loaded_use``): the load's own clients
      and log readers ran on the program's machine (on a robot they would be elsewhere) and took its share.
    """
    short = {name: round(rate, 1) for name, rate in unloaded.items() if rate < BEATS.get(name, 0.0)}
    if short:
        pytest.skip(f"the program misses its beat on this machine ({short} Hz, beats {BEATS}): "
                    f"its rates under {load} cannot be judged here")
    if unloaded_use is not None and unloaded_use.busiest_process_cores > MAX_BUSY_CORES:
        pytest.skip(f"the program keeps its beat with no room to spare on this machine ({unloaded_use}; at most "
                    f"{MAX_BUSY_CORES} of a core leaves room for {load}): its rates under {load} cannot be judged here")
    if loaded_use is not None and loaded_use.machine_idle_cores < MIN_IDLE_CORES:
        pytest.skip(f"the machine's cores were used up under {load} ({loaded_use}; at least {MIN_IDLE_CORES} idle "
                    f"leave the program its share): its rates under {load} cannot be judged here")
