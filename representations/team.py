"""Team communication: what teammates say to each other.

Teammates broadcast on UDP port 10000 + team number; a message is at most 128 bytes (the rules). The
bytes of a Tafel message (its layout, ``pack_message``, ``unpack_message``) are
``modules/communication/team_message_codec.py``, beside the modules that use it; here is the data.
"""

from __future__ import annotations

import enum
import math
from dataclasses import dataclass, field

from tafel.core import representation
from tafel.core.framework.representation import counter
from tafel.representations.game import Datagram

MAX_MESSAGE_BYTES = 128  # the rules' limit
TEAM_PORT_BASE = 10000  # + team number


class Role(enum.Enum):
    none = 0
    goalkeeper = 1
    striker = 2
    supporter = 3
    defender = 4


class Intention(enum.Enum):
    """What the sender is about to do, so that the others need not guess."""

    none = 0
    play_ball = 1
    keep_goal = 2
    take_position = 3
    search_ball = 4


@dataclass
class TeamMessage:
    """One message, unpacked. Positions in mm on the field, rotation in rad, times in s."""

    team: int = 0
    player: int = 0
    sent_ms: int = 0
    pose_valid: bool = False
    fallen: bool = False
    penalized: bool = False
    x: float = 0.0
    y: float = 0.0
    rotation: float = 0.0
    ball_seen: bool = False
    ball_x: float = 0.0
    ball_y: float = 0.0
    ball_vx: float = 0.0
    ball_vy: float = 0.0
    ball_age: float = -1.0
    """s since the sender saw the ball; -1: never"""
    role: Role = Role.none
    intention: Intention = Intention.none
    time_to_ball: float = -1.0
    """s the sender thinks it needs to reach the ball and kick; -1: unknown"""


@representation
class IncomingTeamMessages:
    """What arrived on the team port since the last cognition frame (platform), own messages included."""

    datagrams: list[Datagram]


@representation
class OutgoingTeamMessage:
    """A message to broadcast this frame (``data`` empty: none); ``sent`` counts this robot's messages."""

    data: bytes = b""
    sent: int = counter()


@dataclass
class TeamMate:
    """What one teammate said last, and how old that is (s, by this robot's clock)."""

    message: TeamMessage = field(default_factory=TeamMessage)
    age: float = 0.0


@dataclass
class TeamBall:
    """The ball a teammate reported: on the field (mm, moved on by its velocity), how old (s), and which
    message it came in (player, sender's clock in ms)."""

    x: float
    y: float
    age: float
    message: tuple[int, int]


@representation
class TeamMates:
    """Every teammate heard, by player number order; ``malformed`` counts messages ignored as not ours
    or broken, ``received`` the good ones, and ``spoofed`` those that claim this robot's own player
    number without being a message it sent (spoofed, or a teammate configured with the same number)."""

    mates: list[TeamMate]
    received: int = counter()
    malformed: int = counter()
    spoofed: int = counter()

    def freshest_ball(self, max_age: float) -> TeamBall | None:
        """The freshest ball reported by a teammate with a valid pose, upright and playing, within ``max_age``
        s; None if there is none."""
        heard = [(mate.age + mate.message.ball_age, mate.message) for mate in self.mates
                 if mate.message.ball_seen and mate.message.pose_valid and not (mate.message.fallen or mate.message.penalized)
                 and mate.message.ball_age >= 0.0]
        heard = [(age, m) for age, m in heard if math.isfinite(age) and age <= max_age]
        if not heard:
            return None
        age, m = min(heard, key=lambda h: h[0])
        return TeamBall(m.ball_x + m.ball_vx * age, m.ball_y + m.ball_vy * age, age, (m.player, m.sent_ms))

    def fresh(self, max_age: float) -> list[TeamMate]:
        """The teammates heard within ``max_age`` s."""
        return [mate for mate in self.mates if mate.age <= max_age]

    def status_text(self) -> str:
        return (f"{len(self.mates)} teammates heard" + (f", {self.malformed} bad messages" if self.malformed else "")
                + (f", {self.spoofed} claiming this robot's number" if self.spoofed else ""))


@representation
class PlayerRole:
    """This robot's role and what it intends, decided from the game state and the team's messages."""

    role: Role = Role.none
    intention: Intention = Intention.none
    time_to_ball: float = -1.0
    """s this robot thinks it needs to reach the ball and kick (what it tells the team); -1: unknown"""

    def status_text(self) -> str:
        return self.role.name
