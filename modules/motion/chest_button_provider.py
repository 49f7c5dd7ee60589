"""ChestButtonProvider: the chest button as presses, for cognition (the rules' manual mode)."""

from __future__ import annotations

from dataclasses import dataclass

from tafel.core import Module, bounded, provides, requires
from tafel.representations.infrastructure import FrameInfo
from tafel.representations.motion import CHEST_BUTTON, ChestButton, TouchSensorData


@requires(TouchSensorData, FrameInfo)
@provides(ChestButton)
class ChestButtonProvider(Module):
    """Counts presses at motion's rate: a press is the button held for at least ``min_press`` s and let
    go. Shorter blips (contact bounce, a brush of the hand) do not count."""

    touch_sensor_data: TouchSensorData
    frame_info: FrameInfo
    chest_button: ChestButton

    @dataclass
    class Parameters:
        min_press: float = bounded(0.0, 2.0, 0.05)
        """s the button must be held"""

    parameters: Parameters

    def __init__(self) -> None:
        self.down_since: float | None = None

    def execute(self) -> None:
        touch, out, now = self.touch_sensor_data.pressed, self.chest_button, self.frame_info.time_s
        down = len(touch) > CHEST_BUTTON and touch[CHEST_BUTTON] > 0.5
        if down and self.down_since is None:
            self.down_since = now
        elif not down and self.down_since is not None:
            if now - self.down_since >= self.parameters.min_press:
                out.presses += 1
            self.down_since = None
        out.pressed = down
