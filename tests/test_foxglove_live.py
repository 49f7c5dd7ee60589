"""``tafel run --foxglove``: a client that speaks the Foxglove WebSocket protocol (our own, from its
specification, on the ``websockets`` package) watches and steers the default simulation."""

from __future__ import annotations

import re
import time
from collections.abc import Iterator
from typing import Any

import cv2
import numpy as np
import pytest
from websockets.exceptions import InvalidStatus

from tests.support.foxglove_client import FoxgloveClient
from tests.test_debug_server import Program
from tests.test_foxglove import sdk_class

ADDRESS = re.compile(r"foxglove server listening on (ws://[\d.]+:\d+)")


def foxglove_url(program: Program) -> str:
    """The address the program printed (it prints the debug server's first)."""
    deadline = time.monotonic() + 30
    while time.monotonic() < deadline:
        if match := ADDRESS.search("".join(program.output)):
            return match.group(1)
        time.sleep(0.05)
    raise AssertionError("no foxglove server address printed: " + "".join(program.errors)[-2000:])


@pytest.fixture(scope="module")
def live() -> Iterator[tuple[Program, str]]:
    program = Program("--platform", "mujoco", "--foxglove", "0")
    try:
        yield program, foxglove_url(program)
    finally:
        program.stop()


@pytest.fixture
def clients(live: tuple[Program, str]) -> Iterator[tuple[FoxgloveClient, Any]]:
    """A Foxglove client of the live program, and a debug client to check what changed."""
    program, url = live
    client, debug = FoxgloveClient(url), program.client()
    try:
        yield client, debug
    finally:
        client.close()
        debug.close()


@pytest.mark.slow
def test_a_client_receives_and_decodes_the_top_image_and_the_scene(live: tuple[Program, str]) -> None:
    _, url = live
    client = FoxgloveClient(url)
    try:
        client.subscribe("/camera/top", "/scene")
        client.wait_for(lambda: len(client.received.get("/camera/top", [])) >= 5 and client.received.get("/scene"), 20)
        image = sdk_class("CompressedImage").FromString(client.received["/camera/top"][-1][1])
        assert cv2.imdecode(np.frombuffer(image.data, np.uint8), cv2.IMREAD_COLOR).shape == (240, 320, 3)
        scene = sdk_class("SceneUpdate")
        ids = {e.id for _, data in client.received["/scene"] for e in scene.FromString(data).entities}
        assert {"field", "robot/torso", "ball/model"} <= ids  # the field is sent again to a new subscriber
    finally:
        client.close()


@pytest.mark.slow
def test_parameters_and_debug_requests_are_set_through_the_protocol(clients: tuple[FoxgloveClient, Any]) -> None:
    client, debug = clients
    try:
        listed = client.get_parameters()
        assert listed["/SoccerBehavior/search_turn"] == pytest.approx(0.6)
        assert listed["/debug_request/BallDetector:draw_candidates"] is False
        answer = client.set_parameters({"/SoccerBehavior/search_turn": 0.45, "/debug_request/BallDetector:draw_candidates": True})
        assert answer == {"/SoccerBehavior/search_turn": pytest.approx(0.45), "/debug_request/BallDetector:draw_candidates": True}
        assert "search_turn = 0.45" in debug.ask("parameter:get -module SoccerBehavior")  # the program changed
        assert re.search(r"^\s+on +BallDetector:draw_candidates", debug.ask("debug_request:list"), re.MULTILINE)
        refused = client.set_parameters({"/SoccerBehavior/search_turn": 1e9})  # out of its declared range: unchanged
        assert refused["/SoccerBehavior/search_turn"] == pytest.approx(0.45)
    finally:
        client.set_parameters({"/SoccerBehavior/search_turn": 0.6, "/debug_request/BallDetector:draw_candidates": False})


@pytest.mark.slow
def test_the_command_service_answers_as_the_console_would(clients: tuple[FoxgloveClient, Any]) -> None:
    client, debug = clients
    assert client.call_service("/tafel/command", b"ping") == b"pong"
    assert client.call_service("/tafel/command", b"modules:list").decode().startswith(debug.ask("modules:list")[:20])
    assert client.call_service("/tafel/command", b"no:such").decode().startswith("error: unknown command")


@pytest.mark.slow
def test_with_everything_subscribed_the_loops_keep_their_rates(clients: tuple[FoxgloveClient, Any]) -> None:
    client, debug = clients
    client.subscribe(*sorted(client.wait_for(client.topics)))
    client.pump(1.0)

    def frames() -> tuple[float, dict[str, int]]:
        counts = re.findall(r"\[(\w+)\]\nloop: [\d.]+ Hz, frame (\d+)", debug.ask("stopwatch:list"))
        return time.monotonic(), {context: int(frame) for context, frame in counts}

    start, first = frames()
    client.pump(6.0)
    end, last = frames()
    rates = {context: (last[context] - first[context]) / (end - start) for context in first}
    assert rates["motion"] == pytest.approx(100, rel=0.03) and rates["cognition"] == pytest.approx(30, rel=0.05), rates
    assert len(client.received["/camera/top"]) >= 150  # about 30 a second arrived


@pytest.mark.slow
def test_with_a_debug_token_a_client_needs_it_too(tmp_path) -> None:
    program = Program("--platform", "dummy", "--foxglove", "0", "--debug-token", "s3cret")
    try:
        url = foxglove_url(program)
        with pytest.raises(InvalidStatus, match="401"):
            FoxgloveClient(url)
        with pytest.raises(InvalidStatus, match="401"):
            FoxgloveClient(url + "/?token=wrong")
        client = FoxgloveClient(url + "/?token=s3cret")
        assert client.wait_for(client.topics)
        client.close()
        old_name = FoxgloveClient(url, subprotocol="foxglove.websocket.v1", headers={"Authorization": "Bearer s3cret"})
        assert old_name.wait_for(old_name.topics)
        old_name.close()
    finally:
        program.stop()


@pytest.mark.slow
def test_contexts_in_their_own_processes_are_served_too() -> None:
    """The concurrent runtime (as on the robot): the context processes hand over what clients subscribe to."""
    program = Program("--platform", "dummy", "--concurrent", "--foxglove", "0")
    try:
        client = FoxgloveClient(foxglove_url(program))
        client.subscribe("/joints", "/scene", "/rates")
        client.wait_for(lambda: len(client.received.get("/joints", [])) >= 50 and client.received.get("/scene"), 20)
        assert client.set_parameters({"/SoccerBehavior/search_turn": 0.5}) == {"/SoccerBehavior/search_turn": pytest.approx(0.5)}
        assert "search_turn = 0.5" in program.ask("parameter:get -module SoccerBehavior")
        client.close()
    finally:
        program.stop()
