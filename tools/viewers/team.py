"""``tafel team``: TeamControl in the browser, without a running program.

It listens, and only listens, to one team's messages on the network (UDP port 10000 + team number,
or the port given) and to the GameController (port 3838), as NaoTH's TeamControl does: nothing is
ever sent, so it takes none of the team's message budget and is within the rules. Every robot heard
appears in the web view's Team panel with its pose, role, intention, ball, fallen or penalized, and
the time since its last message; the GameController's state on top.

The page is the web view's own (``tools/viewers/web/static``); here it is served by a debug server without
contexts. What was heard goes out as the topics ``TeamMates`` and ``GameState``, the JSON a running
program sends for the same representations, so the Team panel draws a program's teammates and a
listened team the same way. ``team:robots`` (telnet, console) answers the same as JSON.
"""

from __future__ import annotations

import argparse
import json
import logging
import select
import signal
import socket
import threading
import time
from dataclasses import dataclass, field
from typing import Any

from tafel.core.framework.errors import TafelError
from tafel.debug.router import DebugRouter
from tafel.debug.server import DebugServer
from tafel.debug.values import representation_message
from tafel.debug.websocket import WebServer
from tafel.modules.communication.game_controller_codec import PacketError, decode_game_state
from tafel.modules.communication.team_message_codec import TeamMessageError, unpack_message
from tafel.platforms.network import listening_socket
from tafel.representations.game import GAME_CONTROLLER_PORT, GameState
from tafel.representations.team import TEAM_PORT_BASE, TeamMate, TeamMates, TeamMessage
from tafel.tools.viewers.field import field_geometry
from tafel.tools.viewers.web.view import STATIC

log = logging.getLogger("tafel.team")
#: s after its last message that a robot leaves the view (TeamMatesProvider's default is 10)
FORGET_AFTER_S = 30.0
#: s after the last packet that the GameController counts as heard (B-Human's timeout)
GAME_CONTROLLER_TIMEOUT_S = 2.0
#: messages a second the page gets of each topic
PUBLISH_HZ = 5.0
#: the topics of a team listener's page
TOPICS = ("TeamMates", "GameState")


class TeamListenerError(TafelError):
    """The team's port cannot be listened on; the message says which and why."""


@dataclass
class TeamListener:
    """The team's messages and the GameController's packets as they arrive; receive only."""

    team: int
    port: int = 0
    """UDP port of the team's messages; 0: 10000 + team"""
    game_controller_port: int = GAME_CONTROLLER_PORT
    heard: dict[int, tuple[int, TeamMessage]] = field(default_factory=dict)
    """player -> (monotonic ns received, the message)"""
    game: GameState | None = None
    game_heard_ns: int = 0
    received: int = 0
    malformed: int = 0
    other_teams: int = 0
    sockets: dict[str, socket.socket] = field(default_factory=dict)

    @property
    def team_port(self) -> int:
        return self.port or TEAM_PORT_BASE + self.team

    def open(self) -> None:
        """Listen on the team port (an error when it cannot be had) and the GameController's (a warning)."""
        try:
            self.sockets["team"] = listening_socket(self.team_port)
        except OSError as error:
            raise TeamListenerError(f"cannot listen for team {self.team}'s messages on UDP port {self.team_port}: {error}; "
                                    "choose another with --port") from None
        try:
            self.sockets["game_controller"] = listening_socket(self.game_controller_port)
        except OSError as error:
            log.warning("cannot listen for the GameController on UDP port %d (%s): the team view shows no game state",
                        self.game_controller_port, error)

    def close(self) -> None:
        for sock in self.sockets.values():
            sock.close()
        self.sockets.clear()

    def wait(self, timeout: float) -> None:
        """Until something arrives or ``timeout`` s pass; then take everything that arrived."""
        if self.sockets:
            select.select(list(self.sockets.values()), [], [], timeout)
        else:
            time.sleep(timeout)
        self.poll(time.monotonic_ns())

    def poll(self, now_ns: int) -> None:
        for name, sock in self.sockets.items():
            while True:
                try:
                    data = sock.recv(2048)
                except (BlockingIOError, InterruptedError):
                    break
                except OSError as error:
                    log.warning("team view: reading UDP port failed (%s); listening on", error)
                    break
                if name == "team":
                    self.take_message(data, now_ns)
                else:
                    self.take_game_controller(data, now_ns)

    def take_message(self, data: bytes, now_ns: int) -> None:
        try:
            message = unpack_message(data)
        except TeamMessageError:
            self.malformed += 1
            return
        if message.team != self.team:
            self.other_teams += 1
            return
        self.received += 1
        self.heard[message.player] = (now_ns, message)

    def take_game_controller(self, data: bytes, now_ns: int) -> None:
        try:
            game = decode_game_state(data)
        except PacketError:
            return
        if self.team not in {team.team_number for team in game.teams}:
            return  # another game on this network
        self.game, self.game_heard_ns = game, now_ns

    def team_mates(self, now_ns: int) -> TeamMates:
        """Every robot heard within ``FORGET_AFTER_S``, by player number, with the age of its last message."""
        for player, (received_ns, _) in list(self.heard.items()):
            if (now_ns - received_ns) * 1e-9 > FORGET_AFTER_S:
                del self.heard[player]
        mates = [TeamMate(message=message, age=max(0.0, (now_ns - received_ns) * 1e-9))
                 for _, (received_ns, message) in sorted(self.heard.items())]
        return TeamMates(mates=mates, received=self.received, malformed=self.malformed + self.other_teams)

    def game_state(self, now_ns: int) -> GameState:
        """What the GameController last said, for this team (``heard`` False when silent for 2 s or never heard)."""
        game = GameState(**vars(self.game)) if self.game is not None else GameState()
        since = (now_ns - self.game_heard_ns) * 1e-9 if self.game is not None else 0.0
        game.heard = self.game is not None and since <= GAME_CONTROLLER_TIMEOUT_S
        game.seconds_since_packet = since
        game.team_number = self.team
        return game

    def snapshot(self, now_ns: int) -> dict[str, dict[str, Any]]:
        """The JSON messages of both topics, as a program sends its representations."""
        return {rep.__class__.__name__: representation_message(rep, "team", 0, now_ns)
                for rep in (self.team_mates(now_ns), self.game_state(now_ns))}


def run_team(args: argparse.Namespace) -> int:
    """Serve the team view until SIGINT or SIGTERM (or ``--seconds``)."""
    listener = TeamListener(args.team, args.port, args.game_controller_port)
    listener.open()
    router = DebugRouter()
    router.identity = (f"tafel team {args.team}: listening to UDP {listener.team_port} (team) and "
                       f"{listener.game_controller_port} (GameController), receive only")
    # commands are answered by process_pending in the loop below, between two reads: no lock needed
    router.register("team:robots", "every robot of the team heard, and the GameController's state (JSON)", "team:robots",
                    lambda command: json.dumps(listener.snapshot(time.monotonic_ns()), allow_nan=False))
    router.register("field:geometry", "the field's lines, circle, marks and goal posts as JSON (mm, field frame)", "field:geometry",
                    lambda command: json.dumps(field_geometry()))
    debug = DebugServer(router, host=args.host, port=args.debug_port, token=args.debug_token)
    wanted: dict[str, frozenset[str]] = {"topics": frozenset()}  # what some page subscribes to (the server's thread sets it)
    web = WebServer(debug, STATIC, host=args.host, port=args.web_port, topics=lambda: list(TOPICS),
                    on_subscriptions=lambda topics: wanted.update(topics=topics))
    try:
        debug.start()
        web.start()
    except OSError as error:
        listener.close()
        raise TeamListenerError(f"{error}; choose other ports with --debug-port and --web-port (0: a free one)") from None
    host = f"[{web.host}]" if ":" in web.host else web.host
    print(f"debug server listening on {debug.host}:{debug.port}", flush=True)
    print(f"web view at http://{host}:{web.port}/", flush=True)
    print(f"listening to team {args.team} on UDP port {listener.team_port}, the GameController on {listener.game_controller_port} "
          "(receive only)", flush=True)
    stopping = threading.Event()
    for sig in (signal.SIGINT, signal.SIGTERM):
        signal.signal(sig, lambda number, frame: stopping.set())
    deadline = time.monotonic() + args.seconds if args.seconds else None
    next_publish = 0.0
    try:
        while not stopping.is_set() and (deadline is None or time.monotonic() < deadline):
            listener.wait(0.02)
            debug.process_pending(budget_s=0.005)
            now = time.monotonic()
            if now >= next_publish and wanted["topics"]:
                next_publish = now + 1.0 / PUBLISH_HZ
                for topic, message in listener.snapshot(time.monotonic_ns()).items():
                    if topic in wanted["topics"]:
                        web.publish(topic, json.dumps(message, allow_nan=False))
    finally:
        debug.stop()
        listener.close()
    print(f"team {args.team}: {listener.received} messages heard, {listener.malformed} malformed, "
          f"{listener.other_teams} of other teams", flush=True)
    return 0

