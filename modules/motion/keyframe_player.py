"""KeyframePlayer: plays the motions stored as data (kicks, get-up, sitting down, falling safely)."""

from __future__ import annotations

import logging
from dataclasses import dataclass

import numpy as np

from tafel.core import Module, provides, requires
from tafel.core.framework.parameters import folder_within
from tafel.modules.motion.keyframes import SHIPPED_MOTIONS, KeyframeMotion, MotionFileError, load_motion
from tafel.representations.infrastructure import FrameInfo
from tafel.representations.motion import InertialSensorData, JointSensorData
from tafel.representations.motion_control import (
    FallDirection,
    FallPhase,
    FallState,
    Foot,
    KeyframeOutput,
    MotionRequest,
    MotionSelection,
    MotionType,
)

log = logging.getLogger("tafel.motion")


@requires(MotionSelection, MotionRequest, FallState, JointSensorData, InertialSensorData, FrameInfo)
@provides(KeyframeOutput)
class KeyframePlayer(Module):
    """Plays the motion file that fits what motion selected, from where the joints are when it starts.

    Which file: ``kick_left``/``kick_right`` by the request's foot, ``getup_front``/``getup_back`` by how
    the robot lies (``stand_up`` when a get-up starts with the robot on its feet: out of ``sit``), ``sit``, and ``fall_front``/``fall_back`` by the fall's direction. Files are read
    once and kept; a file that cannot be played is logged and the robot keeps still instead. A keyframe
    with ``abort_if_tilted`` that begins with the torso tilted more than that stops the motion where
    it is (``aborted``); a get-up then starts again once the robot lies still.
    """

    motion_selection: MotionSelection
    motion_request: MotionRequest
    fall_state: FallState
    joint_sensor_data: JointSensorData
    inertial_sensor_data: InertialSensorData
    frame_info: FrameInfo
    keyframe_output: KeyframeOutput

    @dataclass
    class Parameters:
        motions_dir: str = folder_within(SHIPPED_MOTIONS)
        """folder of the motion files (empty: the shipped config/motions). Configuration may name any
        folder; a debug client only the shipped one, the configured one, or a folder inside them"""

    parameters: Parameters

    def __init__(self) -> None:
        self.motions: dict[str, KeyframeMotion | None] = {}
        self.playing: KeyframeMotion | None = None
        self.start_pose = np.zeros(0)
        self.start_ns = 0
        self.selected = MotionType.stand
        self.keyframe = -1
        self.aborted_at: float | None = None

    def execute(self) -> None:
        out, active = self.keyframe_output, self.motion_selection.active
        now = self.frame_info.time_ns
        current = self.playing.name if self.playing else ""
        retry = active is MotionType.getup and out.done and self.fall_state.lying  # still lying after getting up: again
        name = self.motion_for(active) if active in (MotionType.kick, MotionType.getup, MotionType.sit, MotionType.fall) else ""
        if active is MotionType.getup and self.selected is MotionType.getup and self.playing is not None and not retry:
            name = current  # a get-up goes on as it began (the fall state says getting_up meanwhile)
        if active is not self.selected or name != current or retry:
            self.selected = active
            self.playing = self.load(name) if name else None
            self.start_pose = np.array(self.joint_sensor_data.position, dtype=float)
            self.start_ns = now
            self.keyframe, self.aborted_at = -1, None
        out.motion = self.playing.name if self.playing else ""
        out.aborted = self.aborted_at is not None
        if self.playing is None:
            out.done, out.time = True, 0.0
            out.position = np.array(self.joint_sensor_data.position, dtype=float)
            return
        out.time = self.aborted_at if self.aborted_at is not None else (now - self.start_ns) * 1e-9
        if self.aborted_at is None:
            self.check_tilt(self.playing, out.time)
        out.position, out.stiffness = self.playing.at(out.time, self.start_pose)
        out.done = out.aborted or out.time >= self.playing.duration

    def check_tilt(self, motion: KeyframeMotion, time_s: float) -> None:
        """At the start of each keyframe with ``abort_if_tilted``: stop here if the torso tilts more."""
        index = motion.keyframe_at(time_s)
        if index == self.keyframe:
            return
        self.keyframe = index
        limit = motion.keyframes[index].abort_if_tilted
        tilt = float(np.max(np.abs(self.inertial_sensor_data.angles[:2])))
        if limit is not None and tilt > limit:
            self.aborted_at = time_s
            log.info("KeyframePlayer: %s stopped at keyframe %d: the torso tilts %.2f rad, more than %.2f",
                     motion.name, index + 1, tilt, limit)

    def motion_for(self, active: MotionType) -> str:
        if active is MotionType.kick:
            return "kick_left" if self.motion_request.kick_foot is Foot.left else "kick_right"
        if active is MotionType.getup:
            if self.fall_state.upright:
                return "stand_up"  # on its feet, crouched: standing up from sitting
            lying_back = self.fall_state.phase is FallPhase.lying_back or self.fall_state.direction is FallDirection.back
            return "getup_back" if lying_back else "getup_front"
        if active is MotionType.fall:
            return "fall_back" if self.fall_state.direction is FallDirection.back else "fall_front"
        return "sit"

    def load(self, name: str) -> KeyframeMotion | None:
        if name not in self.motions:
            try:
                self.motions[name] = load_motion(name, self.parameters.motions_dir)
            except MotionFileError as exc:
                log.error("KeyframePlayer: %s", exc)
                self.motions[name] = None
        return self.motions[name]
