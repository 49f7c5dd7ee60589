"""TeamMatesProvider: what each teammate said last, from the team messages received."""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass

from tafel.core import Module, bounded, provides, requires, uses
from tafel.modules.communication.team_message_codec import TeamMessageError, unpack_message
from tafel.representations.game import GameState
from tafel.representations.infrastructure import FrameInfo
from tafel.representations.team import IncomingTeamMessages, OutgoingTeamMessage, TeamMate, TeamMates

#: this robot's own messages remembered, to know their echoes: far more than are sent while one is on the way
OWN_MESSAGES_KEPT = 32


@requires(IncomingTeamMessages, GameState, FrameInfo)
@uses(OutgoingTeamMessage)
@provides(TeamMates)
class TeamMatesProvider(Module):
    """Unpacks every message on the team port. Messages that are not ours (broken, another format,
    another team) are ignored and counted in ``TeamMates.malformed``; this robot's own broadcasts come
    back too and are left out. A message with this robot's player number that it did not send (its
    bytes are none of the last messages it sent) is left out too, and counted in ``TeamMates.spoofed``:
    someone speaks in its name, or a teammate has the same number. A teammate not heard for
    ``forget_after`` s is dropped."""

    incoming_team_messages: IncomingTeamMessages
    game_state: GameState
    frame_info: FrameInfo
    outgoing_team_message: OutgoingTeamMessage
    team_mates: TeamMates

    @dataclass
    class Parameters:
        forget_after: float = bounded(1.0, 600.0, 10.0)
        """s after a teammate's last message"""

    parameters: Parameters

    def __init__(self) -> None:
        self.heard: dict[int, tuple[int, TeamMate]] = {}  # player -> (received ns, what it said)
        self.sent: deque[bytes] = deque(maxlen=OWN_MESSAGES_KEPT)  # this robot's last messages

    def execute(self) -> None:
        mates, game, now_ns = self.team_mates, self.game_state, self.frame_info.time_ns
        own = self.outgoing_team_message.data  # what the last frame sent (its echo may be in this frame's datagrams)
        if own and (not self.sent or self.sent[-1] != own):
            self.sent.append(own)
        for datagram in self.incoming_team_messages.datagrams:
            try:
                message = unpack_message(datagram.data)
            except TeamMessageError:
                mates.malformed += 1
                continue
            if message.team != game.team_number:
                mates.malformed += 1
                continue
            if message.player == game.player_number:
                if datagram.data not in self.sent:
                    mates.spoofed += 1
                continue
            mates.received += 1
            self.heard[message.player] = (datagram.received_ns, TeamMate(message=message))
        for player, (received_ns, mate) in list(self.heard.items()):
            mate.age = max(0.0, (now_ns - received_ns) * 1e-9)
            if mate.age > self.parameters.forget_after:
                del self.heard[player]
        mates.mates = [mate for _, (_, mate) in sorted(self.heard.items())]
