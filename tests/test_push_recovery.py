"""Push recovery of the walk (issue 36): a torso tipped by a push must not take the swing foot with it."""

from __future__ import annotations

import math

import numpy as np
import pytest

from tafel.core.testing import ModuleHarness
from tafel.modules.motion.inverse_kinematics import rot_x, rot_y
from tafel.modules.motion.kinematics import link_poses
from tafel.modules.motion.walking_engine import WalkingEngine
from tafel.representations.motion import JOINT_NAMES, InertialSensorData
from tafel.representations.motion_control import Foot, MotionRequest, MotionSelection, MotionType, WalkingEngineOutput
from tafel.representations.nao import FOOT_HEIGHT


def swing_sole_on_the_ground(roll: float, pitch: float, level_swing: float) -> np.ndarray:
    """The swing sole's rotation in an upright (gravity-aligned) frame, after the walking torso has been
    tipped by ``roll``, ``pitch`` (rad) for a few frames."""
    harness = ModuleHarness(WalkingEngine, MotionRequest(motion=MotionType.walk, walk_x=100.0), MotionSelection(active=MotionType.walk),
                            parameters={"level_swing": level_swing}, context="motion")
    harness.execute(frames=30)  # walking undisturbed: the tilt it has now is its own
    harness.set(InertialSensorData(angles=np.array([roll, pitch])))  # tipped, no longer turning
    harness.execute(frames=3)
    engine, output = harness.module, harness[WalkingEngineOutput]
    swing = "R" if engine.support is Foot.left else "L"
    angles = dict(zip(JOINT_NAMES, (float(a) for a in output.position)))
    poses = link_poses({**angles, "RHipYawPitch": angles["LHipYawPitch"]})
    below = np.eye(4)
    below[2, 3] = -FOOT_HEIGHT
    sole = poses[f"{swing}Foot"] @ below
    return rot_y(pitch) @ rot_x(roll) @ sole[:3, :3]  # the torso's own tilt added: as the ground sees it


def tilt_of(rotation: np.ndarray) -> tuple[float, float]:
    """(roll, pitch) rad of a rotation's z axis away from upright."""
    return math.atan2(rotation[2, 1], rotation[2, 2]), math.atan2(-rotation[2, 0], rotation[2, 2])


@pytest.mark.parametrize("roll, pitch, turned", [(0.0, -0.25, True), (0.1, -0.3, True), (0.0, 0.25, False), (0.2, 0.0, False),
                                                  (-0.2, 0.0, False)])
def test_the_swing_foot_of_a_torso_tipped_back_is_turned_back_towards_the_ground(roll: float, pitch: float, turned: bool) -> None:
    # pushed from the front the robot tips back onto its heels: a swing foot that tips with the torso lands
    # heel first, ahead of where the step meant, and the robot never gets its soles flat again (MuJoCo: the
    # first push, 20 N, threw it over in 3 of 5 seeds); forwards and sideways the foot holds on its toes and edges
    stiff = tilt_of(swing_sole_on_the_ground(roll, pitch, 0.0))
    assert stiff == pytest.approx((roll, pitch), abs=0.02)  # without levelling the foot tips with the torso
    defaults = WalkingEngine.Parameters()
    share, deadband = defaults.level_swing, defaults.level_deadband
    assert share >= 0.3 and deadband < 0.1
    levelled = tilt_of(swing_sole_on_the_ground(roll, pitch, share))
    # the backward tilt beyond the deadband (the walk's own rocking), by the share, is taken off
    expected_pitch = pitch + share * max(-pitch - deadband, 0.0) if turned else pitch
    assert levelled == pytest.approx((roll, expected_pitch), abs=0.02)
    if turned:
        assert levelled[1] > pitch + 0.05  # flatter than the torso
