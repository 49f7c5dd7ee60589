"""``tafel run --ready-file`` and systemd's READY=1: the program says it runs once each context ran a
frame, so that a deploy never judges a start by a timer."""

from __future__ import annotations

import os
import signal
import socket
import subprocess
import time
from collections.abc import Iterator
from pathlib import Path

import pytest

from tafel.tools.launch.readiness import Readiness, notify
from tests.test_cli_runtime import REPO, TAFEL


@pytest.fixture
def notify_socket(tmp_path: Path) -> Iterator[tuple[str, socket.socket]]:
    listener = socket.socket(socket.AF_UNIX, socket.SOCK_DGRAM)
    address = str(tmp_path / "notify")
    listener.bind(address)
    listener.settimeout(0.0)
    yield address, listener
    listener.close()


def received(listener: socket.socket) -> list[bytes]:
    messages = []
    while True:
        try:
            messages.append(listener.recv(256))
        except BlockingIOError:
            return messages


def test_it_reports_once_and_only_when_every_context_ran_a_frame(tmp_path: Path, notify_socket: tuple[str, socket.socket]) -> None:
    address, listener = notify_socket
    ready = tmp_path / "tafel.ready"
    readiness = Readiness(ready, address)
    readiness.check({})
    readiness.check({"cognition": 0, "motion": 5})
    assert not ready.exists() and received(listener) == []
    readiness.check({"cognition": 1, "motion": 6})
    assert ready.read_text() == f"{os.getpid()}\n"
    assert received(listener) == [b"READY=1"]
    ready.unlink()
    readiness.check({"cognition": 2, "motion": 7})
    assert not ready.exists() and received(listener) == []  # once


def test_without_a_file_or_systemd_nothing_is_wanted(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv("NOTIFY_SOCKET", raising=False)
    assert not Readiness(None).wanted
    monkeypatch.setenv("NOTIFY_SOCKET", "/run/user/1000/systemd/notify")
    assert Readiness(None).wanted


def test_an_abstract_socket_gets_the_message_and_a_gone_one_loses_it_quietly(tmp_path: Path) -> None:
    name = f"tafel-test-{os.getpid()}"
    with socket.socket(socket.AF_UNIX, socket.SOCK_DGRAM) as listener:
        listener.bind("\0" + name)
        notify("@" + name, "READY=1")
        assert listener.recv(64) == b"READY=1"
    notify(str(tmp_path / "nobody-listens"), "READY=1")  # no exception: the program runs on


def test_a_stale_file_is_cleared_and_a_missing_one_is_fine(tmp_path: Path) -> None:
    stale = tmp_path / "tafel.ready"
    stale.write_text("12345\n")
    Readiness(stale).clear()
    assert not stale.exists()
    Readiness(stale).clear()
    Readiness(None).clear()
    assert list(tmp_path.iterdir()) == []


@pytest.mark.slow
@pytest.mark.parametrize("concurrent", [False, True], ids=["lockstep", "concurrent"])
def test_a_running_program_writes_its_pid_and_tells_systemd(concurrent: bool, tmp_path: Path,
                                                            notify_socket: tuple[str, socket.socket]) -> None:
    address, listener = notify_socket
    ready = tmp_path / "tafel.ready"
    ready.write_text("12345\n")  # from an earlier run: must not announce this one
    process = subprocess.Popen([*TAFEL, "run", "--platform", "dummy", "--no-debug", "--ready-file", str(ready),
                                *(["--concurrent"] if concurrent else [])],
                               cwd=REPO, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                               env={**os.environ, "PYTHONPATH": str(REPO), "NOTIFY_SOCKET": address})
    try:
        deadline = time.monotonic() + 60
        while not (ready.exists() and ready.read_text() == f"{process.pid}\n"):
            assert process.poll() is None, process.communicate()
            assert time.monotonic() < deadline, "no ready file"
            time.sleep(0.1)
        assert received(listener) == [b"READY=1"]
    finally:
        process.send_signal(signal.SIGINT)
        out, err = process.communicate(timeout=30)
    assert process.returncode == 0, err
    assert "cognition:" in out and "motion:" in out


@pytest.mark.slow
def test_a_program_that_cannot_start_removes_a_stale_file_and_reports_nothing(tmp_path: Path,
                                                                                notify_socket: tuple[str, socket.socket]) -> None:
    address, listener = notify_socket
    ready = tmp_path / "tafel.ready"
    ready.write_text("12345\n")
    result = subprocess.run([*TAFEL, "run", "--platform", "dummy", "--no-debug", "--ready-file", str(ready),
                             "--set", "runtime.motion_hz=-5"], cwd=REPO, capture_output=True, text=True, timeout=60,
                            env={**os.environ, "PYTHONPATH": str(REPO), "NOTIFY_SOCKET": address})
    assert result.returncode != 0 and "motion_hz" in result.stderr
    assert not ready.exists()
    assert received(listener) == []
