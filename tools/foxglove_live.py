"""``tafel run --foxglove [HOST:]PORT``: the program live in Foxglove and Lichtblick.

A Foxglove WebSocket server (``foxglove-sdk``) publishes the channels recordings carry
(``foxglove_channels``), offers module parameters, modify values and debug requests in the Parameters
panel (``/BallDetector/min_radius``, ``/modify/NAME``, ``/debug_request/NAME``) and every debug command
as the service ``/tafel/command`` (a command line in, the answer out). Parameters and commands go
through the debug server, so they run between frames like a console's and follow its rules.

The loops never wait for it: after each frame they hand over copies of only those representations
that a subscribed topic needs (nothing when nobody subscribes), into a short queue that drops when
full; a thread of its own turns them into messages (JPEG and all) and the SDK sends them, dropping
for clients that read too slowly.
"""

from __future__ import annotations

import asyncio
import hmac
import logging
import re
import threading
from collections.abc import Callable
from typing import Any
from urllib.parse import parse_qs, urlsplit

import foxglove
from foxglove import messages as fm
from foxglove.websocket import Capability, ChannelView, Client, MessageSchema, Parameter, Service, ServiceRequest, ServiceSchema

from tafel.tools.foxglove_channels import JSON_SCHEMA, NEEDS, TOPICS, FoxgloveTranslator
from tafel.tools.live_feed import LiveFeed

log = logging.getLogger("tafel.foxglove")
#: the message of each protobuf topic (the others carry JSON)
PROTOBUF_TOPICS = {"/camera/top": fm.CompressedImage, "/camera/bottom": fm.CompressedImage,
                   "/camera/top/calibration": fm.CameraCalibration, "/camera/bottom/calibration": fm.CameraCalibration,
                   "/camera/top/annotations": fm.ImageAnnotations, "/camera/bottom/annotations": fm.ImageAnnotations,
                   "/scene": fm.SceneUpdate, "/tf": fm.FrameTransforms, "/log": fm.Log}
COMMAND_SERVICE = "/tafel/command"


#: every representation the bridge may ask the loops for
FED: tuple[type, ...] = tuple(sorted({rep for reps in NEEDS.values() for rep in reps}, key=lambda rep: rep.__name__))


class FoxgloveLive(logging.Handler):
    """The live Foxglove server of one program, fed by ``after_frame`` (loops in this process) or by
    ``take`` (what context processes handed over)."""

    def __init__(self, host: str, port: int, *, ask: Callable[[str], str] | None, jpeg_quality: int = 80,
                 token: str | None = None, flags: Any = None) -> None:
        super().__init__(logging.INFO)
        #: what the loops hand over: with contexts in other processes, ``flags`` (shared) say which of ``FED``
        self.feed = LiveFeed(FED, flags=flags)
        self.host, self.port = host, port
        self.token = token
        self.gate: TokenGate | None = None
        self.ask = ask
        self.subscribers: dict[str, int] = {}
        self.translator = FoxgloveTranslator(jpeg_quality, wanted=lambda topic: self.subscribers.get(topic, 0) > 0)
        self.sent = 0
        self.channels: dict[str, foxglove.Channel] = {}
        self.server: Any = None
        self.thread = threading.Thread(target=self._work, name="tafel-foxglove", daemon=True)

    # -------------------------------------------------------------------------------- lifecycle
    def start(self) -> tuple[str, int]:
        for topic in TOPICS:
            message = PROTOBUF_TOPICS.get(topic)
            if message is not None:
                schema = message.get_schema()
                self.channels[topic] = foxglove.Channel(topic, message_encoding="protobuf",
                                                        schema=foxglove.Schema(name=schema.name, encoding=schema.encoding, data=schema.data))
            else:
                self.channels[topic] = foxglove.Channel(topic, message_encoding="json", schema=foxglove.Schema(
                    name=f"tafel.foxglove{topic.replace('/', '.')}", encoding="jsonschema", data=JSON_SCHEMA))
        capabilities = [Capability.Parameters, Capability.Services] if self.ask is not None else []
        services = [Service(name=COMMAND_SERVICE, schema=ServiceSchema(
            name="tafel.command", request=MessageSchema(encoding="text", schema=foxglove.Schema(name="command line", encoding="", data=b"")),
            response=MessageSchema(encoding="text", schema=foxglove.Schema(name="answer", encoding="", data=b""))),
            handler=self._command)] if self.ask is not None else []
        # with a token the SDK's server listens inside, and a gate that checks the token listens outside
        inside = ("127.0.0.1", 0) if self.token is not None else (self.host, self.port)
        self.server = foxglove.start_server(name="tafel", host=inside[0], port=inside[1], capabilities=capabilities,
                                            server_listener=self, services=services)
        if self.token is not None:
            self.gate = TokenGate(self.host, self.port, self.token, self.server.port)
            self.port = self.gate.start()
        else:
            self.port = self.server.port
        self.thread.start()
        logging.getLogger("tafel").addHandler(self)
        return self.host, self.port

    def stop(self) -> None:
        logging.getLogger("tafel").removeHandler(self)
        if self.thread.is_alive():
            self.feed.close()
            self.thread.join(timeout=5)
        if self.gate is not None:
            self.gate.stop()
        if self.server is not None:
            self.server.stop()
            self.server = None
        for channel in self.channels.values():
            channel.close()

    # ------------------------------------------------------------------------------- the thread
    def _work(self) -> None:
        while True:
            item = self.feed.get()
            if item is None:
                return
            context, value, time_ns, wall = item.context, item.value, item.time_ns, item.wall_ns
            try:
                for out in self.translator.feed(context, value, time_ns, wall):
                    self._send(out.topic, out.message, out.wall_ns)
            except Exception:  # noqa: BLE001 - a message that cannot be made is skipped, the bridge goes on
                log.exception("foxglove: cannot publish %s", type(value).__name__)

    def _send(self, topic: str, message: Any, wall_ns: int) -> None:
        channel = self.channels[topic]
        channel.log(message if isinstance(message, dict) else message.encode(), log_time=wall_ns)
        self.sent += 1

    def emit(self, record: logging.LogRecord) -> None:
        """A log line of the program (any thread) to ``/log``, when somebody listens."""
        out = self.translator.log_record(record, 0)
        if out is not None:
            try:
                self._send(out.topic, out.message, out.wall_ns)
            except Exception:  # noqa: BLE001 - logging must never fail the caller
                pass

    # ------------------------------------------------------------------------- server listener
    def on_subscribe(self, client: Client, channel: ChannelView) -> None:
        self.subscribers[channel.topic] = self.subscribers.get(channel.topic, 0) + 1
        if channel.topic == "/scene":
            self.translator.resend_field()
        self._update_needed()

    def on_unsubscribe(self, client: Client, channel: ChannelView) -> None:
        self.subscribers[channel.topic] = max(0, self.subscribers.get(channel.topic, 0) - 1)
        self._update_needed()

    def _update_needed(self) -> None:
        self.feed.need(rep for topic, count in self.subscribers.items() if count for rep in NEEDS.get(topic, ()))

    def on_get_parameters(self, client: Client, param_names: list[str], request_id: str | None = None) -> list[Parameter]:
        parameters = self._parameters()
        return [p for p in parameters if not param_names or p.name in param_names]

    def on_set_parameters(self, client: Client, parameters: list[Parameter], request_id: str | None = None) -> list[Parameter]:
        for parameter in parameters:
            line = self._set_command(parameter.name, parameter.get_value())
            answer = self._ask(line) if line else f"error: no parameter {parameter.name}"
            if answer.startswith("error:"):
                log.warning("foxglove: %s: %s", parameter.name, answer)
        names = {p.name for p in parameters}
        return [p for p in self._parameters() if p.name in names]

    def _command(self, request: ServiceRequest) -> bytes:
        line = request.payload.decode("utf-8", "replace").strip()
        return self._ask(line).encode()

    # ------------------------------------------------------------------------------ parameters
    def _ask(self, line: str) -> str:
        assert self.ask is not None
        try:
            return self.ask(line)
        except TimeoutError:
            return f"error: {line.split(' ', 1)[0]} got no answer in time (is the program running?)"

    def _parameters(self) -> list[Parameter]:
        """Module parameters, modify values and debug requests, from the debug server's lists."""
        result = []
        for module, values in re.findall(r"^  (\w+): (.*)$", self._ask("parameter:list"), re.MULTILINE):
            for name, value in re.findall(r"(\w+)=((?:\"[^\"]*\")|[^,]*)(?:, |$)", values):
                result.append(Parameter(f"/{module}/{name}", value=_native(value)))
        for name, value in re.findall(r"^  (\S+) = (.*?)(?:  \(pinned to .*\))?$", self._ask("modify:list"), re.MULTILINE):
            result.append(Parameter(f"/modify/{name}", value=_native(value)))
        for state, name in re.findall(r"^  (on|off) +(\S+)", self._ask("debug_request:list"), re.MULTILINE):
            result.append(Parameter(f"/debug_request/{name}", value=state == "on"))
        return result

    @staticmethod
    def _set_command(name: str, value: Any) -> str:
        parts = name.strip("/").split("/", 1)
        if len(parts) != 2:
            return ""
        group, item = parts
        if isinstance(value, bool):
            text = "on" if value else "off"
        else:
            text = repr(value) if isinstance(value, float) else str(value)
        if group == "debug_request":
            return f"debug_request:set -name {item} -value {text}"
        if group == "modify":
            return f"modify:set -name {item} -value {text}"
        return f"parameter:set -module {group} -name {item} -value {text}"


class TokenGate:
    """The door in front of the SDK's server when the program has a token: a WebSocket connection is let
    through (to the server listening on loopback inside) only with ``?token=T`` in its URL or an
    ``Authorization: Bearer T`` header, the way the debug server asks ``auth T`` first. It also lets in
    clients that ask for the protocol by its old name, ``foxglove.websocket.v1`` (older Lichtblick)."""

    SUBPROTOCOLS = ("foxglove.sdk.v1", "foxglove.websocket.v1")

    def __init__(self, host: str, port: int, token: str, inside_port: int) -> None:
        self.host, self.port, self.token, self.inside_port = host, port, token, inside_port
        self.loop: asyncio.AbstractEventLoop | None = None
        self.stopping: asyncio.Event | None = None
        self.ready = threading.Event()
        self.error: BaseException | None = None
        self.thread = threading.Thread(target=self._run, name="tafel-foxglove-gate", daemon=True)
        self.refused = 0

    def start(self) -> int:
        self.thread.start()
        self.ready.wait(10)
        if self.error is not None:
            raise OSError(f"cannot listen on {self.host}:{self.port}: {self.error}")
        return self.port

    def stop(self) -> None:
        if self.loop is not None and self.loop.is_running() and self.stopping is not None:
            self.loop.call_soon_threadsafe(self.stopping.set)
            self.thread.join(timeout=5)

    def allowed(self, path: str, authorization: str | None) -> bool:
        given = parse_qs(urlsplit(path).query).get("token", [""])[0]
        if not given and authorization and authorization.startswith("Bearer "):
            given = authorization[len("Bearer "):]
        return bool(given) and hmac.compare_digest(given.encode(), self.token.encode())

    def _run(self) -> None:
        from websockets.asyncio.client import connect
        from websockets.asyncio.server import serve
        from websockets.exceptions import ConnectionClosed

        def check(connection: Any, request: Any) -> Any:
            if self.allowed(request.path, request.headers.get("Authorization")):
                return None
            self.refused += 1
            log.warning("foxglove: refused a connection without the right token (%d so far)", self.refused)
            return connection.respond(401, "this program needs its token: connect to ws://HOST:PORT/?token=TOKEN\n")

        async def relay(client: Any) -> None:
            try:  # the SDK speaks the one protocol under its new name only
                async with connect(f"ws://127.0.0.1:{self.inside_port}", subprotocols=[self.SUBPROTOCOLS[0]], max_size=None) as inside:
                    async def pump(source: Any, target: Any) -> None:
                        async for message in source:
                            await target.send(message)
                    done, pending = await asyncio.wait([asyncio.create_task(pump(client, inside)),
                                                        asyncio.create_task(pump(inside, client))],
                                                       return_when=asyncio.FIRST_COMPLETED)
                    for task in pending:
                        task.cancel()
            except (ConnectionClosed, OSError):
                pass

        async def main() -> None:
            self.stopping = asyncio.Event()
            try:
                server = await serve(relay, self.host, self.port, process_request=check, subprotocols=list(self.SUBPROTOCOLS),
                                     max_size=None)
            except OSError as exc:
                self.error = exc
                self.ready.set()
                return
            self.port = server.sockets[0].getsockname()[1]
            self.ready.set()
            async with server:
                await self.stopping.wait()

        self.loop = asyncio.new_event_loop()
        try:
            self.loop.run_until_complete(main())
        finally:
            self.loop.close()


def _native(text: str) -> Any:
    """A listed value as a number, a truth value or text."""
    text = text.strip()
    if text in ("true", "True", "on"):
        return True
    if text in ("false", "False", "off"):
        return False
    try:
        return float(text)
    except ValueError:
        return text.strip('"')
