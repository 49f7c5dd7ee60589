"""The web view of one program run: the page's files, its WebSocket, and the feed of subscribed data.

The page (``static/``) speaks the debug protocol over the debug server's WebSocket transport
(``tafel.debug.websocket``). What it subscribes to, representations by name, the loops hand over as
copies (``live_feed``), and this view's own thread encodes outside the loops: camera images as JPEG,
everything else as the JSON of ``representation:print -format json``. Each message is encoded once
for all tabs; a tab that reads slowly loses messages, never the loops' time.

Two topics are the view's own work. A camera image carries the image drawings of the frame it was
used in (its header's ``drawings``), so the page draws them over that image and no other. And
``PlotNames`` lists every plot name the program has (``plot:get``, asked twice a second while a page
follows them), sent when one is new and once a second, so a page learns new names at once without
taking every frame's plot values.
"""

from __future__ import annotations

import json
import logging
import queue
import struct
import threading
import time
from collections.abc import Iterable
from pathlib import Path
from typing import Any

import numpy as np

from tafel.core.runtime import name_os_thread
from tafel.debug.concepts import DebugDrawings, DebugPlots, ModuleTimes
from tafel.debug.server import DebugServer
from tafel.debug.values import jpeg_bytes, representation_message
from tafel.debug.websocket import WebServer
from tafel.representations.motion import JointSensorData, TorsoPose
from tafel.tools.viewers.live_feed import Handed, LiveFeed, feed_order
from tafel.tools.viewers.robot_links import links_message

log = logging.getLogger("tafel.web")
STATIC = Path(__file__).resolve().parent / "static"
DEFAULT_WEB_PORT = 5480
#: always offered: the frame's drawings, plot values and module times of each context
DEBUG_TOPICS = (DebugDrawings, DebugPlots, ModuleTimes)
#: the topic that lists the plot names seen so far: {"names": [...]}
PLOT_NAMES = "PlotNames"
#: s between two lists of plot names when none is new (what a page that just subscribed waits at most)
PLOT_NAMES_EVERY = 1.0
#: s between two questions for the plot names (plot:get) while a page follows them
PLOT_NAMES_POLL = 0.5
#: the topic of the robot's links and cameras in the robot frame, from the measured joints and the torso's pose
ROBOT_LINKS = "RobotLinks"
#: what it is computed from (the motion context's)
ROBOT_LINKS_FROM = (JointSensorData, TorsoPose)
#: RobotLinks messages a second at most (the joints come 100 times a second)
ROBOT_LINKS_HZ = 20.0
#: the contexts whose camera images the page is sent (their drawings travel with them)
IMAGE_CONTEXTS = ("cognition",)
#: s an encoded image waits for its frame's drawings when the feed brings nothing else
PAIRING_WAIT = 0.05


def web_topics(reps: Iterable[type]) -> list[type]:
    """What a page may subscribe to: these representations and the debug topics, in the feed's order."""
    return list(feed_order([*reps, *DEBUG_TOPICS]))


def is_image(value: Any) -> bool:
    image = getattr(value, "image", None)
    return isinstance(image, np.ndarray) and image.ndim == 3 and image.shape[2] == 3


def image_canvas(topic: str) -> str:
    """The drawing canvas of a camera image topic: the top camera's image -> ``image:top``."""
    return "image:" + topic.removeprefix("CameraImage").lower()


def image_header(item: Handed, drawings: DebugDrawings | None) -> bytes:
    """The start of a camera image's message, before its JPEG: header length (4 bytes, big-endian), JSON header.

    The header's ``drawings`` are the primitives of the image's canvas from ``drawings``, the drawings
    of the frame the image was used in (none when that frame's drawings did not come)."""
    image, topic = item.value.image, type(item.value).__name__
    canvas = image_canvas(topic)
    primitives = [{"kind": p.kind, "points": p.points, "color": p.color, "width": p.width, "text": p.text}
                  for p in (drawings.primitives if drawings is not None else ()) if p.canvas == canvas]
    header = json.dumps({"topic": topic, "context": item.context, "frame": item.frame, "time_ns": item.time_ns,
                         "width": int(image.shape[1]), "height": int(image.shape[0]),
                         "horizontal_fov": float(getattr(item.value, "horizontal_fov", 0.0)),
                         "drawings_frame": item.frame if drawings is not None else None, "drawings": primitives},
                        allow_nan=False).encode()
    return struct.pack(">I", len(header)) + header


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
        self.server = WebServer(debug, STATIC, host=host, port=port, topics=lambda: sorted([*self.by_name, PLOT_NAMES, ROBOT_LINKS]),
                                on_subscriptions=self._subscribed)
        self.debug = debug
        self.encoded = 0
        #: encoded images waiting for the drawings of their frame: (item, JPEG), by context
        self.waiting: dict[str, list[tuple[Handed, bytes]]] = {}
        self.plot_names: set[str] = set()
        self.plot_names_at = 0.0  # monotonic s of the last list sent
        self.torso: TorsoPose | None = None  # the last TorsoPose, for RobotLinks
        self.links_at = 0.0  # monotonic s of the last RobotLinks sent
        self.names_lock = threading.Lock()
        self.stopping = threading.Event()
        self.thread = threading.Thread(target=self._work, name="tafel-web", daemon=True)
        self.names_thread = threading.Thread(target=self._poll_plot_names, name="tafel-web-names", daemon=True)
        debug.router.register("web:status", "the web view: pages connected, topics subscribed, messages encoded and sent, "
                              "dropped for slow pages, skipped for -hz (JSON)", "web:status", lambda command: json.dumps(self.status()))

    def start(self) -> tuple[str, int]:
        address = self.server.start()
        self.thread.start()
        self.names_thread.start()
        return address

    def stop(self) -> None:
        self.stopping.set()
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
        needed = {self.by_name[name] for name in topics if name in self.by_name}
        only: dict[type, tuple[str, ...]] = {}
        if any(name.startswith("CameraImage") for name in topics) and DebugDrawings.__name__ not in topics:
            needed.add(DebugDrawings)  # an image travels with its frame's drawings: those of the images' context
            only[DebugDrawings] = IMAGE_CONTEXTS
        if ROBOT_LINKS in topics:  # computed here from the joints and the torso's pose
            for rep in ROBOT_LINKS_FROM:
                if rep in self.feed.index and rep not in needed:  # the motion context's, not a hand-over's copy
                    needed.add(rep)
                    only[rep] = ("motion",)
        self.feed.need(needed, only)

    def _work(self) -> None:
        name_os_thread("tafel-web")
        while True:
            try:
                item = self.feed.get(timeout=PAIRING_WAIT if self.waiting else PLOT_NAMES_EVERY)
            except queue.Empty:
                self._release_images()
                continue
            if item is None:
                return
            try:
                self._take(item)
            except Exception:  # noqa: BLE001 - a message that cannot be made is skipped; the view goes on
                log.exception("web: cannot encode %s", type(item.value).__name__)

    def _take(self, item: Handed) -> None:
        """One handed-over copy: images wait for their frame's drawings, everything else goes out as JSON."""
        topic = type(item.value).__name__
        waiting = self.waiting.get(item.context)
        if waiting and waiting[0][0].frame != item.frame:  # their frame brought no drawings
            self._release_images(item.context)
        if topic == DebugDrawings.__name__ and item.context in self.waiting:
            self._release_images(item.context, item.value)
        if topic == DebugPlots.__name__:
            self._note_plot_names(item.value.names)
        if topic == TorsoPose.__name__:
            self.torso = item.value
        if topic == JointSensorData.__name__ and ROBOT_LINKS in self.wanted and time.monotonic() - self.links_at >= 1 / ROBOT_LINKS_HZ:
            self.links_at = time.monotonic()
            message = {"topic": ROBOT_LINKS, "context": item.context, "frame": item.frame, "time_ns": item.time_ns,
                       "value": links_message(item.value.position, self.torso)}
            self._publish(ROBOT_LINKS, json.dumps(message, allow_nan=False))
        if topic not in self.wanted:  # unsubscribed since it was handed over, or only needed here
            return
        if is_image(item.value):
            self.waiting.setdefault(item.context, []).append((item, jpeg_bytes(item.value.image, self.jpeg_quality)))
            return
        self._publish(topic, json_message(item))

    def _release_images(self, context: str | None = None, drawings: DebugDrawings | None = None) -> None:
        """Send the waiting images (of ``context``, else all), with their frame's ``drawings`` if they came."""
        for name in [context] if context is not None else list(self.waiting):
            for item, jpeg in self.waiting.pop(name, []):
                topic = type(item.value).__name__
                if topic in self.wanted:
                    self._publish(topic, image_header(item, drawings) + jpeg)

    def _poll_plot_names(self) -> None:
        """Its own thread: while a page follows PlotNames, ask the program for its plot names twice a second."""
        name_os_thread("tafel-web-names")
        while not self.stopping.wait(PLOT_NAMES_POLL):
            if PLOT_NAMES not in self.wanted:
                continue
            try:
                answer = self.debug.ask("plot:get")
            except (TimeoutError, OSError):  # the loops are busy or gone: ask again next time
                continue
            if not answer.startswith("error:"):
                self._note_plot_names(line.strip().split(" (")[0] for line in answer.splitlines() if line.strip())

    def _note_plot_names(self, names: Iterable[str]) -> None:
        """Names seen (asked for, or in plot values that passed): sent at once when one is new, else once a second."""
        with self.names_lock:
            new = set(names) - self.plot_names
            self.plot_names |= new
            if PLOT_NAMES not in self.wanted or not (new or time.monotonic() - self.plot_names_at >= PLOT_NAMES_EVERY):
                return
            self.plot_names_at = time.monotonic()
            message = json.dumps({"topic": PLOT_NAMES, "context": "", "value": {"names": sorted(self.plot_names)}})
        self._publish(PLOT_NAMES, message)

    def _publish(self, topic: str, message: str | bytes) -> None:
        self.encoded += 1
        self.server.publish(topic, message)
