"""Attacks on the debug server, as the security issue reproduces them: the program holds."""

from __future__ import annotations

import json
import socket
import time
from pathlib import Path

import pytest

from tests.test_debug_server import Program


@pytest.fixture
def program(tmp_path: Path):
    running = Program("--platform", "dummy", cwd=tmp_path)
    yield running
    running.stop()


def test_an_http_post_runs_nothing_and_is_closed(program: Program, tmp_path: Path) -> None:
    victim = tmp_path / "victim.txt"
    victim.write_text("precious\n")
    body = f"\nlog:start -file {victim}\n".encode()
    request = (b"POST / HTTP/1.1\r\nHost: 127.0.0.1\r\nContent-Type: application/x-www-form-urlencoded\r\n"
               + f"Content-Length: {len(body)}\r\n\r\n".encode() + body)
    with socket.create_connection((program.host, program.port), timeout=5) as connection:
        connection.sendall(request)
        received = b""
        deadline = time.monotonic() + 5
        while time.monotonic() < deadline:
            chunk = connection.recv(4096)
            if not chunk:
                break  # closed by the server
            received += chunk
    assert received == b"", received  # not one answer: the connection was closed at once
    assert victim.read_text() == "precious\n"
    assert json.loads(program.ask("log:status"))["recording"] is False
    time.sleep(0.3)
    assert any("speaks HTTP" in line for line in program.errors)


@pytest.mark.parametrize("name", ["../escape.mcap", "/tmp/absolute.mcap", "sub/dir.mcap", "..", "notes.txt"])
def test_log_start_refuses_names_that_leave_the_recordings_folder(program: Program, tmp_path: Path, name: str) -> None:
    answer = program.ask(f'log:start -file "{name}"')
    assert answer.startswith("error:") and ("plain file name" in answer or "MCAP files" in answer), answer
    assert not (tmp_path / "escape.mcap").exists() and not Path("/tmp/absolute.mcap").exists()


def test_log_start_records_into_the_recordings_folder(program: Program, tmp_path: Path) -> None:
    answer = program.ask("log:start -file run1.mcap")
    assert answer == f"recording to {tmp_path / 'logs' / 'run1.mcap'}"
    time.sleep(0.3)
    assert "stopped recording" in program.ask("log:stop")
    assert (tmp_path / "logs" / "run1.mcap").stat().st_size > 0


def test_the_recordings_folder_is_chosen_with_record_dir(tmp_path: Path) -> None:
    running = Program("--platform", "dummy", "--record-dir", str(tmp_path / "recordings"), cwd=tmp_path)
    try:
        assert running.ask("log:start -file a.mcap") == f"recording to {tmp_path / 'recordings' / 'a.mcap'}"
        running.ask("log:stop")
    finally:
        running.stop()
