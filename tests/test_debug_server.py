"""The debug server end to end: a running ``tafel run``, real sockets, every command, bad clients."""

from __future__ import annotations

import base64
import dataclasses
import json
import os
import random
import re
import shutil
import socket
import subprocess
import sys
import threading
import time
from collections.abc import Iterator
from pathlib import Path

import pytest

from tafel.core.framework.config import load_config
from tafel.core.logs import read_log
from tafel.core.logs.serialization import deserialize
from tafel.debug.client import DebugClient
from tafel.debug.router import DebugRouter
from tafel.debug.server import DebugServer
from tafel.debug.session import NETWORK_S_PER_FRAME
from tafel.modules.modeling.kalman_ball_modeler import KalmanBallModeler
from tafel.representations.modeling import BallModel
from tests.support.processes import stop_program
from tests.test_cli_runtime import REPO, tafel

DEBUG_USER = "tests.support.debug_user:DebugUser"


class Program:
    """A ``tafel run`` subprocess with its debug server address."""

    def __init__(self, *args: str, cwd: Path = REPO) -> None:
        self.cwd = cwd  # where the program runs: its recordings folder lies below it
        self.process = subprocess.Popen(
            [sys.executable, "-m", "tafel.tools.cli", "run", "--debug-port", "0", *args]
            + ([] if "--platform" in args else ["--platform", "dummy"])
            + ([] if {"--web-port", "--no-web", "--no-debug"} & set(args) else ["--web-port", "0"]),  # several may run at once
            cwd=cwd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
            env={**os.environ, "PYTHONPATH": str(REPO)},
        )
        line = self.process.stdout.readline()
        match = re.match(r"debug server listening on ([\d.]+):(\d+)", line)
        assert match, line + self.process.stderr.read()
        self.host, self.port = match.group(1), int(match.group(2))
        # Keep reading the program's output, as a terminal would, so it never blocks on a full pipe.
        self.output: list[str] = []
        self.errors: list[str] = []
        self.readers = [threading.Thread(target=self._drain, args=(stream, sink), daemon=True)
                        for stream, sink in ((self.process.stdout, self.output), (self.process.stderr, self.errors))]
        for reader in self.readers:
            reader.start()

    @staticmethod
    def _drain(stream, sink: list[str]) -> None:
        for line in stream:
            sink.append(line)

    def client(self) -> DebugClient:
        return DebugClient(self.host, self.port)

    def ask(self, line: str) -> str:
        with self.client() as client:
            return client.ask(line)

    def stop(self) -> tuple[str, str]:
        return stop_program(self.process, self.readers, self.output, self.errors)


@pytest.fixture(scope="module")
def config_dir(tmp_path_factory) -> Path:
    """A copy of the configuration, so that *:store commands write into a private layer of the test's own."""
    target = tmp_path_factory.mktemp("config") / "config"
    shutil.copytree(REPO / "config", target, ignore=shutil.ignore_patterns("private"))
    return target


@pytest.fixture(scope="module")
def program(config_dir: Path) -> Iterator[Program]:
    running = Program("--config", str(config_dir), "--set",
                      f'cognition.modules=["KalmanBallModeler", "SimpleBallModeler", "LookAtBallBehavior", "Striker", "{DEBUG_USER}"]',
                      cwd=config_dir.parent)  # recordings go into logs/ there
    yield running
    out, err = running.stop()
    assert running.process.returncode == 0, err


def frame_of(program: Program, context: str = "cognition") -> int:
    """The frame number a context's platform reported last."""
    answer = program.ask(f"representation:print FrameInfo -context {context}")
    return int(re.search(r"frame_number: (\d+)", answer).group(1))


def test_help_lists_every_command_with_a_description(program: Program) -> None:
    answer = program.ask("help")
    for name in ("help", "ping", "auth", "modules:list", "modules:set", "modules:provider", "modules:store", "modules:graph",
                 "representation:list", "representation:print", "representation:get", "representation:set",
                 "debug_request:list", "debug_request:set", "modify:list", "modify:set", "modify:release",
                 "stopwatch:list", "plot:get", "drawings:get", "parameter:list", "parameter:get", "parameter:set",
                 "parameter:store", "log:start", "log:stop", "log:status"):
        assert re.search(rf"^{re.escape(name)}\s+\S", answer, re.MULTILINE), name
    assert "usage: modules:set -module NAME -enabled true|false" in program.ask("help modules:set")
    assert program.ask("help modules:sett").startswith("error: unknown command 'modules:sett': did you mean 'modules:set'")


def test_ping_and_base64_answers(program: Program) -> None:
    assert program.ask("ping") == "pong"
    assert base64.b64decode(program.ask("+ping")) == b"pong"


def test_modules_list_set_and_provider(program: Program) -> None:
    listing = program.ask("modules:list")
    assert "[cognition]" in listing and "[motion]" in listing
    assert re.search(r"KalmanBallModeler\s+on\s+running\s+mean\s+[\d.]+ us\s+max", listing)
    assert "provider BallModel: KalmanBallModeler (alternatives: KalmanBallModeler, SimpleBallModeler)" in listing
    assert "SimpleBallModeler is provided" not in program.ask("modules:provider -representation BallModel -module SimpleBallModeler")
    assert "provider BallModel: SimpleBallModeler" in program.ask("modules:list")
    assert program.ask("modules:set -module KalmanBallModeler -enabled false").startswith("KalmanBallModeler disabled in cognition")
    assert "KalmanBallModeler            off" in program.ask("modules:list")
    refused = program.ask("modules:set -module SimpleBallModeler -enabled false")
    assert refused.startswith("error: LookAtBallBehavior requires BallModel")  # the graph would break: nothing changed
    assert program.ask("modules:set -module KalmanBallModeler -enabled true").startswith("KalmanBallModeler enabled")
    assert program.ask("modules:provider -representation BallModel -module KalmanBallModeler") == "BallModel is provided by KalmanBallModeler in cognition"
    assert program.ask("modules:set -module KalmanBallModeller -enabled true").startswith("error: unknown module 'KalmanBallModeller': did you mean 'KalmanBallModeler'")
    assert program.ask("modules:set -module KalmanBallModeler -enabled maybe") == "error: -enabled takes on/off or true/false, got 'maybe'"


def test_modules_store_writes_the_private_layer(program: Program, config_dir: Path) -> None:
    program.ask("modules:provider -representation BallModel -module SimpleBallModeler")
    answer = program.ask("modules:store")
    assert answer.startswith("stored in") and "cognition.providers.BallModel=SimpleBallModeler" in answer
    private = (config_dir / "private" / "private.toml").read_text()
    assert 'BallModel = "SimpleBallModeler"' in private
    program.ask("modules:provider -representation BallModel -module KalmanBallModeler")


@pytest.mark.slow
def test_modules_store_keeps_only_the_choices_made_at_run_time(tmp_path: Path) -> None:
    """On dummy, whose layer disables the perception, the stored layer holds only what the user switched:
    the next start on another platform keeps its perception (a new user's report)."""
    config = tmp_path / "config"
    shutil.copytree(REPO / "config", config, ignore=shutil.ignore_patterns("private"))
    running = Program("--config", str(config), cwd=tmp_path)
    try:
        assert running.ask("modules:store").startswith("nothing to store")
        assert running.ask("modules:set -module GameControllerReporter -enabled false").startswith("GameControllerReporter disabled")
        assert "cognition.disable=['GameControllerReporter']" in running.ask("modules:store")
        assert load_config(config, "mujoco")["cognition"]["disabled"] == ["GameControllerReporter"]  # no SelfLocator
        assert {"SelfLocator", "GameControllerReporter"} <= set(load_config(config, "dummy")["cognition"]["disabled"])
        running.ask("modules:set -module GameControllerReporter -enabled true")
        running.ask("modules:store")  # switched back: the layer is as it was
        assert load_config(config, "mujoco")["cognition"]["disabled"] == []
    finally:
        running.stop()


def test_modules_graph_is_dot_with_the_hand_over(program: Program) -> None:
    graph = program.ask("modules:graph")
    assert graph.startswith("digraph tafel {") and '"cognition:HeadMotionRequest" -> "motion:HeadMotionRequest"' in graph


def test_representations_list_print_get_set(program: Program) -> None:
    listing = program.ask("representation:list")
    assert re.search(r"BallModel\s+KalmanBallModeler", listing) and "JointSensorData" in listing
    assert "error: representation:get: the name exists in cognition and motion; add -context NAME" == program.ask("+representation:get -name FrameInfo")
    assert program.ask("representation:print FrameInfo -context vision") == "error: -context takes cognition or motion, got 'vision'"
    printed = program.ask("representation:print BallModel")
    assert printed.startswith("BallModel (cognition, frame") and "  valid: " in printed and "  x: " in printed
    model = deserialize(BallModel, base64.b64decode(program.ask("+representation:get -name BallModel")))
    assert isinstance(model, BallModel)
    assert "send +representation:get for base64" in program.ask("representation:get -name BallModel")
    assert program.ask("representation:set -name HeadMotionRequest -context cognition -field max_speed -value 1.25") == "HeadMotionRequest.max_speed = 1.25"
    assert program.ask("representation:set -name BallModel -field nope -value 1").startswith("error: BallModel has no field 'nope'")
    data = base64.b64encode(base64.b64decode(program.ask("+representation:get -name FrameInfo -context motion"))).decode()
    assert program.ask(f"representation:set -name FrameInfo -context motion +data {data}").startswith("FrameInfo set from")
    assert program.ask("representation:print BallModle").startswith("error: unknown representation 'BallModle': did you mean 'BallModel'")


def test_debug_requests_drawings_modify_plots_stopwatches(program: Program) -> None:
    assert "off DebugUser:draw  a circle on the field every frame" in program.ask("debug_request:list")
    assert program.ask("drawings:get -canvas field") == ""
    assert program.ask("debug_request:set -name DebugUser:draw -value on") == "DebugUser:draw on"
    time.sleep(0.3)
    drawings = [json.loads(line) for line in program.ask("drawings:get -canvas field").splitlines()]
    assert drawings == [{"context": "cognition", "canvas": "field", "kind": "circle", "points": [100.0, 200.0, 50.0], "color": "orange", "width": 2.0, "text": ""}]
    assert json.loads(program.ask("drawings:get -canvas image:top"))["text"].startswith("frame ")
    program.ask("debug_request:set -name DebugUser:draw -value off")

    assert "DebugUser:gain = 1" in program.ask("modify:list")
    assert program.ask("modify:set -name DebugUser:gain -value 0") == "DebugUser:gain pinned to 0"
    time.sleep(0.3)
    assert "value: 0" in program.ask("representation:print DebugUserOutput")
    assert "(pinned to 0)" in program.ask("modify:list")
    assert program.ask("modify:release -name DebugUser:gain") == "DebugUser:gain released"
    time.sleep(0.3)
    assert "value: 0\n" not in program.ask("representation:print DebugUserOutput") + "\n"
    assert program.ask("modify:set -name DebugUser:gain -value abc") == "error: DebugUser:gain takes a finite number of at most 1e+12 in size, got 'abc'"

    frames = [line.split() for line in program.ask("plot:get -name DebugUser:frame -count 5").splitlines()]
    assert len(frames) == 5 and all(int(frame) == float(value) for frame, value in frames)
    assert "DebugUser:frame" in program.ask("plot:get")
    watches = program.ask("stopwatch:list")
    assert re.search(r"loop: [\d.]+ Hz", watches) and "DebugUser:work" in watches and "p95" in watches
    assert re.search(r"DebugUser\s+[\d.]+\s+[\d.]+\s+[\d.]+\s+[\d.]+", watches)


def test_parameters_list_get_set_store(program: Program, config_dir: Path) -> None:
    assert "KalmanBallModeler: acceleration_noise=1500" in program.ask("parameter:list")
    assert "friction = 0.5" in program.ask("parameter:get -module KalmanBallModeler")
    assert program.ask("parameter:set -module KalmanBallModeler -name friction -value 0.25") == "KalmanBallModeler.friction = 0.25"
    assert "friction = 0.25" in program.ask("parameter:get -module KalmanBallModeler")
    assert program.ask("parameter:set -module KalmanBallModeler -name friction -value fast").startswith(
        "error: parameter KalmanBallModeler.friction takes a finite number of at most 1e+12 in size, got 'fast'")
    assert program.ask("parameter:set -module KalmanBallModeler -name frcition -value 1").startswith(
        "error: KalmanBallModeler has no parameter 'frcition'; did you mean 'friction'")
    assert program.ask("parameter:store -module KalmanBallModeler").startswith(f"stored {len(dataclasses.fields(KalmanBallModeler.Parameters))} parameters of KalmanBallModeler")
    assert "friction = 0.25" in (config_dir / "private" / "private.toml").read_text()


def test_log_start_status_stop(program: Program, config_dir: Path) -> None:
    path = config_dir.parent / "logs" / "debug.mcap"
    assert json.loads(program.ask("log:status"))["recording"] is False
    assert program.ask("log:start -file debug.mcap") == f"recording to {path}"
    time.sleep(0.5)
    status = json.loads(program.ask("log:status"))
    assert status["recording"] and status["file"] == str(path)
    assert program.ask("log:stop").startswith(f"stopped recording {path}")
    assert program.ask("log:stop") == "error: not recording"
    assert len(read_log(path).frames("motion")) > 10


def test_errors_for_unknown_and_malformed_commands(program: Program) -> None:
    with program.client() as client:
        answers = client.ask_many(["modules:lst", 'x -a "open', "cmd +a !!!", "ping"])
    assert answers[0].startswith("error: unknown command 'modules:lst': did you mean 'modules:list'")
    assert answers[1].startswith("error: the value of -a opens a quote")
    assert answers[2].startswith("error: argument +a is not valid base64")
    assert answers[3] == "pong"


def test_telnet_negotiation_and_line_ends(program: Program) -> None:
    with socket.create_connection((program.host, program.port)) as raw:
        raw.sendall(bytes([255, 253, 1, 255, 251, 31, 255, 250, 24, 1, 255, 240]) + b"ping\r\n" + b"help ping\r\0")
        data = b""
        while data.count(b"\0") < 2:
            data += raw.recv(4096)
    answers = data.split(b"\0")
    assert answers[0] == b"pong\n" and answers[1].startswith(b"ping: answers pong")


def test_bad_clients_never_stop_the_program_or_other_clients(program: Program) -> None:
    before = frame_of(program, "cognition")
    with program.client() as watcher:
        # an overlong line, invalid UTF-8 and binary garbage get error answers and the connection goes on
        with socket.create_connection((program.host, program.port)) as raw:
            # binary garbage (seeded: the same bytes every run), without telnet's IAC, tested on its own
            garbage = random.Random(7).randbytes(2000).replace(b"\n", b"").replace(b"\r", b"").replace(b"\xff", b"")
            raw.sendall(b"x" * (70 * 1024) + b"\n" + b"\xfe\xfd garbage \xc3\x28\n" + garbage + b"\nping\n")
            data = b""
            raw.settimeout(10)
            while b"pong\n\0" not in data:
                data += raw.recv(65536)
        answers = data.split(b"\0")[:-1]
        assert answers[0].startswith(b"error: line too long")
        assert answers[1].startswith(b"error: the line is not valid UTF-8")
        assert all(answer.startswith(b"error:") for answer in answers[2:-1])
        assert answers[-1] == b"pong\n"
        # a client that disconnects in the middle of a command
        with socket.create_connection((program.host, program.port)) as raw:
            raw.sendall(b"representation:print Ball")
        # a client that sends many commands and never reads: dropped, not waited for
        hog = socket.create_connection((program.host, program.port))
        hog.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 4096)
        payload = b"modules:graph\n" * 2000
        sent = 0
        hog.settimeout(5)
        try:
            while sent < 40:
                hog.sendall(payload)
                sent += 1
        except (TimeoutError, ConnectionError, OSError):
            pass
        assert watcher.ask("ping") == "pong"
        hog.close()
        time.sleep(0.5)
        assert watcher.ask("ping") == "pong"
    assert frame_of(program, "cognition") > before  # the loops kept running
    assert program.process.poll() is None


def test_twenty_clients_pipelining_500_commands_each_get_every_answer_in_order(program: Program) -> None:
    before = frame_of(program, "motion")
    commands = []
    for i in range(500):
        commands.append(["ping", f"help {['modules:list', 'ping', 'plot:get'][i % 3]}", "representation:print FrameInfo"][i % 3])
    results: dict[int, list[str]] = {}

    def hammer(index: int) -> None:
        with program.client() as client:
            results[index] = client.ask_many(commands)

    threads = [threading.Thread(target=hammer, args=(i,)) for i in range(20)]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join(timeout=120)
    assert len(results) == 20
    for answers in results.values():
        assert len(answers) == 500
        for i, answer in enumerate(answers):
            if i % 3 == 0:
                assert answer == "pong"
            elif i % 3 == 1:
                assert answer.startswith(["modules:list:", "ping:", "plot:get:"][i % 3])
            else:
                assert answer.startswith("[cognition]\nFrameInfo (cognition") and "[motion]\nFrameInfo (motion" in answer
    assert frame_of(program, "motion") > before  # both loops kept running
    assert frame_of(program, "cognition") > 0


@pytest.mark.slow
def test_token_authentication() -> None:
    secured = Program("--debug-token", "s3cret")
    try:
        with secured.client() as client:
            assert client.ask_many(["ping", "help", "auth wrong", "ping", "auth s3cret", "ping"]) == [
                "error: not authenticated (send: auth TOKEN)", "error: not authenticated (send: auth TOKEN)",
                "error: wrong token", "error: not authenticated (send: auth TOKEN)", "authenticated", "pong"]
    finally:
        secured.stop()


@pytest.mark.slow
def test_replay_commands(tmp_path: Path) -> None:
    log = tmp_path / "replay.mcap"
    assert tafel("run", "--platform", "dummy", "--frames", "300", "--speed", "max", "--record", str(log), "--no-debug").returncode == 0
    replay = Program("--platform", "log", "--log", str(log), "--loop", "--speed", "0.2")
    try:
        assert replay.ask("log:pause") == "paused"
        time.sleep(0.2)
        frame = frame_of(replay, "motion")
        time.sleep(0.3)
        assert frame_of(replay, "motion") == frame  # paused
        assert replay.ask("log:goto -frame 100") == "seeking frame 100: replay pauses there (log:position says when)"
        time.sleep(0.3)
        assert frame_of(replay, "motion") == 100  # a seek shows the frame
        assert json.loads(replay.ask("log:position"))["frame"] == 100
        assert replay.ask("log:step -count 1") == "stepping 1"
        time.sleep(0.3)
        assert frame_of(replay, "motion") == 101
        replay.ask("log:step -count 2")
        time.sleep(0.3)
        assert frame_of(replay, "motion") == 103
        replay.ask("log:step -count -1")
        time.sleep(0.3)
        assert frame_of(replay, "motion") == 102
        assert replay.ask("log:goto -frame 9999").startswith("error: the log has no motion frame 9999")
        assert replay.ask("log:play") == "playing"
    finally:
        replay.stop()


@pytest.mark.slow
@pytest.mark.alone
def test_concurrent_runtime_answers_commands_from_both_processes() -> None:
    concurrent = Program("--concurrent")
    try:
        with concurrent.client() as client:
            answers = client.ask_many(["modules:list", "representation:print HeadMotionRequest", "representation:print JointCommand", "ping"])
        assert "[cognition]" in answers[0] and "[motion]" in answers[0]
        assert answers[1].startswith("[cognition]\nHeadMotionRequest (cognition") and "[motion]\nHeadMotionRequest (motion" in answers[1]
        assert answers[2].startswith("JointCommand (motion")
        assert answers[3] == "pong"
    finally:
        out, err = concurrent.stop()
    assert concurrent.process.returncode == 0, err


@pytest.mark.slow
def test_console_runs_one_command_for_scripts(program: Program) -> None:
    ok = tafel("console", "--port", str(program.port), "-c", "ping")
    assert ok.returncode == 0 and ok.stdout == "pong\n"
    failing = tafel("console", "--port", str(program.port), "-c", "modules:set -module Nope -enabled true")
    assert failing.returncode == 1 and failing.stdout.startswith("error: unknown module 'Nope'")
    nobody = tafel("console", "--port", "1", "-c", "ping")
    assert nobody.returncode == 2 and "cannot connect to 127.0.0.1:1" in nobody.stderr


@pytest.mark.slow
def test_the_listening_line_and_port_conflicts(program: Program) -> None:
    taken = tafel("run", "--platform", "dummy", "--frames", "10", "--speed", "max", "--debug-port", str(program.port))
    assert taken.returncode == 2 and f"debug port 127.0.0.1:{program.port} is taken" in taken.stderr


def test_unknown_canvas_and_bytes_without_plus_say_what_would_be_right(program: Program) -> None:
    answer = program.ask("drawings:get -canvas nosuch")
    assert answer.startswith("error:") and "no canvas 'nosuch'" in answer and "field, robot, image:top, image:bottom" in answer
    close = program.ask("drawings:get -canvas image:tpo")
    assert "did you mean 'image:top'" in close
    raw = program.ask("representation:get -name BallModel")
    assert raw.startswith("error:") and "+representation:get" in raw


# ------------------------------------------------------------------ web pages, idle places (second security round)
def read_until_closed(connection: socket.socket, timeout: float = 10.0) -> bytes:
    """Everything the server sends until it closes the connection (a reset counts as closed)."""
    connection.settimeout(timeout)
    received = b""
    try:
        while chunk := connection.recv(4096):
            received += chunk
    except ConnectionResetError:
        pass
    return received


@pytest.mark.slow
def test_an_http_post_with_a_request_line_over_64_kib_runs_nothing(tmp_path: Path) -> None:
    """A page on another origin can make a browser POST here with a request line longer than a command
    line may be: it arrived as "too long", took the first place in the order, and the body ran."""
    running = Program("--platform", "dummy", cwd=tmp_path)
    try:
        body = b"\nlog:start -file posted.mcap\nping\n"
        request = (b"POST /?" + b"a" * (70 * 1024) + b" HTTP/1.1\r\nHost: 127.0.0.1:5401\r\nOrigin: http://evil.example\r\n"
                   b"Content-Type: text/plain\r\n" + f"Content-Length: {len(body)}\r\n\r\n".encode() + body)
        with socket.create_connection((running.host, running.port), timeout=10) as connection:
            try:
                connection.sendall(request)
            except (BrokenPipeError, ConnectionResetError):
                pass  # closed while the request was still on its way: as it should be
            received = read_until_closed(connection)
        assert received == b"", received[:200]  # not one answer, not even "line too long"
        assert json.loads(running.ask("log:status"))["recording"] is False
    finally:
        running.stop()
    assert not (tmp_path / "logs").exists()
    assert any("speaks HTTP" in line for line in running.errors), running.errors


@pytest.mark.slow
@pytest.mark.parametrize("token", [None, "right"])
def test_connections_that_never_authenticate_are_closed_and_free_their_place(tmp_path: Path, token: str | None) -> None:
    """32 connections held open idle locked every console user out. Now one that has not authenticated
    (without a token: sent no command) within --debug-idle-timeout is told so and closed; a user who
    did stays, however long they idle."""
    running = Program("--platform", "dummy", "--no-web", "--debug-max-connections", "4", "--debug-idle-timeout", "0.5",
                      *(["--debug-token", token] if token else []), cwd=tmp_path)
    what = "authenticating" if token else "a command"
    try:
        with running.client() as user:
            assert user.ask(f"auth {token}" if token else "ping") == ("authenticated" if token else "pong")
            idle = [socket.create_connection((running.host, running.port), timeout=10) for _ in range(3)]  # every other place
            for connection in idle:
                assert read_until_closed(connection) == f"error: 0.5 s without {what}; closing\n\0".encode()
                connection.close()
            with running.client() as late:  # a place is free again
                assert late.ask(f"auth {token}" if token else "ping") == ("authenticated" if token else "pong")
            assert user.ask("ping") == "pong"  # idle longer than the others were, and still served
    finally:
        running.stop()


def outward_address() -> str | None:
    """This machine's address on its network (not loopback), or None without one."""
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as probe:
        try:
            probe.connect(("192.0.2.1", 9))  # no packet is sent: this only picks the route's source address
        except OSError:
            return None
        address = probe.getsockname()[0]
    return None if address.startswith("127.") else address


def test_the_last_place_is_kept_for_a_client_on_this_machine() -> None:
    """Connections from elsewhere, held open and even authenticated, never take the last place: the
    robot's own user (or one logged in on it) can always get in."""
    address = outward_address()
    if address is None:
        pytest.skip("this machine has no network address besides loopback")
    server = DebugServer(DebugRouter(), "0.0.0.0", 0, max_connections=3)
    server.start()
    held: list[socket.socket] = []
    try:
        for _ in range(2):
            connection = socket.create_connection((address, server.port), timeout=10)
            connection.sendall(b"ping\n")
            assert connection.recv(64) == b"pong\n\0"
            held.append(connection)
        with socket.create_connection((address, server.port), timeout=10) as third:
            refusal = read_until_closed(third)
        assert refusal.startswith(b"error: too many debug connections (3 at most, the last 1 kept for clients on the robot itself)")
        with DebugClient("127.0.0.1", server.port) as local:
            assert local.ask("ping") == "pong"
    finally:
        for connection in held:
            connection.close()
        server.stop()


def test_the_network_threads_share_of_a_frame_is_for_all_clients_together() -> None:
    """Lines answered at once (ping, help, refusals) run in the network thread, under the lock the loops need:
    all clients together get ``NETWORK_S_PER_FRAME`` of it per frame, then wait for the next frame."""
    server = DebugServer(DebugRouter())
    assert not server.spend_network_time(0.6 * NETWORK_S_PER_FRAME)  # one client's lines
    assert server.spend_network_time(0.6 * NETWORK_S_PER_FRAME)  # another's, in the same frame: the share is used up
    assert server.spend_network_time(0.0)
    server.next_frame()
    assert not server.spend_network_time(0.6 * NETWORK_S_PER_FRAME)  # a new frame, a new share


def test_a_client_flooding_lines_answered_at_once_gets_every_answer_in_order_while_no_frame_starts() -> None:
    """Throttled by the network thread's share of each frame, a flood of pings still gets every answer, in order,
    when the loop is paused (no frame starts: each wait ends after ``FRAME_WAIT``); other clients are answered meanwhile."""
    server = DebugServer(DebugRouter())
    server.start()
    try:
        with socket.create_connection(("127.0.0.1", server.port), timeout=30) as flood:
            count = 30_000  # 150 kB of lines: more than a frame's bytes and share allow
            sender = threading.Thread(target=flood.sendall, args=(b"ping\n" * (count - 1) + b"hello\n",), daemon=True)
            sender.start()
            with DebugClient("127.0.0.1", server.port) as other:
                assert other.ask("ping") == "pong"
            received = b""
            while received.count(b"\0") < count:
                chunk = flood.recv(1 << 16)
                assert chunk, ("closed after", received.count(b"\0"), "answers")
                received += chunk
            sender.join(timeout=30)
        answers = received.split(b"\0")[:count]
        assert answers[:-1] == [b"pong\n"] * (count - 1) and answers[-1] != b"pong\n", answers[-1]
    finally:
        server.stop()
