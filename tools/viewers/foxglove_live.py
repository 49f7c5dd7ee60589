"""``tafel run --foxglove [HOST:]PORT``: the program live in Foxglove and Lichtblick.

A Foxglove WebSocket server (``foxglove-sdk``) publishes the channels recordings carry
(``foxglove_channels``), offers module parameters, modify values and debug requests in the Parameters
panel (``/BallDetector/min_radius``, ``/modify/NAME``, ``/debug_request/NAME``) and every debug command
as the service ``/tafel/command`` (a command line in, the answer out; as text, or as JSON
``{"command": LINE}`` answered by ``{"answer": TEXT}``, what Foxglove's Service Call panel sends).
Parameters and commands go through the debug server, so they run between frames like a console's and
follow its rules.

Clients reach the SDK's server (on a loopback port of its own) only through a ``Gate``: it applies the
web view's rules (``Host`` an address, ``localhost`` or the name listened on; ``Origin`` none, the same
or configured), the token when there is one, and lets in both names of the protocol
(``foxglove.sdk.v1`` and the older ``foxglove.websocket.v1``).

The loops never wait for it: after each frame they hand over copies of only those representations
that a subscribed topic needs (nothing when nobody subscribes), into a short queue that drops when
full; a thread of its own turns them into messages (JPEG and all) and the SDK sends them, dropping
for clients that read too slowly.
"""

from __future__ import annotations

import json
import logging
import re
import threading
from collections.abc import Callable, Iterable
from typing import Any

import foxglove
from foxglove import messages as fm
from foxglove.websocket import Capability, ChannelView, Client, Parameter, Service, ServiceRequest, ServiceSchema, StatusLevel

from tafel.tools.viewers.foxglove_channels import JSON_SCHEMAS, NEEDS, TOPICS, FoxgloveTranslator, json_schema_name
from tafel.tools.viewers.foxglove_gate import Gate, quiet_per_client_errors
from tafel.tools.viewers.live_feed import LiveFeed

log = logging.getLogger("tafel.foxglove")
#: the message of each protobuf topic (the others carry JSON)
PROTOBUF_TOPICS = {"/camera/top": fm.CompressedImage, "/camera/bottom": fm.CompressedImage,
                   "/camera/top/calibration": fm.CameraCalibration, "/camera/bottom/calibration": fm.CameraCalibration,
                   "/camera/top/annotations": fm.ImageAnnotations, "/camera/bottom/annotations": fm.ImageAnnotations,
                   "/scene": fm.SceneUpdate, "/tf": fm.FrameTransforms, "/log": fm.Log}
COMMAND_SERVICE = "/tafel/command"
#: how a client may call the command service: JSON first, because Foxglove's Service Call panel takes the first it knows
SERVICE_ENCODINGS = ["json", "text"]
COMMAND_USAGE = 'send {"command": "COMMAND LINE"}, e.g. {"command": "modules:list"} (or the command line as text)'


#: every representation the bridge may ask the loops for
FED: tuple[type, ...] = tuple(sorted({rep for reps in NEEDS.values() for rep in reps}, key=lambda rep: rep.__name__))


class FoxgloveLive(logging.Handler):
    """The live Foxglove server of one program, fed by ``after_frame`` (loops in this process) or by
    ``take`` (what context processes handed over)."""

    def __init__(self, host: str, port: int, *, ask: Callable[[str], str] | None, jpeg_quality: int = 80,
                 token: str | None = None, flags: Any = None, origins: Iterable[str] = ()) -> None:
        super().__init__(logging.INFO)
        #: what the loops hand over: with contexts in other processes, ``flags`` (shared) say which of ``FED``
        self.feed = LiveFeed(FED, flags=flags)
        self.host, self.port = host, port
        self.token = token
        self.origins = tuple(origins)
        self.gate: Gate | None = None
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
                    name=json_schema_name(topic), encoding="jsonschema", data=JSON_SCHEMAS[topic]))
        capabilities = [Capability.Parameters, Capability.Services] if self.ask is not None else []
        # no request schema: the SDK then takes a call in any of SERVICE_ENCODINGS (with one, only in that one)
        services = [Service(name=COMMAND_SERVICE, schema=ServiceSchema(name="tafel.command", request=None, response=None),
                            handler=self._command)] if self.ask is not None else []
        # the SDK's server listens on loopback inside; the gate that checks every client listens outside
        self.server = foxglove.start_server(name="tafel", host="127.0.0.1", port=0, capabilities=capabilities, server_listener=self,
                                            services=services, supported_encodings=SERVICE_ENCODINGS if services else None)
        quiet_per_client_errors()
        self.gate = Gate(self.host, self.port, self.server.port, token=self.token, origins=self.origins)
        try:
            self.port = self.gate.start()
        except OSError:
            self.server.stop()
            raise
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
        """Sets what the program takes; answers with every named parameter's value now, so that a refused one
        shows its old value again, and says why in a status message (and the log) the user sees."""
        refused = []
        for parameter in parameters:
            line = self._set_command(parameter.name, parameter.get_value())
            answer = self._ask(line) if line else (f"error: there is no parameter {parameter.name!r}; the names are "
                                                    "/MODULE/NAME, /modify/NAME and /debug_request/NAME")
            if answer.startswith("error:"):
                refused.append(f"{parameter.name} stays as it was: {answer[len('error:'):].strip()}")
        names = {p.name for p in parameters}
        current = [p for p in self._parameters() if p.name in names]
        for reason in refused:
            log.warning("foxglove: %s", reason)
            if self.server is not None:
                self.server.publish_status(reason, StatusLevel.Warning)
        return current

    def _command(self, request: ServiceRequest) -> bytes:
        """A command line as text (answered as text), or as JSON ``{"command": LINE}`` (answered ``{"answer": TEXT}``);
        JSON that is not such a request fails the call with a message saying what to send."""
        text = request.payload.decode("utf-8", "replace")
        if request.encoding != "json":
            return self._ask(text.strip()).encode()
        return json.dumps({"answer": self._ask(command_from_json(text))}).encode()

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


def command_from_json(text: str) -> str:
    """The command line of a JSON request: ``{"command": LINE}`` or a bare JSON string; anything else is a
    ``ValueError`` that says what to send."""
    try:
        request = json.loads(text)
    except ValueError as exc:
        raise ValueError(f"the request is not JSON ({exc}): {COMMAND_USAGE}") from None
    if isinstance(request, dict):
        unknown = sorted(set(request) - {"command"})
        if unknown:
            raise ValueError(f"unknown field {unknown[0]!r} in the request: {COMMAND_USAGE}")
        request = request.get("command")
    if not isinstance(request, str) or not request.strip():
        raise ValueError(f"the request names no command: {COMMAND_USAGE}")
    return request.strip()


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
