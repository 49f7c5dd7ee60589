"""The debug protocol over a WebSocket, the page's files, and the JSON the page reads: in one process,
over real sockets, without a browser."""

from __future__ import annotations

import http.client
import json
import math
import threading
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from websockets.exceptions import InvalidStatus
from websockets.sync.client import connect

from tafel.core.framework.manager import ModuleManager
from tafel.core.framework.representation import registered_representations
from tafel.core.testing import strategy_for
from tafel.debug.commands import ContextDebug
from tafel.debug.executors import LocalExecutor
from tafel.debug.protocol import parse
from tafel.debug.router import DebugRouter, merge_answers
from tafel.debug.server import DebugServer
from tafel.debug.values import json_value
from tafel.debug.websocket import WebServer, WebSocketSession, host_allowed
from tafel.modules.modeling.kalman_ball_modeler import KalmanBallModeler
from tafel.modules.modeling.simple_ball_modeler import SimpleBallModeler
from tafel.representations import load_all
from tafel.representations.infrastructure import FrameInfo
from tafel.representations.modeling import BallModel
from tafel.representations.perception import BallPercept, CameraImageTop
from tafel.tools.viewers.live_feed import LiveFeed

load_all()


class Served:
    """A debug server with one context (two ball modelers) and the web transport, answered by a thread."""

    def __init__(self, static: Path, *, token: str | None = None, max_connections: int = 32) -> None:
        self.manager = ModuleManager([KalmanBallModeler, SimpleBallModeler], external=[BallPercept, FrameInfo],
                               providers={"BallModel": "KalmanBallModeler"})
        self.router = DebugRouter()
        self.debug = ContextDebug("cognition", self.manager)
        self.router.add_context("cognition", LocalExecutor(self.debug))
        self.server = DebugServer(self.router, "127.0.0.1", 0, token=token, max_connections=max_connections)
        self.server.start()
        self.subscribed: list[frozenset[str]] = []
        self.web = WebServer(self.server, static, port=0, topics=lambda: ["BallModel", "CameraImageTop"],
                             on_subscriptions=self.subscribed.append)
        self.web.start()
        self.running = True
        self.thread = threading.Thread(target=self._answer, daemon=True)
        self.thread.start()

    def _answer(self) -> None:
        while self.running:
            self.server.process_pending()
            time.sleep(0.005)

    @property
    def url(self) -> str:
        return f"ws://127.0.0.1:{self.web.port}/ws"

    def stop(self) -> None:
        self.running = False
        self.thread.join(timeout=5)
        self.server.stop()


@pytest.fixture
def static(tmp_path: Path) -> Path:
    folder = tmp_path / "static"
    folder.mkdir()
    (folder / "index.html").write_text("<!doctype html><title>page</title>")
    (folder / "app.js").write_text("export const x = 1;")
    (tmp_path / "secret.txt").write_text("not for you")
    return folder


@pytest.fixture
def served(static: Path) -> Iterator[Served]:
    running = Served(static)
    yield running
    running.stop()


def ask(socket: Any, line: str) -> str:
    socket.send(line)
    return json.loads(socket.recv(timeout=5))["answer"]


# ----------------------------------------------------------------------------------------- commands
def test_commands_are_the_text_protocols_and_answers_come_in_order(served: Served) -> None:
    with connect(served.url) as socket:
        assert ask(socket, "ping") == "pong"
        for line in ("ping", "modules:list", "ping", "parameter:list", "help ping"):
            socket.send(line)
        answers = [json.loads(socket.recv(timeout=5))["answer"] for _ in range(5)]
        assert answers[0] == answers[2] == "pong"
        assert "KalmanBallModeler" in answers[1] and answers[4].startswith("ping: answers pong")
        assert ask(socket, "modules:list -format json").startswith("{")
        assert ask(socket, "representation:print -name BallModle").startswith("error: unknown representation 'BallModle': did you mean 'BallModel'")
        assert ask(socket, "nonsense:command").startswith("error: unknown command 'nonsense:command'")
        assert ask(socket, '-bad "line').startswith("error: expected a command name")
        assert ask(socket, "stopwatch:list -format xml") == "error: cognition: -format takes text or json, got 'xml'"


def test_telnet_clients_learn_that_streaming_is_the_websockets(served: Served) -> None:
    assert served.server.ask("subscribe BallModel").startswith("error: subscribe streams over the web page's WebSocket (ws://")
    assert "subscribe NAME [NAME...] [-hz N]" in served.server.ask("help subscribe")


def test_switching_a_provider_over_the_websocket_is_seen_by_telnet_clients_too(served: Served) -> None:
    with connect(served.url) as socket:
        assert ask(socket, "modules:provider -representation BallModel -module SimpleBallModeler") == \
            "BallModel is provided by SimpleBallModeler in cognition"
    assert "provider BallModel: SimpleBallModeler" in served.server.ask("modules:list")


def test_with_a_token_nothing_runs_before_auth(static: Path) -> None:
    running = Served(static, token="s3cret")
    try:
        with connect(running.url) as socket:
            assert ask(socket, "modules:list") == "error: not authenticated (send: auth TOKEN)"
            assert ask(socket, "subscribe BallModel") == "error: not authenticated (send: auth TOKEN)"
            assert ask(socket, "auth wrong") == "error: wrong token"
            assert ask(socket, "auth s3cret") == "authenticated"
            assert "KalmanBallModeler" in ask(socket, "modules:list")
    finally:
        running.stop()


def test_connections_over_the_limit_are_refused_with_a_reason(static: Path) -> None:
    running = Served(static, max_connections=2)
    try:
        with connect(running.url) as first, connect(running.url) as second:
            assert ask(first, "ping") == ask(second, "ping") == "pong"
            with connect(running.url) as third:
                assert json.loads(third.recv(timeout=5))["answer"].startswith("error: too many debug connections (2 at most)")
    finally:
        running.stop()


# ------------------------------------------------------------------------------------ subscriptions
def test_subscribed_topics_stream_and_unknown_ones_are_an_error(served: Served) -> None:
    with connect(served.url) as socket:
        assert ask(socket, "subscribe BallModle") .startswith("error: there is no topic 'BallModle'; did you mean 'BallModel'")
        assert ask(socket, "subscribe") == "error: usage: subscribe NAME [NAME...] [-hz N]; the topics are BallModel, CameraImageTop"
        assert ask(socket, "subscribe BallModel -hz fast") == \
            "error: -hz takes messages a second from 0.1 to 1000 (leave it out for every one), got 'fast'"
        assert ask(socket, "subscribe BallModel CameraImageTop") == "subscribed BallModel CameraImageTop"
        assert served.subscribed[-1] == {"BallModel", "CameraImageTop"}
        served.web.publish("BallModel", json.dumps({"topic": "BallModel", "value": {"x": 1.0}}))
        served.web.publish("CameraImageTop", b"\x00\x00\x00\x02{}jpeg")
        served.web.publish("FrameInfo", "nobody subscribed: never sent")
        first, second = socket.recv(timeout=5), socket.recv(timeout=5)
        assert json.loads(first)["value"] == {"x": 1.0} and second == b"\x00\x00\x00\x02{}jpeg"
        assert ask(socket, "unsubscribe BallModel") == "unsubscribed BallModel"
        assert served.subscribed[-1] == {"CameraImageTop"}
    deadline = time.monotonic() + 5
    while served.subscribed[-1]:  # a closed page subscribes to nothing
        assert time.monotonic() < deadline
        time.sleep(0.05)


def test_a_rate_limited_subscription_gets_the_newest_message_at_most_that_often(served: Served) -> None:
    with connect(served.url) as socket:
        assert ask(socket, "subscribe BallModel -hz 5") == "subscribed BallModel at most 5 a second"
        started = time.monotonic()
        received = []
        for frame in range(60):  # 100 messages a second for 0.6 s
            served.web.publish("BallModel", json.dumps({"frame": frame}))
            time.sleep(0.01)
        try:
            while True:
                received.append(json.loads(socket.recv(timeout=0.5))["frame"])
        except TimeoutError:
            pass
        elapsed = time.monotonic() - started
        assert 2 <= len(received) <= 5 * elapsed + 1, (received, elapsed)
        assert received[-1] == 59  # the newest is never lost, only those in between


def test_a_slow_page_gets_the_newest_message_of_each_topic_and_every_answer() -> None:
    class Quiet:
        remote_address = ("127.0.0.1", 1)

    server = DebugServer(DebugRouter(), port=0)
    session = WebSocketSession(server, WebServer(server, Path(".")), Quiet())  # type: ignore[arg-type]
    for frame in range(5):
        session.stream("BallModel", f"ball {frame}")
    session.stream("RobotPose", "pose 0")
    assert list(session.latest.items()) == [("BallModel", "ball 4"), ("RobotPose", "pose 0")]
    assert session.dropped == 4
    assert session._write([b"pong\n\0", b"error: x\n\0"])
    assert [json.loads(m)["answer"] for m in session.out] == ["pong", "error: x"]


# --------------------------------------------------------------------------------------------- HTTP
def get(port: int, path: str, host: str | None = None) -> tuple[int, dict[str, str], bytes]:
    connection = http.client.HTTPConnection("127.0.0.1", port, timeout=5)
    connection.putrequest("GET", path, skip_host=True)
    connection.putheader("Host", host or f"127.0.0.1:{port}")
    connection.endheaders()
    answer = connection.getresponse()
    return answer.status, dict(answer.getheaders()), answer.read()


def test_the_page_files_are_served_and_nothing_else(served: Served) -> None:
    status, headers, body = get(served.web.port, "/")
    assert status == 200 and headers["Content-Type"] == "text/html; charset=utf-8" and b"<title>page" in body
    status, headers, _ = get(served.web.port, "/app.js")
    assert status == 200 and headers["Content-Type"].startswith("text/javascript")
    for path in ("/../secret.txt", "/%2e%2e/secret.txt", "/nothing.js", "/static/../../secret.txt"):
        status, _, body = get(served.web.port, path)
        assert status == 404 and b"not for you" not in body, path
    status, _, body = get(served.web.port, "/", host=f"localhost:{served.web.port}")
    assert status == 200


def test_a_foreign_host_or_origin_is_refused(served: Served) -> None:
    status, _, body = get(served.web.port, "/", host="attacker.example:5480")  # DNS rebinding
    assert status == 403 and b"not for 'attacker.example:5480'" in body
    with pytest.raises(InvalidStatus) as refused:
        with connect(served.url, origin="http://attacker.example"):  # type: ignore[arg-type]
            pass
    assert refused.value.response.status_code == 403
    with connect(served.url, origin=f"http://127.0.0.1:{served.web.port}") as socket:  # type: ignore[arg-type]
        assert ask(socket, "ping") == "pong"
    assert served.web.refused_origin == 1


@pytest.mark.parametrize(("host", "allowed"), [("127.0.0.1:5480", True), ("localhost:5480", True), ("[::1]:5480", True),
                                               ("10.0.0.7", True), ("robot.local:5480", False), ("evil.example", False), ("", False)])
def test_only_addresses_and_localhost_are_our_host(host: str, allowed: bool) -> None:
    assert host_allowed(host, "127.0.0.1") is allowed
    assert host_allowed(host, "127.0.0.1", names=True) is bool(host)  # with a token, robot names work too


# ------------------------------------------------------------------------------------------- JSON
def test_json_answers_of_two_contexts_are_one_object_by_context() -> None:
    command = parse("stopwatch:list -format json")
    merged = merge_answers(command, {"cognition": ("ok", '{"rate_hz": 30}'), "motion": ("ok", '{"rate_hz": 100}')})
    assert merged == (False, json.dumps({"cognition": {"rate_hz": 30}, "motion": {"rate_hz": 100}}))
    with_error = merge_answers(command, {"cognition": ("ok", "{}"), "motion": ("error", "stalled")})
    assert json.loads(with_error[1]) == {"cognition": {}, "motion": {"error": "stalled"}}


def test_the_json_of_commands_a_page_reads() -> None:
    manager = ModuleManager([KalmanBallModeler, SimpleBallModeler], external=[BallPercept, FrameInfo],
                               providers={"BallModel": "KalmanBallModeler"})
    debug = ContextDebug("cognition", manager)
    for _ in range(3):
        manager.execute()
    graph = json.loads(debug.execute(parse("modules:list -format json"))[1])
    kalman = next(m for m in graph["modules"] if m["name"] == "KalmanBallModeler")
    assert kalman["enabled"] and kalman["active"] and kalman["mean_us"] > 0 and kalman["errors"] == 0
    assert graph["representations"]["BallModel"] == {"provider": "KalmanBallModeler", "alternatives": ["KalmanBallModeler", "SimpleBallModeler"]}
    watches = json.loads(debug.execute(parse("stopwatch:list -format json"))[1])
    assert watches["frame"] == 3 and {s["name"] for s in watches["stopwatches"]} == {"KalmanBallModeler"}
    printed = json.loads(debug.execute(parse("representation:print -name BallModel -format json"))[1])
    assert printed["topic"] == "BallModel" and printed["context"] == "cognition" and set(printed["value"]) >= {"x", "y", "valid"}
    listed = json.loads(debug.execute(parse("representation:list -format json"))[1])
    assert {"name": "BallModel", "provider": "KalmanBallModeler"} in listed
    status, answer = debug.execute(parse("image:get -name BallModel"))
    assert status == "error" and "holds no camera image" in str(answer)


def test_image_get_answers_a_jpeg_of_the_camera_image() -> None:
    manager = ModuleManager([], external=[CameraImageTop])
    manager.blackboard[CameraImageTop].image[:] = 200
    debug = ContextDebug("cognition", manager)
    status, jpeg = debug.execute(parse("image:get -name CameraImageTop -quality 50"))
    assert status == "ok" and jpeg[:2] == b"\xff\xd8"
    assert debug.execute(parse("image:get -name CameraImageTop -quality 500")) == \
        ("error", "-quality takes a whole number from 1 to 100, got '500'")


def test_json_value_summarizes_large_arrays_and_nulls_what_json_cannot_hold() -> None:
    value = json_value({"image": np.zeros((240, 320, 3), np.uint8), "small": np.arange(3.0), "nan": math.nan, "inf": -math.inf})
    assert value == {"image": {"shape": [240, 320, 3], "dtype": "uint8", "min": 0.0, "max": 0.0}, "small": [0.0, 1.0, 2.0],
                     "nan": None, "inf": None}


@settings(max_examples=60, deadline=None)
@given(st.sampled_from(sorted(registered_representations())).flatmap(lambda name: strategy_for(registered_representations()[name])))
def test_every_representation_becomes_strict_json(rep: Any) -> None:
    text = json.dumps(json_value(rep), allow_nan=False)  # what browsers can parse: no NaN, no Infinity
    assert set(json.loads(text)) == {f.name for f in __import__("dataclasses").fields(rep)}


# ------------------------------------------------------------------------------------------- feed
def test_the_feed_hands_over_only_what_is_needed_and_drops_when_full() -> None:
    manager = ModuleManager([KalmanBallModeler], external=[BallPercept, FrameInfo])
    manager.execute()
    feed = LiveFeed([BallModel, BallPercept], queue_size=2)
    feed.after_frame("cognition", manager.blackboard, 0, 1)
    assert feed.queue.empty()  # nobody looks: nothing copied
    feed.need([BallModel])
    for frame in range(4):
        feed.after_frame("cognition", manager.blackboard, frame * 33_000_000, frame)
    first = feed.queue.get_nowait()
    assert type(first.value) is BallModel and first.frame == 0 and first.value is not manager.blackboard[BallModel]
    assert feed.dropped == 2


def test_a_need_limited_to_one_context_hands_over_only_from_it() -> None:
    manager = ModuleManager([KalmanBallModeler], external=[BallPercept, FrameInfo])
    manager.execute()
    flags = [0, 0]
    feed = LiveFeed([BallModel, BallPercept], flags=flags)
    feed.need([BallModel, BallPercept], only={BallModel: ["cognition"]})
    feed.after_frame("motion", manager.blackboard, 0, 1)
    feed.after_frame("cognition", manager.blackboard, 0, 1)
    handed = [(item.context, type(item.value).__name__) for item in [feed.queue.get_nowait() for _ in range(feed.queue.qsize())]]
    assert handed == [("motion", "BallPercept"), ("cognition", "BallModel"), ("cognition", "BallPercept")]
    assert flags == [1, 0x7F]  # what a context process reads: BallModel from cognition only, BallPercept from every context


# ------------------------------------------------------------------------------------ the web view
def receive_streamed(socket: Any, count: int) -> list[Any]:
    """The next ``count`` streamed messages (answers skipped): binary images as their JSON header."""
    got: list[Any] = []
    while len(got) < count:
        message = socket.recv(timeout=5)
        if isinstance(message, bytes):
            length = int.from_bytes(message[:4], "big")
            got.append(json.loads(message[4:4 + length]))
        elif "answer" not in (parsed := json.loads(message)):
            got.append(parsed)
    return got


def test_an_image_carries_the_drawings_of_its_own_frame_and_plot_names_come_when_new(served: Served) -> None:
    from tafel.debug.concepts import DebugDrawingPrimitive, DebugDrawings, DebugPlots
    from tafel.tools.viewers.live_feed import Handed
    from tafel.tools.viewers.web.view import WebView

    view = WebView(served.server, [CameraImageTop, BallModel], port=0)
    view.start()
    try:
        with connect(f"ws://127.0.0.1:{view.server.port}/ws") as socket:
            assert ask(socket, "subscribe CameraImageTop PlotNames").startswith("subscribed")
            deadline = time.monotonic() + 10.0  # the view learns of the subscription on its own thread
            while not {"CameraImageTop", "PlotNames"} <= set(view.wanted) and time.monotonic() < deadline:
                time.sleep(0.01)
            circle = lambda frame: DebugDrawingPrimitive("image:top", "circle", [frame, 10.0, 5.0], "orange")  # noqa: E731
            field_line = DebugDrawingPrimitive("field", "line", [0.0, 0.0, 1.0, 1.0])
            for frame in (5, 6):  # as a loop hands them over: the frame's image first, its drawings after it
                view.feed.take(Handed("cognition", CameraImageTop(), frame * 1000, 0, frame))
                view.feed.take(Handed("motion", DebugDrawings([]), frame * 1000, 0, 40 + frame))  # the other context's
                view.feed.take(Handed("cognition", DebugDrawings([circle(frame), field_line]), frame * 1000, 0, frame))
            view.feed.take(Handed("cognition", CameraImageTop(), 7000, 0, 7))  # its frame's drawings never come
            view.feed.take(Handed("cognition", DebugPlots(["a"], [1.0]), 7000, 0, 7))
            view.feed.take(Handed("motion", DebugPlots(["b"], [2.0]), 7000, 0, 80))
            images, names = [], []
            deadline = time.monotonic() + 20.0  # bounded: a list that never comes fails, it does not hang the suite
            while (not any(m["frame"] == 7 for m in images) or not names or not {"a", "b"} <= set(names[-1])) \
                    and time.monotonic() < deadline:
                for message in receive_streamed(socket, 1):
                    (images if message["topic"] == "CameraImageTop" else names).append(
                        message if message["topic"] == "CameraImageTop" else message["value"]["names"])
            seen = [(m["frame"], m["drawings_frame"], [d["points"][0] for d in m["drawings"]]) for m in images]
            # each image its own frame's image drawings, only those (in the full suite the first image may go before
            # the view sends: what comes must be right, and frames 6 and 7 must come)
            assert seen[-2:] == [(6, 6, [6.0]), (7, None, [])], seen
            assert all(m in ((5, 5, [5.0]), (6, 6, [6.0]), (7, None, [])) for m in seen), seen
            # pushed when new: "a" alone first if the push came between the two contexts' plots, then both (the
            # program's own plots, if a test before left any, may come along)
            assert {"a", "b"} <= set(names[-1]) and all("a" in n for n in names), names
    finally:
        view.stop()
