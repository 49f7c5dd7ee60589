"""MotionCombinator: one joint command from the body and the head motions."""

from __future__ import annotations

from tafel.core import Module, provides, requires
from tafel.representations.motion import HEAD_PITCH, HEAD_YAW, BodyJointTargets, HeadJointTargets, JointCommand


@requires(BodyJointTargets, HeadJointTargets)
@provides(JointCommand)
class MotionCombinator(Module):
    """The body motion's targets for every joint, with the head joints from the head motion."""

    def execute(self) -> None:
        body, head, command = self.body_joint_targets, self.head_joint_targets, self.joint_command
        position = body.position.copy()
        stiffness = body.stiffness.copy()
        position[HEAD_YAW], position[HEAD_PITCH] = head.yaw, head.pitch
        stiffness[HEAD_YAW] = stiffness[HEAD_PITCH] = head.stiffness
        command.position = position
        command.stiffness = stiffness
