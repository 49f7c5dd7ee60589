"""MotionCombinator: the one place that writes ``JointCommand``, blending what the motions computed."""

from __future__ import annotations

import numpy as np

from tafel.core import Module, provides, requires
from tafel.representations.motion import HEAD_PITCH, HEAD_YAW, BodyJointTargets, HeadJointTargets, JointCommand
from tafel.representations.motion_control import (
    KeyframeOutput,
    MotionInfo,
    MotionRequest,
    MotionSelection,
    MotionType,
    WalkingEngineOutput,
)

HEAD = [HEAD_YAW, HEAD_PITCH]
KEYFRAMED = (MotionType.kick, MotionType.getup, MotionType.sit, MotionType.fall)
#: motions that move the head themselves; the others leave it to the head motion
HEAD_FROM_KEYFRAME = (MotionType.getup, MotionType.sit, MotionType.fall)


@requires(MotionSelection, MotionRequest, BodyJointTargets, WalkingEngineOutput, KeyframeOutput, HeadJointTargets)
@provides(JointCommand, MotionInfo)
class MotionCombinator(Module):
    """Each motion's targets weighted by its share in ``MotionSelection`` (the shares blend a motion into
    the next without a jump), the head from the head motion unless a get-up, fall or sit moves it, and
    ``MotionInfo`` for cognition."""

    motion_selection: MotionSelection
    motion_request: MotionRequest
    body_joint_targets: BodyJointTargets
    walking_engine_output: WalkingEngineOutput
    keyframe_output: KeyframeOutput
    head_joint_targets: HeadJointTargets
    joint_command: JointCommand
    motion_info: MotionInfo

    def execute(self) -> None:
        selection, command = self.motion_selection, self.joint_command
        weights = np.asarray(selection.weights, dtype=float)
        if not weights.any():
            weights = np.zeros(len(MotionType))
            weights[selection.active.value] = 1.0
        sources: dict[MotionType, BodyJointTargets | WalkingEngineOutput | KeyframeOutput] = {
            MotionType.stand: self.body_joint_targets, MotionType.walk: self.walking_engine_output,
            MotionType.walk_to: self.walking_engine_output}
        position = np.zeros(len(command.position))
        stiffness = np.zeros(len(command.stiffness))
        head_from_keyframe = 0.0
        for motion in MotionType:
            share = float(weights[motion.value])
            if share <= 0.0:
                continue
            source = self.keyframe_output if motion in KEYFRAMED else sources[motion]
            position += share * np.asarray(source.position, dtype=float)
            stiffness += share * np.asarray(source.stiffness, dtype=float)
            if motion in HEAD_FROM_KEYFRAME:
                head_from_keyframe += share
        head = self.head_joint_targets
        head_position = np.array([head.yaw, head.pitch])
        keyframe_head = np.asarray(self.keyframe_output.position, dtype=float)[HEAD]
        position[HEAD] = (1.0 - head_from_keyframe) * head_position + head_from_keyframe * keyframe_head
        stiffness[HEAD] = (1.0 - head_from_keyframe) * head.stiffness + head_from_keyframe * np.asarray(self.keyframe_output.stiffness)[HEAD]
        command.position, command.stiffness = position, np.clip(stiffness, 0.0, 1.0)
        self.report(selection.active)

    def report(self, active: MotionType) -> None:
        info, walk, keyframe = self.motion_info, self.walking_engine_output, self.keyframe_output
        info.motion = active
        info.executing_request = active is self.motion_request.motion or (
            active is MotionType.stand and self.motion_request.motion is MotionType.kick)
        info.requested = self.motion_request.motion
        info.waiting_for = "" if info.executing_request else self.motion_selection.waiting_for
        info.support_foot, info.step_phase = walk.support_foot, walk.step_phase if active in (MotionType.walk, MotionType.walk_to) else 0.0
        info.busy = active in (MotionType.kick, MotionType.getup) and not keyframe.done
