"""The Tafel team message as bytes: a plain helper of the communication modules, not a module.

A message is 30 bytes, little-endian, no padding (``MESSAGE`` below; the rules allow 128):

=======  =====  ==============================================================
bytes    type   field
=======  =====  ==============================================================
0..1     2s     ``b"TF"``: a Tafel message
2        B      version (1)
3        B      team number
4        B      player number (1..20)
5        B      flags: 1 pose valid, 2 fallen, 4 ball seen, 8 penalized
6        B      role (``Role``)
7        B      intention (``Intention``)
8..11    I      the sender's clock when sent (ms)
12..17   3h     pose: x, y (mm, field), rotation (1/10000 rad)
18..21   2h     ball on the field: x, y (mm)
22..23   H      ball age (1/100 s; 65535: never seen)
24..25   H      the sender's estimate of its time to reach the ball (1/100 s; 65535: unknown)
26..29   2h     ball velocity on the field (mm/s)
=======  =====  ==============================================================

It lives here, beside ``TeamMessageSender`` and ``TeamMatesProvider`` that use it, rather than in
``representations/team.py``, which keeps the data (``TeamMessage``, the bytes received and to send);
the platforms only move the bytes, and the tools (``tafel team``) may import modules.
"""

from __future__ import annotations

import math
import struct

from tafel.core.framework.errors import TafelError
from tafel.representations.team import Intention, Role, TeamMessage

MESSAGE = struct.Struct("<2s6BI3h2h2H2h")
HEADER, VERSION = b"TF", 1
UNKNOWN = 65535  # an age or a time that is not known


class TeamMessageError(TafelError):
    """Bytes that are not a Tafel team message; the message says what was wrong."""


def _clamp(value: float, low: int, high: int) -> int:
    return int(max(low, min(high, round(value)))) if math.isfinite(value) else 0


def _time(value: float) -> int:
    return UNKNOWN if value < 0 or not math.isfinite(value) else min(UNKNOWN - 1, int(round(value * 100)))


def pack_message(message: TeamMessage) -> bytes:
    """The bytes of ``message``; values beyond what a field holds are clamped to it."""
    flags = (message.pose_valid * 1) | (message.fallen * 2) | (message.ball_seen * 4) | (message.penalized * 8)
    return MESSAGE.pack(HEADER, VERSION, _clamp(message.team, 0, 255), _clamp(message.player, 0, 255), flags,
                        message.role.value, message.intention.value, int(message.sent_ms) % 2**32,
                        _clamp(message.x, -32768, 32767), _clamp(message.y, -32768, 32767),
                        _clamp(math.remainder(message.rotation, math.tau) * 10000, -31416, 31416),
                        _clamp(message.ball_x, -32768, 32767), _clamp(message.ball_y, -32768, 32767),
                        _time(message.ball_age), _time(message.time_to_ball),
                        _clamp(message.ball_vx, -32768, 32767), _clamp(message.ball_vy, -32768, 32767))


def unpack_message(data: bytes) -> TeamMessage:
    """A message from its bytes; ``TeamMessageError`` says what is wrong with bytes that are not one."""
    if len(data) != MESSAGE.size or data[:2] != HEADER or data[2] != VERSION:
        raise TeamMessageError(f"not a version {VERSION} Tafel team message ({HEADER!r}, {MESSAGE.size} bytes): "
                               f"{len(data)} bytes starting {bytes(data[:3])!r}")
    (_, _, team, player, flags, role, intention, sent_ms, x, y, rotation, ball_x, ball_y, ball_age, time_to_ball, ball_vx,
     ball_vy) = MESSAGE.unpack(data)
    if not 1 <= player <= 20:
        raise TeamMessageError(f"player number {player} is not 1 to 20")
    try:
        role_value, intention_value = Role(role), Intention(intention)
    except ValueError:
        raise TeamMessageError(f"role {role} or intention {intention} is not defined (roles 0..4, intentions 0..4)") from None
    if flags > 15:
        raise TeamMessageError(f"flags {flags:#x} has bits the format does not define (1, 2, 4, 8)")
    return TeamMessage(team=team, player=player, sent_ms=sent_ms, pose_valid=bool(flags & 1), fallen=bool(flags & 2),
                       ball_seen=bool(flags & 4), penalized=bool(flags & 8), x=float(x), y=float(y), rotation=rotation / 10000,
                       ball_x=float(ball_x), ball_y=float(ball_y), ball_vx=float(ball_vx), ball_vy=float(ball_vy),
                       ball_age=-1.0 if ball_age == UNKNOWN else ball_age / 100, role=role_value, intention=intention_value,
                       time_to_ball=-1.0 if time_to_ball == UNKNOWN else time_to_ball / 100)
