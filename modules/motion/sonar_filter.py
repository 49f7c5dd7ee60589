"""SonarFilter: near echoes of the chest sonars as obstacles, in motion (where LoLA's packets arrive).

As HULKs' ``SonarFilter`` and B-Human's sonar handling do: each side's distance is smoothed over the
packets (a low-pass filter, as single packets jump), only echoes between the distances the sonars
measure reliably count (nearer ones are the own arms and the floor, farther ones are noise), and
nothing counts while the robot is not upright. An echo lies in the middle of its transducer's cone;
when both hear about the same distance, the obstacle stands straight ahead. The percept crosses to
cognition, where ``ObstacleModeler`` walks round it."""

from __future__ import annotations

import math
from dataclasses import dataclass

from tafel.core import Module, bounded, provides, uses
from tafel.representations.motion_control import FallState
from tafel.representations.sonar import SONAR_ANGLE, SonarData, SonarEcho, SonarPercept


@uses(SonarData, FallState)
@provides(SonarPercept)
class SonarFilter(Module):
    """Each side: ``smoothing`` of the new reading per packet; an echo between ``nearest`` and
    ``farthest`` mm is an obstacle ``SONAR_ANGLE`` to its side; both within ``same_distance`` mm of
    each other: one obstacle straight ahead at their mean. Platforms without sonars (the simulators)
    provide no ``SonarData``: then there are no echoes."""

    sonar_data: SonarData
    fall_state: FallState
    sonar_percept: SonarPercept

    @dataclass
    class Parameters:
        smoothing: float = bounded(0.0, 1.0, 0.2)
        """share of a new reading in the smoothed distance, per packet (12 ms)"""
        nearest: float = bounded(0.0, 2000.0, 250.0)
        """mm: nearer echoes are the own arms and the floor"""
        farthest: float = bounded(300.0, 5000.0, 1200.0)
        """mm: farther echoes are left to the cameras (the sonars' cones are wide and they hear much there)"""
        same_distance: float = bounded(0.0, 2000.0, 150.0)
        """mm between both sides' echoes within which they are one obstacle ahead"""

    parameters: Parameters

    def __init__(self) -> None:
        self.smoothed: list[float] | None = None  # mm, left and right

    def execute(self) -> None:
        p, data, out = self.parameters, self.sonar_data, self.sonar_percept
        out.echoes, out.left, out.right = [], 0.0, 0.0
        if not data.valid:
            return
        readings = [data.left * 1000.0, data.right * 1000.0]
        if self.smoothed is None:
            self.smoothed = readings
        else:
            self.smoothed = [old + p.smoothing * (new - old) for old, new in zip(self.smoothed, readings)]
        left, right = (d if p.nearest <= d <= p.farthest else 0.0 for d in self.smoothed)
        if not self.fall_state.upright:
            return
        out.left, out.right = left, right
        if left and right and abs(left - right) <= p.same_distance:
            out.echoes = [SonarEcho((left + right) / 2, 0.0)]
            return
        for distance, side in ((left, 1.0), (right, -1.0)):
            if distance:
                out.echoes.append(SonarEcho(distance * math.cos(SONAR_ANGLE), side * distance * math.sin(SONAR_ANGLE)))
