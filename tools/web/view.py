"""The web view of one program run: the page's files, its WebSocket, and the feed of subscribed data.

The page (``static/``) speaks the debug protocol over the debug server's WebSocket transport
(``tafel.debug.websocket``). What it subscribes to, representations by name, the loops hand over as
copies (``live_feed``), and this view's own thread encodes outside the loops: camera images as JPEG,
everything else as the JSON of ``representation:print -format json``. Each message is encoded once
for all tabs; a tab that reads slowly loses messages, never the loops' time.
"""

from __future__ import annotations

import json
import logging
import struct
import threading
from collections.abc import Iterable
from pathlib import Path
from typing import Any

import numpy as np

from tafel.core.runtime import name_os_thread
from tafel.debug.commands import jpeg_bytes, representation_message
from tafel.debug.concepts import DebugDrawings, DebugPlots, ModuleTimes
from tafel.debug.server import DebugServer
from tafel.debug.websocket import WebServer
from tafel.tools.live_feed import Handed, LiveFeed, feed_order

log = logging.getLogger("tafel.web")
STATIC = Path(__file__).resolve().parent / "static"
DEFAULT_WEB_PORT = 5480
#: always offered: the frame's drawings, plot values and module times of each context
DEBUG_TOPICS = (DebugDrawings, DebugPlots, ModuleTimes)


def web_topics(reps: Iterable[type]) -> list[type]:
    """What a page may subscribe to: these representations and the debug topics, in the feed's order."""
    return list(feed_order([*reps, *DEBUG_TOPICS]))


def is_image(value: Any) -> bool:
    image = getattr(value, "image", None)
    return isinstance(image, np.ndarray) and image.ndim == 3 and image.shape[2] == 3


def image_message(item: Handed, quality: int) -> bytes:
    """A camera image as the page gets it: header length (4 bytes, big-endian), JSON header, JPEG."""
    image = item.value.image
    header = json.dumps({"topic": type(item.value).__name__, "context": item.context, "frame": item.frame,
                         "time_ns": item.time_ns, "width": int(image.shape[1]), "height": int(image.shape[0]),
                         "horizontal_fov": float(getattr(item.value, "horizontal_fov", 0.0))}).encode()
    return struct.pack(">I", len(header)) + header + jpeg_bytes(image, quality)


def json_message(item: Handed) -> str:
    return json.dumps(representation_message(item.value, item.context, item.frame, item.time_ns), allow_nan=False)


class WebView:
    """Serves the page on ``host:port`` for the debug server ``debug``; offers ``reps`` as topics."""

    def __init__(self, debug: DebugServer, reps: Iterable[type], *, host: str = "127.0.0.1", port: int = DEFAULT_WEB_PORT,
                 jpeg_quality: int = 80, flags: Any = None) -> None:
        self.feed = LiveFeed(web_topics(reps), flags=flags)
        self.by_name = {rep.__name__: rep for rep in self.feed.reps}
        self.jpeg_quality = jpeg_quality
        self.wanted: frozenset[str] = frozenset()
        self.server = WebServer(debug, STATIC, host=host, port=port, topics=lambda: sorted(self.by_name),
                                on_subscriptions=self._subscribed)
        self.encoded = 0
        self.thread = threading.Thread(target=self._work, name="tafel-web", daemon=True)
        debug.router.register("web:status", "the web view: pages connected, topics subscribed, messages encoded and sent, "
                              "dropped for slow pages, skipped for -hz (JSON)", "web:status", lambda command: json.dumps(self.status()))

    def start(self) -> tuple[str, int]:
        address = self.server.start()
        self.thread.start()
        return address

    def stop(self) -> None:
        if self.thread.is_alive():
            self.feed.close()
            self.thread.join(timeout=5)

    def url(self) -> str:
        host = self.server.host
        return f"http://{'[' + host + ']' if ':' in host else host}:{self.server.port}/"

    def status(self) -> dict[str, Any]:
        sessions = self.server.sessions()
        return {"url": self.url(), "pages": len(sessions), "topics": sorted(self.wanted), "encoded": self.encoded,
                **{key: sum(getattr(s, key) for s in sessions) + gone for key, gone in self.server.gone.items()},
                "handed_over_dropped": self.feed.dropped}

    def _subscribed(self, topics: frozenset[str]) -> None:
        self.wanted = topics
        self.feed.need(self.by_name[name] for name in topics if name in self.by_name)

    def _work(self) -> None:
        name_os_thread("tafel-web")
        while True:
            item = self.feed.get()
            if item is None:
                return
            topic = type(item.value).__name__
            if topic not in self.wanted:  # unsubscribed since it was handed over
                continue
            try:
                message: str | bytes = image_message(item, self.jpeg_quality) if is_image(item.value) else json_message(item)
            except Exception:  # noqa: BLE001 - a message that cannot be made is skipped; the view goes on
                log.exception("web: cannot encode %s", topic)
                continue
            self.encoded += 1
            self.server.publish(topic, message)
