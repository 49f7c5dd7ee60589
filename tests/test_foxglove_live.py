"""``tafel run --foxglove``: a client that speaks the Foxglove WebSocket protocol (our own, from its
specification, on the ``websockets`` package) watches and steers the default simulation."""

from __future__ import annotations

import json
import re
import socket
import struct
import time
from collections.abc import Iterator
from typing import Any

import cv2
import jsonschema
import numpy as np
import pytest
from websockets.exceptions import InvalidStatus

from tests.support import cpu_use
from tests.support.attack import loop_frames, skip_without_headroom
from tests.support.foxglove_client import FoxgloveClient, ServiceCallFailure
from tests.test_cli_runtime import tafel
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


@pytest.mark.alone
@pytest.mark.slow
def test_with_everything_subscribed_the_loops_keep_their_rates(live: tuple[Program, str], clients: tuple[FoxgloveClient, Any]) -> None:
    """Streaming every channel must not slow the loops: their rates with everything subscribed are
    compared with their rates, measured just before in the same program, with nothing subscribed (the
    simulator's own pace on this machine is the baseline, not a fixed 100 Hz). Judged where the program keeps its
    beat alone with room to spare (``skip_without_headroom``): where it uses up its core already, the server's work takes
    its share whatever it does."""
    client, debug = clients

    def frames() -> tuple[float, dict[str, int]]:
        return time.monotonic(), loop_frames(debug.ask("stopwatch:list"))

    def rates(seconds: float) -> dict[str, float]:
        start, first = frames()
        client.pump(seconds)
        end, last = frames()
        return {context: (last[context] - first[context]) / (end - start) for context in first}

    pid = live[0].process.pid
    alone, alone_use = cpu_use.measured(pid, lambda: rates(4.0))
    client.subscribe(*sorted(client.wait_for(client.topics)))
    client.pump(1.0)
    streaming, streaming_use = cpu_use.measured(pid, lambda: rates(6.0))
    print("rates alone", alone, alone_use, "streaming", streaming, streaming_use)
    assert alone["motion"] > 30 and alone["cognition"] > 9, alone  # the program runs at all (60 Hz motion alone, once, on a slow machine)
    assert len(client.received["/camera/top"]) >= 5 * streaming["cognition"]  # about one image a cognition frame arrived
    skip_without_headroom(alone, "streaming", alone_use, streaming_use)
    for context in ("motion", "cognition"):
        assert streaming[context] >= 0.9 * alone[context], (alone, streaming)


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


@pytest.mark.slow
def test_a_client_that_asks_for_the_old_protocol_name_gets_in_without_a_token(live: tuple[Program, str]) -> None:
    """Older Lichtblick and third-party clients offer only ``foxglove.websocket.v1`` (the SDK knows only the new name)."""
    _, url = live
    client = FoxgloveClient(url, subprotocol="foxglove.websocket.v1")
    try:
        assert client.socket.subprotocol == "foxglove.websocket.v1"
        assert "/camera/top" in client.wait_for(client.topics)
        assert client.call_service("/tafel/command", b"ping") == b"pong"
    finally:
        client.close()
    with pytest.raises(InvalidStatus, match="400"):  # neither name: refused, saying which to ask for
        FoxgloveClient(url, subprotocol="chat")


@pytest.mark.slow
def test_pages_of_other_sites_and_rebinding_names_are_refused(live: tuple[Program, str]) -> None:
    """Without a token: a page of another site (cross-site WebSocket hijacking) and a DNS name pointed at the
    robot (DNS rebinding) get no connection, so never ``/tafel/command``; a desktop app (no Origin) and a page
    of the server's own origin do."""
    program, url = live
    port = int(url.rsplit(":", 1)[1])
    with pytest.raises(InvalidStatus, match="403"):
        FoxgloveClient(url, origin="http://attacker.example")
    with pytest.raises(InvalidStatus, match="403"):
        FoxgloveClient(url, host="rebind.attacker.example")
    with pytest.raises(InvalidStatus, match="403"):  # the rebinding page's own origin does not help
        FoxgloveClient(url, host="rebind.attacker.example", origin=f"http://rebind.attacker.example:{port}")
    assert "may not steer this program" in "".join(program.errors)
    for allowed in (FoxgloveClient(url), FoxgloveClient(url, origin=f"http://127.0.0.1:{port}"), FoxgloveClient(url, host="localhost")):
        try:
            assert allowed.call_service("/tafel/command", b"ping") == b"pong"
        finally:
            allowed.close()


@pytest.mark.slow
def test_the_command_service_takes_json_as_the_service_call_panel_sends_it(clients: tuple[FoxgloveClient, Any]) -> None:
    client, debug = clients
    assert "json" in client.wait_for(lambda: client.server_info)["supportedEncodings"]
    answer = json.loads(client.call_service("/tafel/command", b'{"command": "ping"}', encoding="json"))
    assert answer == {"answer": "pong"}
    listed = json.loads(client.call_service("/tafel/command", json.dumps({"command": "modules:list"}).encode(), encoding="json"))
    assert listed["answer"][:20] == debug.ask("modules:list")[:20]
    for bad, says in ((b'{"command": ', "not JSON"), (b"{}", "names no command"), (b'{"cmd": "ping"}', "unknown field 'cmd'"),
                      (b'{"command": 5}', "names no command")):
        with pytest.raises(ServiceCallFailure) as failure:
            client.call_service("/tafel/command", bad, encoding="json")
        assert says in str(failure.value) and '{"command": "' in str(failure.value), failure.value  # and what to send


@pytest.mark.slow
def test_a_refused_parameter_answers_with_its_value_and_says_why(clients: tuple[FoxgloveClient, Any]) -> None:
    client, _ = clients
    before = client.get_parameters("/SoccerBehavior/search_turn")["/SoccerBehavior/search_turn"]
    answer = client.set_parameters({"/SoccerBehavior/search_turn": 1e9})
    assert answer == {"/SoccerBehavior/search_turn": pytest.approx(before)}
    status = client.wait_for(lambda: next((r for r in client.replies if r.get("op") == "status"), None))
    assert status["level"] == 1  # a warning, shown by Foxglove and Lichtblick
    message = status["message"]
    assert "/SoccerBehavior/search_turn" in message and "takes a finite number from 0 to 2, got" in message, status
    assert "1e+09" in message or "1000000000" in message, status  # the value sent, as the command line carried it
    client.replies.clear()
    assert client.set_parameters({"/NoSuch": 1.0}) == {}
    status = client.wait_for(lambda: next((r for r in client.replies if r.get("op") == "status"), None))
    assert "/MODULE/NAME" in status["message"]


@pytest.mark.slow
def test_each_json_channel_declares_the_fields_its_messages_carry(clients: tuple[FoxgloveClient, Any]) -> None:
    client, _ = clients
    json_topics = ("/joints", "/imu", "/fsr", "/timing", "/rates")
    client.subscribe(*json_topics)
    client.wait_for(lambda: all(len(client.received.get(topic, [])) >= 20 for topic in json_topics), 20)
    channels = client.topics()
    for topic in json_topics:
        assert channels[topic]["schemaEncoding"] == "jsonschema"
        schema = json.loads(channels[topic]["schema"])
        jsonschema.Draft202012Validator.check_schema(schema)
        declared = set(schema["properties"])
        for _, payload in client.received[topic]:
            message = json.loads(payload)
            jsonschema.validate(message, schema)
            assert set(message) <= declared, (topic, set(message) - declared)
        assert declared, topic
    joints = json.loads(channels["/joints"]["schema"])["properties"]["position"]["properties"]
    assert "LKneePitch" in joints and joints["LKneePitch"] == {"type": "number"}


@pytest.mark.slow
def test_a_subscriber_that_goes_away_costs_one_line() -> None:
    """A client that streams everything and disappears (its socket closed under it, or reset) leaves at most one
    line about it on the program's stderr, not one per message the server still had for it (hundreds)."""
    program = Program("--platform", "mujoco", "--foxglove", "0")
    try:
        url = foxglove_url(program)
        for how in ("closed", "reset", "closed", "closed"):
            before = len(program.errors)
            client = FoxgloveClient(url)
            client.subscribe(*sorted(client.wait_for(client.topics)))
            client.pump(0.6)
            raw = client.socket.socket
            if how == "reset":
                raw.setsockopt(socket.SOL_SOCKET, socket.SO_LINGER, struct.pack("ii", 1, 0))
            raw.close()  # under the client's reading thread, as when its process dies
            time.sleep(1.5)
            lines = [line for line in program.errors[before:] if "foxglove" in line and "[tafel]" not in line]
            assert len(lines) <= 1, f"{how}: {len(lines)} lines, " + "".join(lines[:3])
    finally:
        program.stop()


@pytest.mark.slow
def test_configured_origins_are_let_in_and_a_wrong_list_is_refused_at_start() -> None:
    """``[foxglove] origins``: a browser app the user trusts (Foxglove's web app) gets in, other pages still not."""
    program = Program("--platform", "dummy", "--foxglove", "0", "--set", 'foxglove.origins=["https://app.foxglove.dev"]')
    try:
        url = foxglove_url(program)
        client = FoxgloveClient(url, origin="https://app.foxglove.dev")
        assert client.call_service("/tafel/command", b"ping") == b"pong"
        client.close()
        with pytest.raises(InvalidStatus, match="403"):
            FoxgloveClient(url, origin="https://app.foxglove.dev.attacker.example")
    finally:
        program.stop()
    wrong = tafel("run", "--platform", "dummy", "--seconds", "0.2", "--no-debug", "--foxglove", "0", "--set", "foxglove.origins=5")
    assert wrong.returncode == 2 and "foxglove.origins takes a list of web origins" in wrong.stderr and "Traceback" not in wrong.stderr
