"""The NAO's two chest sonars: what LoLA measures (``SonarData``) and the echoes worth walking around
(``SonarPercept``). The left transducer looks ``SONAR_ANGLE`` to the left of the torso's x axis, the
right one as far to the right; each hears echoes within a cone of about +-30 degrees."""

from __future__ import annotations

from dataclasses import dataclass

from tafel.core import bounded, representation

SONAR_ANGLE = 0.35  # rad: each transducer's axis from the torso's x axis (about 20 degrees)


@representation
class SonarData:
    """LoLA's ``Sonar`` array as it comes: the distance of the nearest echo each transducer heard (m;
    LoLA reports its largest value, about 5 m, when nothing answered). ``valid``: a packet held it."""

    left: float = bounded(0.0, 100.0, 5.0)
    right: float = bounded(0.0, 100.0, 5.0)
    valid: bool = False


@dataclass
class SonarEcho:
    """An obstacle one or both sonars heard: in the middle of the cone at the echo's distance (mm, robot frame)."""

    x: float = 0.0
    y: float = 0.0


@representation
class SonarPercept:
    """The sonars' echoes within the distances they measure reliably, smoothed over the packets (mm, robot
    frame); none while the robot is not upright (the floor answers then)."""

    echoes: list[SonarEcho]
    left: float = bounded(0.0, 100000.0, 0.0)
    """mm of the left sonar's smoothed echo (0: none within the reliable range)"""
    right: float = bounded(0.0, 100000.0, 0.0)
    """mm of the right sonar's smoothed echo (0: none)"""
