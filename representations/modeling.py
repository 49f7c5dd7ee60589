"""Representations of the world model: what the robot believes beyond a single frame."""

from __future__ import annotations

from tafel.core import representation


@representation
class BallModel:
    """The believed ball state in the robot frame.

    ``x``/``y`` in mm, ``vx``/``vy`` in mm/s, ``position_std`` the standard deviation of the position
    (mm). ``valid`` while the ball was seen recently enough to be trusted; ``seen`` when it was seen in
    this frame; ``time_since_seen`` in s.
    """

    valid: bool = False
    seen: bool = False
    x: float = 0.0
    y: float = 0.0
    vx: float = 0.0
    vy: float = 0.0
    position_std: float = 0.0
    time_since_seen: float = 0.0

    def status_text(self) -> str:
        """One phrase for the status line of ``tafel run`` (``[status] show`` in configuration)."""
        if not self.valid:
            return "ball not seen"
        return f"ball {'seen' if self.seen else 'remembered'} at x={self.x:.0f} y={self.y:.0f} mm"
