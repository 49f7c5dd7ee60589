"""StatusLeds: show at a glance whether cognition runs (chest green) or is gone (chest red)."""

from __future__ import annotations

import numpy as np

from tafel.core import Module, provides, requires
from tafel.representations.infrastructure import CognitionStatus
from tafel.representations.motion import LedRequest

GREEN, RED = np.array([0.0, 1.0, 0.0]), np.array([1.0, 0.0, 0.0])
BLUE_EYE = np.concatenate([np.zeros(16), np.ones(8)])  # 8 red, 8 green, 8 blue segments


@requires(CognitionStatus)
@provides(LedRequest)
class StatusLeds(Module):
    """Chest green while cognition runs, red when it stalled or died (motion then moves safely);
    eyes blue, ears on."""

    def __init__(self) -> None:
        leds = self.led_request  # the same every frame but for the chest
        leds.left_eye, leds.right_eye = BLUE_EYE.copy(), BLUE_EYE.copy()
        leds.left_ear, leds.right_ear = np.ones(10), np.ones(10)

    def execute(self) -> None:
        self.led_request.chest = GREEN if self.cognition_status.alive else RED
