"""StatusLeds: show at a glance whether cognition runs (chest green) or is gone (chest red)."""

from __future__ import annotations

import numpy as np

from core import Module, provides, requires
from representations.infrastructure import CognitionStatus
from representations.motion import LedRequest

GREEN, RED, BLUE = np.array([0.0, 1.0, 0.0]), np.array([1.0, 0.0, 0.0]), np.array([0.0, 0.0, 1.0])


@requires(CognitionStatus)
@provides(LedRequest)
class StatusLeds(Module):
    """Chest green while cognition runs, red when it stalled or died (motion then moves safely);
    eyes blue, ears on."""

    def execute(self) -> None:
        leds = self.led_request
        leds.chest = GREEN.copy() if self.cognition_status.alive else RED.copy()
        eye = np.zeros(24)
        eye[16:] = 1.0  # the blue segments
        leds.left_eye, leds.right_eye = eye, eye.copy()
        leds.left_ear, leds.right_ear = np.ones(10), np.ones(10)
        leds.left_foot, leds.right_foot = np.zeros(3), np.zeros(3)
        leds.skull = np.zeros(12)
