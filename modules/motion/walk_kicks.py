"""Kicks out of the walk: the shape of a kicking step, read from ``config/motions/walk_kicks.toml``.

A kicking step is a walk step of the kicking foot whose swing draws the foot back, then drives it
through the ball along the kick direction (the foot turned towards it) and puts it down where a
normal step would land; the support foot and the torso's sway go on as in any step. The walking
engine (``WalkingEngine``) plays it when the ``MotionRequest`` asks for a ``walk_kick``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields
from pathlib import Path

import numpy as np

from tafel.modules.motion.keyframes import SHIPPED_MOTIONS, MotionFileError, read_motion_file
from tafel.representations.motion_control import Foot, WalkKick

WALK_KICKS_FILE = SHIPPED_MOTIONS / "walk_kicks.toml"


@dataclass(frozen=True)
class KickStep:
    """One kick's step (lengths mm along the kick direction from the foot's place beside the torso)."""

    duration: float  # s of the kicking step
    retract: float  # mm the foot draws back, reached at ``extend_from``
    reach: float  # mm ahead the foot's centre is driven to, reached at ``extend_to``
    extend_from: float  # share of the step at which the drive through the ball begins
    extend_to: float  # share at which the foot reaches ``reach`` (the shorter, the faster: motors limit it)
    put_down_from: float  # share from which the foot goes back to its landing place
    lift: float  # mm the foot is lifted while drawn back
    reach_lift: float  # mm the foot is lifted where it reaches (it swings up through the ball)
    sway: float  # mm the torso leans over the support foot while the other kicks
    landing: float  # mm forward the kicking step carries the robot, as a walk step would
    max_direction: float  # rad: kick directions beyond this either side are clipped to it
    yaw_share: float  # share of the kick direction the foot turns towards it (the HipYawPitch is shared)
    toe_pitch: float  # rad the toe points down while it drives through the ball


def load_walk_kicks(path: Path = WALK_KICKS_FILE) -> dict[WalkKick, KickStep]:
    """The kicks in ``path`` by strength (tables ``[short]`` and ``[long]``), each key checked."""
    data = read_motion_file(path)
    names = [f.name for f in fields(KickStep)]
    kicks = {}
    for kick in (WalkKick.short, WalkKick.long):
        table = data.get(kick.name)
        if not isinstance(table, dict) or sorted(table) != sorted(names):
            raise MotionFileError(f"{path}: [{kick.name}] needs exactly {', '.join(names)}")
        try:
            step = KickStep(**{name: float(table[name]) for name in names})
        except (TypeError, ValueError):
            raise MotionFileError(f"{path}: [{kick.name}] needs a number for each of {', '.join(names)}") from None
        if not 0.0 <= step.extend_from < step.extend_to <= step.put_down_from < 1.0 or step.duration <= 0.0:
            raise MotionFileError(f"{path}: [{kick.name}] needs 0 <= extend_from < extend_to <= put_down_from < 1 and duration > 0")
        kicks[kick] = step
    return kicks


def _smooth(share: float) -> float:
    share = min(1.0, max(0.0, share))
    return 0.5 - 0.5 * math.cos(math.pi * share)


def kick_swing(step: KickStep, phase: float, start: np.ndarray, landing: np.ndarray, direction: float,
               foot: Foot, offset: tuple[float, float] = (0.0, 0.0)) -> tuple[np.ndarray, float, float]:
    """The kicking foot at ``phase`` (0..1) of its step: (x, y mm, yaw rad) relative to its place beside
    the torso, its lift (mm) and toe pitch (rad); from ``start`` back, through the ball along
    ``direction`` (rad, robot frame; the line shifted by ``offset`` mm where the ball lies off the planned
    spot), and down at ``landing``. The foot never crosses inwards."""
    along = np.array([math.cos(direction), math.sin(direction)])
    yaw = step.yaw_share * direction
    back = np.array([*(-step.retract * along + offset), yaw])
    ahead = np.array([*(step.reach * along + offset), yaw])
    if phase < step.extend_from:
        place = start + (back - start) * _smooth(phase / step.extend_from)
        lift = step.lift * _smooth(2.0 * phase / step.extend_from)
    elif phase < step.put_down_from:
        share = min(1.0, (phase - step.extend_from) / (step.extend_to - step.extend_from))
        place = back + (ahead - back) * share  # linear: the motors drive it as fast as they can
        lift = step.lift + (step.reach_lift - step.lift) * share
    else:
        down = _smooth((phase - step.put_down_from) / (1.0 - step.put_down_from))
        place = ahead + (landing - ahead) * down
        lift = step.reach_lift * (1.0 - down)
    side = 1.0 if foot is Foot.left else -1.0
    place[1] = side * max(side * place[1], -5.0)  # never towards the support foot
    driving = step.extend_from <= phase < step.put_down_from
    return place, lift, step.toe_pitch if driving else 0.0
