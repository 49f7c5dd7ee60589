"""MotionSelector: which motion runs, and the blend from one motion into the next."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from tafel.core import Module, bounded, provides, requires, uses
from tafel.representations.infrastructure import FrameInfo
from tafel.representations.motion_control import (
    FallPhase,
    FallState,
    KeyframeOutput,
    MotionRequest,
    MotionSelection,
    MotionType,
    WalkingEngineOutput,
)

WALKING = (MotionType.walk, MotionType.walk_to)


@requires(MotionRequest, FallState, FrameInfo)
@uses(WalkingEngineOutput, KeyframeOutput)
@provides(MotionSelection)
class MotionSelector(Module):
    """Follows the request, but never cuts a motion off where that would throw the robot over.

    - A fall overrides everything at once (the protective motion), except that a walk first has
      ``catch_time`` to catch the stagger with its steps; lying is followed by getting up, and nothing
      else runs until the robot stands again.
    - A kick or get-up plays to its end. Leaving ``sit`` is a get-up (standing up from the crouch) before
      anything else. A walk stops with its feet together before anything else
      starts. A kick runs once per request: the request must change before the next.
    - The joint commands blend from the old motion into the new one over ``blend_time``.
    """

    motion_request: MotionRequest
    fall_state: FallState
    frame_info: FrameInfo
    walking_engine_output: WalkingEngineOutput
    keyframe_output: KeyframeOutput
    motion_selection: MotionSelection

    @dataclass
    class Parameters:
        blend_time: float = bounded(0.0, 2.0, 0.3)
        """s over which one motion blends into the next"""
        startup: float = bounded(0.0, 10.0, 1.6)
        """s of standing at the start, while the stand motion brings the joints from where they are"""
        catch_time: float = bounded(0.0, 0.5, 0.12)
        """s a fall must go on while walking before the protective motion takes over: the walk's step
        adjustment catches a push in that time, a real fall still meets the protective motion before the ground"""

    parameters: Parameters

    def __init__(self) -> None:
        self.kicked = False
        #: why the motion chosen in this frame is not the one requested
        self.waiting_for = ""
        self.last_ns: int | None = None
        self.first_ns: int | None = None
        self.falling_since: int | None = None  # ns: when the FallDetector began to say falling

    def execute(self) -> None:
        selection = self.motion_selection
        previous = selection.active
        now = self.frame_info.time_ns
        self.first_ns = now if self.first_ns is None else self.first_ns
        starting = (now - self.first_ns) * 1e-9 < self.parameters.startup
        self.waiting_for = "start-up standing" if starting else ""
        active = MotionType.stand if starting else self.choose(previous)
        dt = (now - self.last_ns) * 1e-9 if self.last_ns is not None and now > self.last_ns else 0.01
        self.last_ns = now
        weights = np.array(selection.weights, dtype=float)
        if not weights.any() or active is MotionType.fall or starting:
            weights = np.zeros(len(MotionType))
            weights[active.value] = 1.0
        else:
            share = min(1.0, weights[active.value] + dt / max(self.parameters.blend_time, 1e-6))
            others = weights.sum() - weights[active.value]
            if others > 0:
                weights *= (1.0 - share) / others
            weights[active.value] = share
        selection.active, selection.weights = active, weights
        selection.requested = self.motion_request.motion
        selection.waiting_for = self.waiting_for if active is not selection.requested else ""

    def choose(self, current: MotionType) -> MotionType:
        """The motion to run now; ``self.waiting_for`` says why, where that is not the one requested."""
        fall, keyframe, walk, request = self.fall_state, self.keyframe_output, self.walking_engine_output, self.motion_request
        if current is MotionType.getup and (not keyframe.done or fall.lying or (keyframe.aborted and not fall.upright)):
            self.waiting_for = "getting up first"
            return MotionType.getup  # an aborted get-up holds still until the robot lies, then starts again
        now = self.frame_info.time_ns
        if fall.phase is not FallPhase.falling:
            self.falling_since = None
        elif self.falling_since is None:
            self.falling_since = now
        if fall.phase is FallPhase.falling and current is not MotionType.getup:
            if current in WALKING and (now - (self.falling_since or now)) * 1e-9 < self.parameters.catch_time:
                self.waiting_for = "the walk tries to catch the stagger first"
                return current
            self.waiting_for = "falling"
            return MotionType.fall
        if fall.lying:
            self.waiting_for = "getting up first"
            return MotionType.getup
        if current is MotionType.sit and request.motion is not MotionType.sit:
            self.waiting_for = "standing up from sitting first"
            return MotionType.getup  # the KeyframePlayer's stand_up: out of the limp crouch, never straight into a walk
        if current is MotionType.kick and not keyframe.done:
            self.waiting_for = "the kick plays to its end"
            return MotionType.kick
        if current in WALKING and not walk.standing and request.motion not in WALKING:
            self.waiting_for = "the walk stops with its feet together first"
            return current
        wanted = request.motion
        if wanted is MotionType.kick:
            self.waiting_for = "kicked once; the next kick needs a new request"
            if self.kicked:
                return MotionType.stand
            if current is MotionType.kick:  # the one frame in which the kick is done
                self.kicked = True
                return MotionType.stand
            return MotionType.kick
        self.kicked = False
        if wanted in (MotionType.stand, MotionType.walk, MotionType.walk_to, MotionType.sit):
            return wanted
        self.waiting_for = f"{wanted.name} is not a motion to request (stand, walk, walk_to, kick, sit)"
        return MotionType.stand
