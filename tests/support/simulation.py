"""Run the real program in-process on a simulator, with access to ground truth, for tests."""

from __future__ import annotations

import json
from typing import Any

from tafel.tools.simulation.stepped_program import SteppedProgram

#: the behaviour replaced by a robot that stands still: for tests of perception and head motion
PERCEPTION = ["FieldColorProvider", "FieldBoundaryDetector", "SPLBallDetector", "BallDetector", "BallLocator", "LineDetector",
              "GoalPostDetector", "SelfLocator", "KalmanBallModeler", "SimpleBallModeler"]
STANDING = ["cognition.modules=" + json.dumps([*PERCEPTION, "LookAtBallBehavior", "tests.support.motion_requests:ConstantMotionRequest"])]


class Simulation(SteppedProgram):
    """The default configuration on a simulated platform, stepped by hand; the platform is ground truth.

    ``scene="still"`` (the default here) keeps the robot standing at the centre spot facing the
    opponent goal with the ball at (1000, 300) unless options say otherwise; ``scene="default"`` is
    the program as ``tafel run`` starts it (striker at (-1500, 0), ball on the centre spot).
    """

    def __init__(self, platform: str, overrides: list[str] | None = None, scene: str = "still", **options: Any) -> None:
        if scene == "still":
            options = {"start": "0,0,0", "ball": "1000,300", **options}
            overrides = [*STANDING, *(overrides or [])]
        super().__init__(platform, options, overrides or [])
