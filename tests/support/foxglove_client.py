"""A Foxglove WebSocket client written from the protocol's published specification
(github.com/foxglove/ws-protocol), with the ``websockets`` package and no ``foxglove-sdk``: what
Foxglove and Lichtblick do when they connect, for tests and benchmarks. The specification calls the
subprotocol ``foxglove.websocket.v1``; foxglove-sdk knows the same protocol only under its new name
``foxglove.sdk.v1`` (what current Foxglove and Lichtblick ask for); Tafel's gate takes both."""

from __future__ import annotations

import json
import socket
import struct
import time
from typing import Any
from urllib.parse import urlsplit

from websockets.exceptions import ConnectionClosed
from websockets.sync.client import connect

SUBPROTOCOL = "foxglove.sdk.v1"
MESSAGE_DATA, SERVICE_CALL_REQUEST, SERVICE_CALL_RESPONSE = 0x01, 0x02, 0x03


class ServiceCallFailure(Exception):
    """The server answered a service call with ``serviceCallFailure`` (its message is the exception's)."""


class FoxgloveClient:
    """``host``: the name the client believes it reaches (its ``Host`` header), while it connects to the
    address of ``url``: what a browser does after DNS rebinding. ``origin``: the page it runs in."""

    def __init__(self, url: str, timeout: float = 10.0, subprotocol: str = SUBPROTOCOL, headers: dict[str, str] | None = None,
                 host: str | None = None, origin: str | None = None) -> None:
        parts = urlsplit(url)
        sock = socket.create_connection((parts.hostname, parts.port), timeout=timeout)
        if host is not None:
            url = parts._replace(netloc=f"{host}:{parts.port}").geturl()
        # close_timeout: a client closing under a stream of images waits at most 1 s for the server's close
        # frame (websockets' default of 10 s made every such teardown take 10 s)
        try:
            self.socket = connect(url, sock=sock, subprotocols=[subprotocol], max_size=None, open_timeout=timeout,
                                  additional_headers=headers, origin=origin, proxy=None, legacy=True, close_timeout=1.0)
        except BaseException:
            sock.close()
            raise
        self.timeout = timeout
        self.channels: dict[int, dict[str, Any]] = {}  # channel id -> its advertisement
        self.services: dict[str, dict[str, Any]] = {}
        self.server_info: dict[str, Any] = {}
        self.subscriptions: dict[int, str] = {}  # subscription id -> topic
        self.received: dict[str, list[tuple[int, bytes]]] = {}  # topic -> [(timestamp ns, payload)]
        self.replies: list[dict[str, Any]] = []
        self.service_answers: dict[int, bytes] = {}
        self.next_id = 1
        self.closed = False

    def close(self) -> None:
        self.socket.close()

    # ------------------------------------------------------------------------------- receiving
    def pump(self, seconds: float) -> None:
        """Read whatever the server sends for ``seconds``."""
        deadline = time.monotonic() + seconds
        while (left := deadline - time.monotonic()) > 0:
            try:
                frame = self.socket.recv(timeout=left)
            except TimeoutError:
                return
            except ConnectionClosed:  # the program ended
                self.closed = True
                return
            self._handle(frame)

    def wait_for(self, what: Any, seconds: float | None = None) -> Any:
        """Pump until ``what()`` gives something true; returns it."""
        deadline = time.monotonic() + (seconds or self.timeout)
        while time.monotonic() < deadline:
            found = what()
            if found:
                return found
            self.pump(0.05)
        raise TimeoutError("the Foxglove server did not send what was expected in time")

    def _handle(self, frame: str | bytes) -> None:
        if isinstance(frame, str):
            message = json.loads(frame)
            op = message.get("op")
            if op == "serverInfo":
                self.server_info = message
            elif op == "advertise":
                for channel in message["channels"]:
                    self.channels[channel["id"]] = channel
            elif op == "advertiseServices":
                for service in message["services"]:
                    self.services[service["name"]] = service
            else:
                self.replies.append(message)
            return
        op = frame[0]
        if op == MESSAGE_DATA:
            subscription, stamp = struct.unpack_from("<IQ", frame, 1)
            topic = self.subscriptions.get(subscription)
            if topic is not None:
                self.received.setdefault(topic, []).append((stamp, bytes(frame[13:])))
        elif op == SERVICE_CALL_RESPONSE:
            _service, call, length = struct.unpack_from("<III", frame, 1)
            self.service_answers[call] = bytes(frame[13 + length:])

    # --------------------------------------------------------------------------------- asking
    def topics(self) -> dict[str, dict[str, Any]]:
        return {c["topic"]: c for c in self.channels.values()}

    def subscribe(self, *topics: str) -> None:
        by_topic = self.wait_for(lambda: self.topics() if set(topics) <= set(self.topics()) else None)
        subscriptions = []
        for topic in topics:
            self.subscriptions[self.next_id] = topic
            subscriptions.append({"id": self.next_id, "channelId": by_topic[topic]["id"]})
            self.next_id += 1
        self.socket.send(json.dumps({"op": "subscribe", "subscriptions": subscriptions}))

    def unsubscribe_all(self) -> None:
        self.socket.send(json.dumps({"op": "unsubscribe", "subscriptionIds": list(self.subscriptions)}))
        self.subscriptions.clear()

    def _request(self, message: dict[str, Any]) -> dict[str, Any]:
        request_id = f"r{self.next_id}"
        self.next_id += 1
        self.socket.send(json.dumps({**message, "id": request_id}))
        return self.wait_for(lambda: next((r for r in self.replies if r.get("id") == request_id), None))

    def get_parameters(self, *names: str) -> dict[str, Any]:
        reply = self._request({"op": "getParameters", "parameterNames": list(names)})
        return {p["name"]: p.get("value") for p in reply["parameters"]}

    def set_parameters(self, values: dict[str, Any]) -> dict[str, Any]:
        reply = self._request({"op": "setParameters", "parameters": [{"name": k, "value": v} for k, v in values.items()]})
        return {p["name"]: p.get("value") for p in reply["parameters"]}

    def call_service(self, name: str, payload: bytes, encoding: str = "text") -> bytes:
        service = self.wait_for(lambda: self.services.get(name))
        call = self.next_id
        self.next_id += 1
        data = encoding.encode()
        self.socket.send(struct.pack("<BIII", SERVICE_CALL_REQUEST, service["id"], call, len(data)) + data + payload)

        def answered() -> bytes | None:
            for reply in self.replies:
                if reply.get("op") == "serviceCallFailure" and reply.get("callId") == call:
                    raise ServiceCallFailure(reply.get("message", ""))
            return self.service_answers.get(call)

        return self.wait_for(answered)
