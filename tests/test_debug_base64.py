"""Every argument of every command can be sent in base64 (``+name``), as the protocol says."""

from __future__ import annotations

import base64
import shutil
from collections.abc import Iterator

import pytest

from tests.test_cli_runtime import REPO
from tests.test_debug_server import DEBUG_USER, Program

# command -> arguments of a valid call (the same call in plain text and in base64 must agree)
CALLS: dict[str, dict[str, str]] = {
    "auth": {"token": "anything"},
    "debug_request:list": {},
    "debug_request:set": {"name": "DebugUser:draw", "value": "on"},
    "drawings:get": {"canvas": "field"},
    "hello": {},
    "help": {"name": "modules:list"},
    "log:start": {"file": "b64.mcap"},
    "log:status": {},
    "log:stop": {},
    "modify:list": {},
    "modify:set": {"name": "DebugUser:gain", "value": "2.5"},
    "modify:release": {"name": "DebugUser:gain"},
    "modules:graph": {},
    "modules:list": {},
    "modules:provider": {"representation": "BallModel", "module": "KalmanBallModeler"},
    "modules:set": {"module": "LookAtBallBehavior", "enabled": "on"},
    "module:reload": {"module": "DebugUser"},
    "modules:store": {},
    "parameter:get": {"module": "KalmanBallModeler"},
    "parameter:list": {},
    "parameter:set": {"module": "KalmanBallModeler", "name": "friction", "value": "0.5"},
    "parameter:store": {"module": "KalmanBallModeler"},
    "ping": {},
    "plot:get": {"name": "DebugUser:frame"},
    "representation:get": {"name": "DebugUserOutput", "context": "cognition"},
    "representation:list": {},
    "representation:print": {"name": "BallModel", "context": "cognition"},
    "representation:set": {"name": "HeadMotionRequest", "field": "max_speed", "value": "1.5"},
    "stopwatch:list": {},
    "representation:override": {"name": "MotionRequest", "context": "motion", "fields": "{}"},
    "representation:release": {"name": "MotionRequest", "context": "motion"},
    "motion:walk": {"x": "100", "y": "-20", "rotation": "0.1"},
    "motion:walk_to": {"x": "500", "y": "0", "rotation": "0"},
    "motion:kick": {"foot": "right", "direction": "0.1"},
    "motion:stand": {},
    "motion:sit": {},
    "motion:release": {},
    "image:get": {"name": "CameraImageTop", "quality": "70"},
    "field:geometry": {},
    "web:status": {},
    "network:status": {},
    "subscribe": {"topics": "BallModel", "hz": "5"},
    "unsubscribe": {"topics": "BallModel"},
}
#: commands that undo what another did: that one runs before each call
PRECEDED = {"log:stop": "log:start -file stop.mcap", "representation:release": "motion:stand", "motion:release": "motion:stand"}
#: the dummy platform has no cameras: the same error either way shows the arguments arrived alike
ERROR_HERE = {"image:get", "subscribe", "unsubscribe"}  # and a telnet client cannot stream
#: answers that change from frame to frame: compared by kind (error or not) only
VARYING = {"hello", "log:start", "log:status", "log:stop", "modules:list", "plot:get", "representation:get", "representation:print", "stopwatch:list",
           "drawings:get", "modules:store", "parameter:store", "web:status", "module:reload"}  # reload: its time and frame


def line(name: str, args: dict[str, str], encoded: str | None = None) -> str:
    parts = ["+" + name if name in ("representation:get", "image:get") else name]  # they answer with bytes
    for key, value in args.items():
        if key == encoded:
            parts.append(f"+{key} {base64.b64encode(value.encode()).decode()}")
        else:
            parts.append(f'-{key} "{value}"')
    return " ".join(parts)


@pytest.fixture(scope="module")
def program(tmp_path_factory) -> Iterator[Program]:
    folder = tmp_path_factory.mktemp("b64")
    shutil.copytree(REPO / "config", folder / "config", ignore=shutil.ignore_patterns("private"))
    running = Program("--config", str(folder / "config"), "--set",
                      f'cognition.modules=["KalmanBallModeler", "SimpleBallModeler", "LookAtBallBehavior", "Striker", "{DEBUG_USER}"]',
                      cwd=folder)
    yield running
    running.stop()


def test_every_command_is_covered(program: Program) -> None:
    listed = {row.split()[0] for row in program.ask("help").splitlines() if row.strip()}
    assert listed <= set(CALLS), f"add base64 calls for: {sorted(listed - set(CALLS))}"


@pytest.mark.parametrize("name", sorted(CALLS))
def test_each_argument_in_base64_gives_the_plain_answer(program: Program, name: str) -> None:
    args = CALLS[name]
    with program.client() as client:
        if name in PRECEDED:
            client.ask(PRECEDED[name])
        plain = client.ask(line(name, args))
        assert not plain.startswith("error:") or name in ERROR_HERE, plain
        for key in args:
            if name in PRECEDED:
                client.ask(PRECEDED[name])
            encoded = client.ask(line(name, args, key))
            assert not encoded.startswith("error:") or name in ERROR_HERE, f"{name} with +{key}: {encoded}"
            if name not in VARYING:
                assert encoded == plain, f"{name} with +{key}"
            if name == "log:start":
                client.ask("log:stop")


def test_base64_that_is_not_text_is_a_clear_error(program: Program) -> None:
    answer = program.ask("parameter:get +module " + base64.b64encode(b"\xff\xfe").decode())
    assert answer.startswith("error:") and "not UTF-8 text" in answer
