"""Run the real program in-process on a simulator, with access to ground truth, for tests."""

from __future__ import annotations

import json
from collections.abc import Callable
from typing import Any

from tafel.core.config import load_config
from tafel.core.platform import load_platform
from tafel.core.program import plan_program
from tafel.core.runtime import LockstepRuntime
from tafel.tools.cli import DEFAULT_CONFIG, discover_modules

#: the behaviour replaced by a robot that stands still: for tests of perception and head motion
PERCEPTION = ["FieldColorProvider", "FieldBoundaryDetector", "SPLBallDetector", "BallDetector", "BallLocator", "LineDetector",
              "GoalPostDetector", "SelfLocator", "KalmanBallModeler", "SimpleBallModeler"]
STANDING = ["cognition.modules=" + json.dumps([*PERCEPTION, "LookAtBallBehavior", "tests.support.motion_requests:ConstantMotionRequest"])]


class Simulation:
    """The default configuration on a simulated platform, stepped by hand; the platform is ground truth.

    ``scene="still"`` (the default here) keeps the robot standing at the centre spot facing the
    opponent goal with the ball at (1000, 300) unless options say otherwise; ``scene="default"`` is
    the program as ``tafel run`` starts it (striker at (-1500, 0), ball on the centre spot).
    """

    def __init__(self, platform: str, overrides: list[str] | None = None, scene: str = "still", **options: Any) -> None:
        discover_modules()
        if scene == "still":
            options = {"start": "0,0,0", "ball": "1000,300", **options}
            overrides = [*STANDING, *(overrides or [])]
        self.platform = load_platform(platform)(options)
        config = load_config(DEFAULT_CONFIG, self.platform.config_layers(), overrides=overrides or [])
        self.platform.configure(config)
        self.plans = plan_program(config, self.platform)
        self.runtime = LockstepRuntime(self.plans, self.platform)
        self.runtime.open()

    def blackboard(self, context: str) -> Any:
        return self.runtime.runners[context].manager.blackboard

    @property
    def time(self) -> float:
        """Simulated seconds of the last tick."""
        return self.runtime.time_ns * 1e-9

    def run(self, seconds: float, every_tick: Callable[[Simulation], None] | None = None) -> None:
        for _ in range(int(round(seconds * self.plans["motion"].rate_hz))):
            self.runtime.tick()
            if every_tick is not None:
                every_tick(self)

    def close(self) -> None:
        self.runtime.close()
