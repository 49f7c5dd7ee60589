"""The last line of defence before the motors: every platform that drives joints sends through this.

Whatever a module, a debug client or a bug computed, a motor gets a target inside its joint's limits
and a stiffness from 0 to 1. A NaN or infinite value (``np.clip`` would pass NaN straight through) is
replaced by the last good value of that joint; the events are counted and logged at most once a second,
so a module that produces NaN every frame cannot flood the log either.
"""

from __future__ import annotations

import logging
import time

import numpy as np

from tafel.representations.motion import JOINT_COUNT, JOINT_NAMES
from tafel.representations.nao import JOINTS_BY_NAME

log = logging.getLogger("tafel.actuators")

#: (lower, upper) limit of each joint in ``JOINT_NAMES`` order (rad)
JOINT_LIMITS = np.array([JOINTS_BY_NAME[name].limits for name in JOINT_NAMES], dtype=float)


class ActuatorGuard:
    """Clips joint commands to what the robot can take, and replaces non-finite values by the last good ones."""

    def __init__(self, platform: str, limits: np.ndarray = JOINT_LIMITS, report_interval_s: float = 1.0) -> None:
        self.platform = platform
        self.lower, self.upper = limits[:, 0].copy(), limits[:, 1].copy()
        self.position = np.clip(np.zeros(JOINT_COUNT), self.lower, self.upper)  # last good values
        self.stiffness = np.zeros(JOINT_COUNT)
        self.replaced = 0  # non-finite values replaced, in all
        self.clipped = 0  # values outside their range, in all
        self.report_interval_s = report_interval_s
        self._reported = (0, 0)
        self._last_report = -float("inf")
        self._has_command = False

    def hold(self, measured: np.ndarray) -> None:
        """Until the first good command, the joints' measured angles are the value to fall back on."""
        if not self._has_command:
            values = np.asarray(measured, dtype=float)
            if values.shape == (JOINT_COUNT,) and np.isfinite(values).all():
                self.position = np.clip(values, self.lower, self.upper)

    def __call__(self, position: object, stiffness: object) -> tuple[np.ndarray, np.ndarray]:
        """(targets rad, stiffness 0..1) that are safe to send, each of ``JOINT_COUNT`` values."""
        self.position = self._safe(position, self.position, self.lower, self.upper)
        self.stiffness = self._safe(stiffness, self.stiffness, 0.0, 1.0)
        self._has_command = True
        self._report()
        return self.position.copy(), self.stiffness.copy()

    def _safe(self, values: object, last: np.ndarray, lower: np.ndarray | float, upper: np.ndarray | float) -> np.ndarray:
        try:
            array = np.asarray(values, dtype=float)
        except (TypeError, ValueError):
            array = np.full(JOINT_COUNT, np.nan)
        if array.shape != (JOINT_COUNT,):
            array = np.full(JOINT_COUNT, np.nan)  # a command of the wrong size tells nothing about any joint
        bad = ~np.isfinite(array)
        if bad.any():
            self.replaced += int(bad.sum())
            array = np.where(bad, last, array)
        outside = (array < lower) | (array > upper)
        if outside.any():
            self.clipped += int(outside.sum())
            array = np.clip(array, lower, upper)
        return array

    def _report(self) -> None:
        if (self.replaced, self.clipped) == self._reported:
            return
        now = time.monotonic()
        if now - self._last_report < self.report_interval_s:
            return
        replaced, clipped = self.replaced - self._reported[0], self.clipped - self._reported[1]
        if replaced:
            log.warning("%s: replaced %d non-finite joint command value(s) by the last good ones (%d in all); "
                        "a module or client sends NaN or inf", self.platform, replaced, self.replaced)
        if clipped:
            log.info("%s: clipped %d joint command value(s) to the joint limits or 0..1 (%d in all)",
                     self.platform, clipped, self.clipped)
        self._reported = (self.replaced, self.clipped)
        self._last_report = now
