"""A robot's UDP in a game: the GameController's packets in, return packets out, team messages both ways.

Every platform with a network (the simulators, the NAO, the dummy) owns one ``GameNetwork`` and calls
it from cognition's ``sense`` and ``act``. It moves bytes only: modules decode and encode them
(``GameStateProvider``, ``TeamMatesProvider``, ``GameControllerReporter``, ``TeamMessageSender``), so
a log replays exactly what was heard.

Its settings are the ``[game]`` table of the configuration (see ``config/general.toml``). A socket
that cannot be opened (port taken without SO_REUSEPORT, no network) is a warning, never a crash: the
robot then plays without it, as the rules' manual mode expects.

``game.network`` says where the bytes go: ``"udp"`` (real sockets: the robot, matches, a
GameController on this machine), ``"simulated"`` (inside the program: the robot hears its own team
messages a frame later, as a real broadcast echoes back, and no GameController; nothing from another
program on the machine gets in, so equal runs stay equal), or ``"auto"``: the platform's choice,
``simulated`` for the simulators and the dummy, ``udp`` for the NAO and matches.
"""

from __future__ import annotations

import logging
import socket
import time
from collections import deque
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any, ClassVar, Literal

from tafel.core.framework.config import ConfigError
from tafel.core.framework.manager import Blackboard
from tafel.core.framework.values import convert
from tafel.representations.game import GAME_CONTROLLER_PORT, RETURN_PORT, Datagram, GameControllerPackets, GameControllerReturn
from tafel.representations.infrastructure import FrameInfo
from tafel.representations.team import MAX_MESSAGE_BYTES, TEAM_PORT_BASE, IncomingTeamMessages, OutgoingTeamMessage

log = logging.getLogger("tafel.network")

#: what a platform with a network adds to cognition
NETWORK_INPUTS = (GameControllerPackets, IncomingTeamMessages)
NETWORK_OUTPUTS = (GameControllerReturn, OutgoingTeamMessage)
RETURNS_PER_SECOND = 2  # the rules: at most two return packets in any second
MAX_DATAGRAMS_PER_FRAME = 64  # more in one frame is a flood: the rest waits (or is dropped by the kernel)
NETWORK_MODES = ("auto", "udp", "simulated")


#: what each ``[game]`` setting takes: (type, range, what would be right in words or None for the type's)
GAME_SETTINGS: dict[str, tuple[Any, tuple[int, int] | None, str | None]] = {
    "team_number": (int, (1, 254), "a team number from 1 to 254 (the GameController's)"),
    "player_number": (int, (1, 20), None),
    "enabled": (bool, None, None),
    "game_controller_port": (int, (0, 65535), "a UDP port from 0 to 65535"),
    "return_port": (int, (0, 65535), "a UDP port from 0 to 65535"),
    "team_port": (int, (0, 65535), "a UDP port from 0 to 65535 (0: 10000 + team number)"),
    "broadcast": (str, None, "an IPv4 address such as 255.255.255.255"),
    "network": (Literal["auto", "udp", "simulated"], None, None),
}


@dataclass(frozen=True)
class NetworkSettings:
    """The ``[game]`` table: who this robot is and where it talks."""

    team_number: int = 1
    player_number: int = 2
    enabled: bool = True
    game_controller_port: int = GAME_CONTROLLER_PORT
    return_port: int = RETURN_PORT
    team_port: int = 0
    """0: 10000 + team number"""
    broadcast: str = "255.255.255.255"
    """where team messages go: the robots' subnet's broadcast address (127.255.255.255 on one machine)"""
    network: str = "auto"
    """``udp``, ``simulated`` (inside the program), or ``auto``: the platform's choice"""

    @classmethod
    def from_config(cls, table: Mapping[str, Any] | None) -> NetworkSettings:
        table = dict(table or {})
        known = {name for name in cls.__dataclass_fields__}
        extra = sorted(set(table) - known)
        if extra:
            raise ConfigError(f"[game] has unknown keys {', '.join(extra)}; it knows {', '.join(sorted(known))}")
        values = {key: convert(table[key], kind, where=f"game.{key}", bounds=bounds, text=False, expected=expected, error=ConfigError)
                  for key, (kind, bounds, expected) in GAME_SETTINGS.items() if key in table}
        return cls(**values)

    @property
    def team_messages_port(self) -> int:
        return self.team_port or TEAM_PORT_BASE + self.team_number


def listening_socket(port: int) -> socket.socket:
    """A non-blocking UDP socket on ``port`` of every address that shares the port with other programs on
    this machine (several robots of a simulated match), and may broadcast."""
    sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
    if hasattr(socket, "SO_REUSEPORT"):
        sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEPORT, 1)
    sock.setsockopt(socket.SOL_SOCKET, socket.SO_BROADCAST, 1)
    sock.bind(("", port))
    sock.setblocking(False)
    return sock


class GameNetwork:
    """The sockets, opened at ``open`` and read and written once per cognition frame; with a simulated
    network no socket at all: the team message sent comes back in the next frame, as a broadcast would."""

    def __init__(self, settings: NetworkSettings, default_mode: str = "udp") -> None:
        self.settings = settings
        self.simulated = (default_mode if settings.network == "auto" else settings.network) == "simulated"
        self.echo: list[bytes] = []
        self.game_controller: socket.socket | None = None
        self.team: socket.socket | None = None
        self.collected: tuple[list[Datagram], list[Datagram]] | None = None  # with collect(): what receive() hands on
        self.return_times: deque[int] = deque(maxlen=RETURNS_PER_SECOND)  # ns of the last return packets sent
        self.returns_sent = self.returns_refused = self.messages_sent = self.messages_refused = self.send_errors = 0

    def open(self) -> None:
        if not self.settings.enabled or self.simulated:
            return
        for name, port in (("game_controller", self.settings.game_controller_port), ("team", self.settings.team_messages_port)):
            try:
                setattr(self, name, listening_socket(port))
            except OSError as error:
                log.warning("cannot listen on UDP port %d (%s): playing without %s", port, error,
                            "the GameController" if name == "game_controller" else "team messages")

    def close(self) -> None:
        for sock in (self.game_controller, self.team):
            if sock is not None:
                sock.close()
        self.game_controller = self.team = None

    def collect(self, time_ns: int) -> None:
        """Take what has arrived now, for the next ``receive``: a platform in lockstep with others calls it
        when a tick begins, so that a frame hears what was sent during the last tick, however the
        processes are scheduled meanwhile."""
        game_controller, team = self.collected or ([], [])
        self.collected = (game_controller + self.drain(self.game_controller, time_ns), team + self.drain(self.team, time_ns))

    def receive(self, blackboard: Blackboard, time_ns: int) -> None:
        """Everything that arrived since the last frame (or was collected), into the input representations."""
        if self.simulated:
            game_controller = []
            team = [Datagram(data=data, host="127.0.0.1", port=self.settings.team_messages_port, received_ns=time_ns)
                    for data in self.echo]
            self.echo = []
        elif self.collected is not None:
            game_controller, team = self.collected
            self.collected = ([], [])
        else:
            game_controller, team = self.drain(self.game_controller, time_ns), self.drain(self.team, time_ns)
        blackboard.set(GameControllerPackets(datagrams=game_controller, team_number=self.settings.team_number,
                                             player_number=self.settings.player_number))
        blackboard.set(IncomingTeamMessages(datagrams=team))

    @staticmethod
    def drain(sock: socket.socket | None, time_ns: int) -> list[Datagram]:
        datagrams: list[Datagram] = []
        while sock is not None and len(datagrams) < MAX_DATAGRAMS_PER_FRAME:
            try:
                data, (host, port) = sock.recvfrom(2048)
            except (BlockingIOError, InterruptedError):
                break
            except OSError as error:  # e.g. ICMP port unreachable of an earlier send: not this socket's fault
                log.debug("receive: %s", error)
                continue
            datagrams.append(Datagram(data=data, host=host, port=port, received_ns=time_ns))
        return datagrams

    def send(self, blackboard: Blackboard) -> None:
        """Send what cognition handed over: the return packet (at most two in any second) and a team message
        (at most 128 bytes); anything beyond the limits is refused and counted, never sent."""
        answer = blackboard[GameControllerReturn] if GameControllerReturn in blackboard else None
        if answer is not None and answer.data and answer.host and self.game_controller is not None:
            # the platform's time: the wall clock on a robot, simulated time in a simulation at any speed
            now_ns = blackboard[FrameInfo].time_ns if FrameInfo in blackboard else time.monotonic_ns()
            if len(self.return_times) == RETURNS_PER_SECOND and now_ns - self.return_times[0] < 1_000_000_000:
                self.returns_refused += 1  # a third within one second of the one two before
            elif self.transmit(self.game_controller, answer.data, (answer.host, self.settings.return_port)):
                self.return_times.append(now_ns)
                self.returns_sent += 1
        message = blackboard[OutgoingTeamMessage] if OutgoingTeamMessage in blackboard else None
        if message is not None and message.data and (self.team is not None or self.simulated and self.settings.enabled):
            if len(message.data) > MAX_MESSAGE_BYTES:
                self.messages_refused += 1
                log.warning("team message of %d bytes not sent: the rules allow %d", len(message.data), MAX_MESSAGE_BYTES)
            elif self.simulated:
                self.echo.append(bytes(message.data))
                self.messages_sent += 1
            elif self.transmit(self.team, message.data, (self.settings.broadcast, self.settings.team_messages_port)):
                self.messages_sent += 1

    def transmit(self, sock: socket.socket, data: bytes, address: tuple[str, int]) -> bool:
        try:
            sock.sendto(data, address)
            return True
        except OSError as error:  # no route, network down: the game goes on
            self.send_errors += 1
            if self.send_errors in (1, 10, 100) or self.send_errors % 1000 == 0:
                log.warning("cannot send to %s:%d (%s); %d sends failed so far", address[0], address[1], error, self.send_errors)
            return False

    def commands(self) -> dict[str, tuple[str, Any]]:
        """The platform's debug command about the network."""
        return {"network:status": ("this robot's team and player number, its UDP ports, and what it sent and refused",
                                   lambda args: self.status())}

    def status(self) -> str:
        s = self.settings
        if self.simulated:
            return (f"team {s.team_number} player {s.player_number}, simulated network inside this program (no GameController; "
                    f"--set game.network=\"udp\" for real sockets); team messages sent {self.messages_sent}, refused "
                    f"{self.messages_refused}")
        listening = "listening" if self.game_controller or self.team else "not listening"
        return (f"team {s.team_number} player {s.player_number}, {listening} (GameController port {s.game_controller_port}, team port "
                f"{s.team_messages_port}); returns sent {self.returns_sent}, refused {self.returns_refused}; team messages sent "
                f"{self.messages_sent}, refused {self.messages_refused}; send errors {self.send_errors}")


class NetworkedPlatform:
    """For platforms with a network: the ``GameNetwork`` made from the ``[game]`` table of the configuration.

    Mix in before ``Platform``; the platform calls ``network.open()`` in ``start``, ``network.receive``
    in cognition's ``sense``, ``network.send`` in cognition's ``act`` and ``network.close()`` in ``stop``."""

    options: dict[str, Any]
    #: what ``game.network = "auto"`` means on this platform: a simulation keeps its game to itself
    default_network: ClassVar[str] = "udp"

    def __init__(self, options: Mapping[str, Any] | None = None) -> None:
        super().__init__(options)  # type: ignore[call-arg]
        self.network = GameNetwork(NetworkSettings.from_config(self.options.get("game")), self.default_network)

    def configure(self, config: Mapping[str, Any]) -> None:
        self.options["game"] = dict(config.get("game") or {})
        self.network = GameNetwork(NetworkSettings.from_config(self.options["game"]), self.default_network)
