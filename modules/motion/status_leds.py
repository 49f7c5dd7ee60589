"""StatusLeds: the chest shows the referee the game state in the rules' colours; the eyes and ears show
whether cognition runs."""

from __future__ import annotations

import numpy as np

from tafel.core import Module, provides, requires, uses
from tafel.representations.game import GameState, State
from tafel.representations.infrastructure import CognitionStatus
from tafel.representations.motion import LedRequest

OFF = np.zeros(3)
GREEN, RED, BLUE = np.array([0.0, 1.0, 0.0]), np.array([1.0, 0.0, 0.0]), np.array([0.0, 0.0, 1.0])
CYAN, YELLOW = np.array([0.0, 1.0, 1.0]), np.array([1.0, 1.0, 0.0])
#: the chest in each game state, as the SPL rules ask; a penalized robot's chest is red whatever the state
CHEST = {State.initial: OFF, State.standby: CYAN, State.ready: BLUE, State.set: YELLOW, State.playing: GREEN, State.finished: OFF}
PENALIZED = RED
BLUE_EYE = np.concatenate([np.zeros(16), np.ones(8)])  # 8 red, 8 green, 8 blue segments
RED_EYE = np.concatenate([np.ones(8), np.zeros(16)])
EARS_ON, EARS_OFF = np.ones(10), np.zeros(10)


@requires(CognitionStatus)
@uses(GameState)
@provides(LedRequest)
class StatusLeds(Module):
    """The chest is the referee's: off in INITIAL and FINISHED, cyan in STANDBY, blue in READY, yellow in
    SET, green in PLAYING, red while penalized (``CHEST``), from the last ``GameState`` cognition handed
    over. Cognition's health is the team's: eyes blue and ears lit while it runs, eyes red and ears
    dark in the frame it stalls or dies (motion then moves safely)."""

    cognition_status: CognitionStatus
    game_state: GameState
    led_request: LedRequest

    def execute(self) -> None:
        leds, game, alive = self.led_request, self.game_state, self.cognition_status.alive
        leds.chest = (PENALIZED if game.penalized else CHEST[game.state]).copy()
        eye = BLUE_EYE if alive else RED_EYE
        leds.left_eye, leds.right_eye = eye.copy(), eye.copy()
        leds.left_ear, leds.right_ear = (EARS_ON if alive else EARS_OFF).copy(), (EARS_ON if alive else EARS_OFF).copy()
