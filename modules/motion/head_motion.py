"""HeadMotion: move the head towards the requested angles, smoothly and within the joint limits."""

from __future__ import annotations

import math
from dataclasses import dataclass

from tafel.core import Module, bounded, provides, requires
from tafel.representations.behavior import HeadMotionRequest
from tafel.representations.infrastructure import CognitionStatus, FrameInfo
from tafel.representations.motion import HEAD_PITCH, HEAD_YAW, HeadJointTargets, JointSensorData


@requires(HeadMotionRequest, JointSensorData, FrameInfo, CognitionStatus)
@provides(HeadJointTargets)
class HeadMotion(Module):
    """Moves the head targets towards the request at no more than its speed, clamped to the joint limits.

    Starts from the measured head position, so switching it on never jerks the head. Without cognition
    (``CognitionStatus.alive`` false) it brings the head slowly to the safe position instead.
    """

    head_motion_request: HeadMotionRequest
    joint_sensor_data: JointSensorData
    frame_info: FrameInfo
    cognition_status: CognitionStatus
    head_joint_targets: HeadJointTargets

    @dataclass
    class Parameters:
        yaw_limit: float = math.radians(119.5)
        """rad, symmetric HeadYaw limit"""
        pitch_min: float = math.radians(-38.5)
        """rad, HeadPitch limit up"""
        pitch_max: float = math.radians(29.5)
        """rad, HeadPitch limit down"""
        max_speed: float = bounded(0.1, 10.0, 4.0)
        """rad/s, never faster than this whatever the request says"""
        safe_pitch: float = 0.0
        """rad, head pitch held when cognition is gone"""
        safe_speed: float = 0.5
        """rad/s, speed towards the safe position"""
        stiffness: float = 0.8
        """0..1"""
        nominal_dt: float = 0.01
        """s, step used when the frame clock does not advance"""

    parameters: Parameters

    def __init__(self) -> None:
        self.last_time_ns: int | None = None

    def execute(self) -> None:
        p, targets = self.parameters, self.head_joint_targets
        now_ns = self.frame_info.time_ns
        dt = p.nominal_dt
        if self.last_time_ns is None:  # start where the head is (a sensor may read past a limit: clamp)
            targets.yaw = min(max(float(self.joint_sensor_data.position[HEAD_YAW]), -p.yaw_limit), p.yaw_limit)
            targets.pitch = min(max(float(self.joint_sensor_data.position[HEAD_PITCH]), p.pitch_min), p.pitch_max)
        elif now_ns > self.last_time_ns:
            dt = (now_ns - self.last_time_ns) * 1e-9
        self.last_time_ns = now_ns

        if self.cognition_status.alive:
            request = self.head_motion_request
            goal_yaw, goal_pitch, speed = request.yaw, request.pitch, min(request.max_speed, p.max_speed)
        else:
            goal_yaw, goal_pitch, speed = 0.0, p.safe_pitch, p.safe_speed
        goal_yaw = min(max(goal_yaw, -p.yaw_limit), p.yaw_limit)
        goal_pitch = min(max(goal_pitch, p.pitch_min), p.pitch_max)
        step = max(speed, 0.0) * dt
        targets.yaw = _approach(targets.yaw, goal_yaw, step)
        targets.pitch = _approach(targets.pitch, goal_pitch, step)
        targets.stiffness = p.stiffness


def _approach(current: float, goal: float, step: float) -> float:
    """``current`` moved towards ``goal`` by at most ``step``."""
    if abs(goal - current) <= step:
        return goal
    return current + math.copysign(step, goal - current)
