"""GameStateProvider: the game state from the GameController's packets, or from the chest button without one."""

from __future__ import annotations

from dataclasses import dataclass

from tafel.core import Module, bounded, provides, requires, uses
from tafel.core.framework.parameters import choice_of
from tafel.modules.communication.game_controller_codec import MAX_PLAYERS, PacketError, decode_game_state
from tafel.representations.game import GameControllerPackets, GameState, Penalty, RobotInfo, State, TeamInfo
from tafel.representations.infrastructure import FrameInfo
from tafel.representations.motion import ChestButton

STATES = tuple(state.name for state in State)
#: presses one frame acts on at most: the first may start PLAYING, then each toggles the penalty, so
#: three (or two, for the same parity) do what any larger number would, however many a client claims
MAX_PRESSES_PER_FRAME = 3


@requires(GameControllerPackets, FrameInfo)
@uses(ChestButton)
@provides(GameState)
class GameStateProvider(Module):
    """Takes the newest packet that names this robot's team; packets that are not the protocol, or for
    other teams, are ignored and counted in ``GameState.ignored_packets``.

    Without a packet for ``timeout`` s, ``heard`` turns false and the last state stays. Then the chest
    button steps through the states as the rules' manual mode says: a press in INITIAL (or any state
    before PLAYING) starts PLAYING penalized, the next press unpenalizes, the next penalizes again, and
    so on. Before any GameController is heard the state is ``start_state``: INITIAL as the rules want
    on a real robot; the simulators' configuration says PLAYING, so that ``tafel run`` plays at once.
    """

    game_controller_packets: GameControllerPackets
    frame_info: FrameInfo
    chest_button: ChestButton
    game_state: GameState

    @dataclass
    class Parameters:
        start_state: str = choice_of(STATES, "initial")
        """the state before any GameController is heard: initial, ready, set, playing, finished or standby"""
        timeout: float = bounded(0.1, 60.0, 2.0)
        """s without a packet for this team after which the GameController counts as not heard"""

    parameters: Parameters

    def __init__(self) -> None:
        self.last_heard_ns: int | None = None
        self.presses_seen = 0
        self.started = False

    def execute(self) -> None:
        game, packets, now_ns = self.game_state, self.game_controller_packets, self.frame_info.time_ns
        if not self.started:
            self.start(game)
        game.team_number, game.player_number = packets.team_number, packets.player_number
        for datagram in packets.datagrams:
            try:
                heard = decode_game_state(datagram.data)
            except PacketError:
                game.ignored_packets += 1
                continue
            if not any(team.team_number == packets.team_number for team in heard.teams):
                game.ignored_packets += 1
                continue
            for name in heard.__dataclass_fields__:
                if name not in ("heard", "seconds_since_packet", "manual", "ignored_packets", "source", "team_number", "player_number"):
                    setattr(game, name, getattr(heard, name))
            game.manual, game.source, self.last_heard_ns = False, datagram.host, datagram.received_ns
        game.seconds_since_packet = (now_ns - self.last_heard_ns) * 1e-9 if self.last_heard_ns is not None else float("inf")
        game.heard = game.seconds_since_packet < self.parameters.timeout
        presses = self.chest_button.presses
        if not game.heard:
            for _ in range(self.presses_to_act_on(presses - self.presses_seen)):
                self.press(game)
        self.presses_seen = presses

    @staticmethod
    def presses_to_act_on(new: int) -> int:
        """How many of ``new`` presses to carry out: all of a few, and for more the fewest with the same
        effect (the penalty toggles, so parity is what counts): never a loop a client's number bounds."""
        return max(0, new) if new <= MAX_PRESSES_PER_FRAME else 2 + new % 2  # 2 or 3: the first, and the parity of the rest

    def start(self, game: GameState) -> None:
        state = self.parameters.start_state.lower()  # checked where it was set (choice_of); this guards direct writes
        if state not in STATES:
            raise ValueError(f"GameStateProvider.start_state is {self.parameters.start_state!r}; it takes {', '.join(STATES)}")
        game.state, self.started = State[state], True
        game.teams = [TeamInfo(team_number=self.game_controller_packets.team_number, players=[RobotInfo() for _ in range(MAX_PLAYERS)])]

    @staticmethod
    def press(game: GameState) -> None:
        """One press of the chest button in the rules' manual mode."""
        game.manual = True
        player = game.own_player()
        if player is None:
            return
        if game.state in (State.initial, State.standby, State.ready, State.set):
            game.state, player.penalty = State.playing, Penalty.manual
        elif player.penalty is Penalty.none:
            player.penalty = Penalty.manual
        else:
            player.penalty, player.secs_till_unpenalised = Penalty.none, 0
