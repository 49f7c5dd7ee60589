"""Just enough of ``systemctl --user`` for the deploy tests, where no systemd runs: ``daemon-reload``,
``restart``, ``stop`` and ``is-active`` of units in ``$HOME/.config/systemd/user``, started as systemd
starts them: ``Type=simple`` counts as started at once; ``Type=notify`` only when the program sends
``READY=1`` to ``$NOTIFY_SOCKET`` within ``TimeoutStartSec``, else ``restart`` fails (exit 1).

Called through a ``systemctl`` shell wrapper on ``PATH`` that runs this file with the tests' Python."""

from __future__ import annotations

import os
import shlex
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

UNITS = Path(os.environ["HOME"]) / ".config" / "systemd" / "user"


def settings(unit: str) -> dict[str, str]:
    """The ``[Service]`` keys of a unit file."""
    found: dict[str, str] = {}
    for line in (UNITS / unit).read_text().splitlines():
        key, sep, value = line.partition("=")
        if sep and not line.startswith("#"):
            found[key.strip()] = value.strip()
    return found


def pid_of(unit: str) -> int | None:
    path = UNITS / f"{unit}.pid"
    if not path.exists():
        return None
    pid = int(path.read_text())
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return None
    return pid


def stop(unit: str) -> int:
    pid = pid_of(unit)
    if pid is not None:
        os.kill(pid, signal.SIGTERM)
        deadline = time.monotonic() + 15
        while pid_of(unit) is not None and time.monotonic() < deadline:
            time.sleep(0.05)
        if pid_of(unit) is not None:
            os.kill(pid, signal.SIGKILL)
    (UNITS / f"{unit}.pid").unlink(missing_ok=True)
    return 0


def restart(unit: str) -> int:
    stop(unit)
    service = settings(unit)
    address = f"@fake-systemd-{os.getpid()}-{unit}"  # abstract, as systemd's own: no path length limit
    with socket.socket(socket.AF_UNIX, socket.SOCK_DGRAM) as listener:
        listener.bind("\0" + address[1:])
        listener.settimeout(0.1)
        with open(UNITS / f"{unit}.log", "ab") as log:
            program = subprocess.Popen(shlex.split(service["ExecStart"]), cwd=service.get("WorkingDirectory"), stdout=log,
                                       stderr=log, stdin=subprocess.DEVNULL, start_new_session=True,
                                       env={**os.environ, "NOTIFY_SOCKET": address})
        (UNITS / f"{unit}.pid").write_text(str(program.pid))
        if service.get("Type", "simple") != "notify":
            return 0
        deadline = time.monotonic() + float(service.get("TimeoutStartSec", "90"))
        while time.monotonic() < deadline:
            try:
                if listener.recv(256) == b"READY=1":
                    return 0
            except TimeoutError:
                pass
            if program.poll() is not None:
                break
        stop(unit)
        print(f"Job for {unit} failed because the control process exited with error code.", file=sys.stderr)
        return 1


def main(arguments: list[str]) -> int:
    words = [word for word in arguments if word not in ("--user", "--quiet")]
    if words == ["daemon-reload"]:
        return 0
    command, unit = words
    if command == "restart":
        return restart(unit)
    if command == "stop":
        return stop(unit)
    if command == "is-active":
        return 0 if pid_of(unit) is not None else 3
    print(f"fake systemctl: {command} is not faked", file=sys.stderr)
    return 1


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
