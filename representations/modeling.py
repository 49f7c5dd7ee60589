"""Representations of the world model: what the robot believes beyond a single frame."""

from __future__ import annotations

from tafel.core import bounded, representation


@representation
class BallModel:
    """The believed ball state in the robot frame.

    ``x``/``y`` in mm, ``vx``/``vy`` in mm/s, ``position_std`` the standard deviation of the position
    (mm). ``valid`` while the ball was seen recently enough to be trusted; ``seen`` when it was seen in
    this frame; ``time_since_seen`` in s.
    """

    valid: bool = False
    seen: bool = False
    x: float = bounded(-15000.0, 15000.0)
    y: float = bounded(-15000.0, 15000.0)
    vx: float = bounded(-20000.0, 20000.0)
    vy: float = bounded(-20000.0, 20000.0)
    position_std: float = bounded(0.0, 1e6)
    time_since_seen: float = bounded(0.0, 1e6)

    def status_text(self) -> str:
        """One phrase for the status line of ``tafel run`` (``[status] show`` in configuration)."""
        if not self.valid:
            return "ball not seen"
        return f"ball {'seen' if self.seen else 'remembered'} at x={self.x:.0f} y={self.y:.0f} mm"
