"""SimpleBallModeler: the ball model is the last percept, forgotten after a while."""

from __future__ import annotations

from dataclasses import dataclass

from tafel.core import Module, provides, requires
from tafel.representations.infrastructure import FrameInfo
from tafel.representations.modeling import BallModel
from tafel.representations.perception import BallPercept


@requires(BallPercept, FrameInfo)
@provides(BallModel)
class SimpleBallModeler(Module):
    """Copies the seen ball's position; keeps it, unchanged, until ``forget_after`` has passed.

    No velocity and no filtering: the baseline the Kalman modeler must beat, and a fallback that
    cannot diverge.
    """

    ball_percept: BallPercept
    frame_info: FrameInfo
    ball_model: BallModel

    @dataclass
    class Parameters:
        forget_after: float = 2.0
        """s without a percept after which the model is no longer valid"""

    parameters: Parameters

    def __init__(self) -> None:
        self.last_seen_ns: int | None = None

    def execute(self) -> None:
        percept, model, now_ns = self.ball_percept, self.ball_model, self.frame_info.time_ns
        model.seen = percept.seen
        if percept.seen:
            model.x, model.y = percept.x, percept.y
            self.last_seen_ns = now_ns
        model.vx = model.vy = 0.0
        if self.last_seen_ns is None:
            model.valid, model.time_since_seen = False, 0.0
            return
        model.time_since_seen = max(0.0, (now_ns - self.last_seen_ns) * 1e-9)
        model.valid = model.time_since_seen <= self.parameters.forget_after
