"""Kicks out of the walk (issue 36): the kicking step on the mocked blackboard, the behaviour's approach,
and kicks judged on simulator ground truth in MuJoCo and PyBullet."""

from __future__ import annotations

import math
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from tafel.core.testing import ModuleHarness
from tafel.modules.behavior.kicking import KickParameters, approach_and_kick
from tafel.modules.behavior.striker import Striker
from tafel.modules.motion.keyframes import MotionFileError
from tafel.modules.motion.walk_kicks import WALK_KICKS_FILE, kick_swing, load_walk_kicks
from tafel.modules.motion.walking_engine import WalkingEngine
from tafel.representations.modeling import BallModel
from tafel.representations.motion_control import (
    Foot,
    MotionRequest,
    MotionSelection,
    MotionType,
    Odometry,
    WalkingEngineOutput,
    WalkKick,
)
from tests.support.kick_trials import kick_trial
from tests.support.simulation import Simulation

KICKS = load_walk_kicks()


def walk_kick(foot: Foot, kick: WalkKick = WalkKick.long, direction: float = 0.0) -> MotionRequest:
    return MotionRequest(motion=MotionType.walk, walk_kick=kick, kick_foot=foot, kick_direction=direction)


def walking(request: MotionRequest) -> ModuleHarness:
    return ModuleHarness(WalkingEngine, request, MotionSelection(active=request.motion), context="motion")


# ------------------------------------------------------------------------------------ the kicking step
@pytest.mark.parametrize("foot", [Foot.left, Foot.right])
def test_a_walk_kick_is_a_step_of_the_kicking_foot_after_two_walk_steps_once_per_request(foot: Foot) -> None:
    harness = walking(walk_kick(foot))
    harness.advance(0.9)  # the kick's rearm time is 1 s: one kick
    outputs = harness.history(WalkingEngineOutput)
    kicking = [o for o in outputs if o.kicking]
    assert harness[WalkingEngineOutput].kicks == 1 and kicking
    swing = {o.support_foot for o in kicking}
    assert swing == {Foot.right if foot is Foot.left else Foot.left}  # the other foot supports
    first = next(i for i, o in enumerate(outputs) if o.kicking)
    changes = sum(1 for a, b in zip(outputs[:first], outputs[1:first + 1]) if a.support_foot is not b.support_foot)
    assert first * 0.01 >= 2 * 0.25 - 1e-6 and changes >= 1  # two walk steps first: the torso sways in rhythm
    harness.set(MotionRequest(motion=MotionType.walk))  # the request dropped: no kick, it re-arms
    harness.advance(0.5)
    assert harness[WalkingEngineOutput].kicks == 1
    harness.set(walk_kick(foot))
    harness.advance(1.0)
    assert harness[WalkingEngineOutput].kicks == 2  # a new request kicks again at once


def test_the_kicking_foot_is_driven_forward_further_than_a_walk_step_and_the_walk_goes_on() -> None:
    harness = walking(walk_kick(Foot.left))
    engine = harness.module
    ahead = []
    for _ in range(120):
        harness.execute(1)
        if harness[WalkingEngineOutput].kicking:
            ahead.append(float(engine.now[Foot.left][0]))
    assert max(ahead) == pytest.approx(KICKS[WalkKick.long].reach, abs=1.0)
    assert min(ahead) < -KICKS[WalkKick.long].retract * 0.9  # drawn back first
    assert not harness[WalkingEngineOutput].standing  # still stepping: no stop


def test_a_kick_asked_for_while_standing_starts_the_walk_and_kicks() -> None:
    harness = walking(MotionRequest(motion=MotionType.walk))
    harness.advance(0.5)
    assert harness[WalkingEngineOutput].standing
    harness.set(walk_kick(Foot.right, WalkKick.short))
    harness.advance(1.0)
    assert harness[WalkingEngineOutput].kicks == 1


@pytest.mark.parametrize("kick", [WalkKick.short, WalkKick.long])
@pytest.mark.parametrize("direction", [-0.8, -0.4, 0.0, 0.4, 0.8])
def test_the_kicking_foot_swings_along_the_kick_direction_never_inwards(kick: WalkKick, direction: float) -> None:
    step, start, landing = KICKS[kick], np.zeros(3), np.array([20.0, 0.0, 0.0])
    direction = max(-step.max_direction, min(step.max_direction, direction))
    for foot, side in ((Foot.left, 1.0), (Foot.right, -1.0)):
        back, _, _ = kick_swing(step, step.extend_from, start, landing, direction, foot)
        ahead, lift, _ = kick_swing(step, step.put_down_from - 1e-6, start, landing, direction, foot)
        assert lift > 0.0
        for phase in np.linspace(0.0, 1.0, 41):
            place, _, _ = kick_swing(step, float(phase), start, landing, direction, foot)
            assert place[1] * side >= -5.0 - 1e-9  # never towards the support foot
        if direction * side >= 0:  # outwards: driven out along the kick's line, the foot turned to it, from behind
            assert math.atan2(ahead[1], ahead[0]) == pytest.approx(direction, abs=1e-9)
            assert ahead[2] == pytest.approx(step.yaw_share * direction)
            assert back[0] < 0.0 < ahead[0]


def test_the_walk_kicks_file_is_checked_key_by_key(tmp_path: Path) -> None:
    text = WALK_KICKS_FILE.read_text(encoding="utf-8")
    broken = tmp_path / "walk_kicks.toml"
    broken.write_text(text.replace("\nreach_lift =", "\nreach_lifted =", 1), encoding="utf-8")
    with pytest.raises(ValueError, match=r"\[short\] needs exactly .*reach_lift"):
        load_walk_kicks(broken)
    broken.write_text(text.replace("extend_to = 0.7", "extend_to = 0.2", 1), encoding="utf-8")
    with pytest.raises(ValueError, match="extend_from < extend_to"):
        load_walk_kicks(broken)


def test_a_missing_unreadable_or_non_numeric_walk_kicks_file_says_what_is_wrong(tmp_path: Path) -> None:
    """Bad motion files get the motion files' own error (``MotionFileError``) with what would be right."""
    with pytest.raises(MotionFileError, match="no motion file .*walk_kicks.toml; the motions are"):
        load_walk_kicks(tmp_path / "walk_kicks.toml")
    broken = tmp_path / "walk_kicks.toml"
    broken.write_text("[short\nduration = 0.4", encoding="utf-8")
    with pytest.raises(MotionFileError, match="not valid TOML"):
        load_walk_kicks(broken)
    text = WALK_KICKS_FILE.read_text(encoding="utf-8")
    broken.write_text(text.replace("extend_to = 0.7", 'extend_to = "fast"', 1), encoding="utf-8")
    with pytest.raises(MotionFileError, match=r"\[short\] needs a number for each of"):
        load_walk_kicks(broken)


def test_the_status_line_names_a_walk_kick_and_only_then() -> None:
    assert walk_kick(Foot.right, WalkKick.short).status_text().endswith(", short kick right")
    asked = MotionRequest(motion=MotionType.walk_to, target_x=300.0, walk_kick=WalkKick.long).status_text()
    assert asked == "request walk_to 300,0 mm 0.00 rad, long kick left"
    assert "kick" not in MotionRequest(motion=MotionType.walk_to, target_x=300.0).status_text()


# ------------------------------------------------------------------------------------ the behaviour
def striker(ball: BallModel) -> MotionRequest:
    return ModuleHarness(Striker, ball, Odometry()).execute()[MotionRequest]


def test_the_striker_walks_to_the_walk_kick_pose_and_asks_for_the_long_kick_there() -> None:
    p = KickParameters()
    far = striker(BallModel(valid=True, x=2000.0, y=0.0))
    assert far.motion is MotionType.walk_to and far.walk_kick is WalkKick.none
    assert far.target_x == pytest.approx(2000.0 - p.walk_kick_distance) and far.target_y == pytest.approx(-p.foot_offset)
    near = striker(BallModel(valid=True, x=p.walk_kick_distance + 30.0, y=p.foot_offset + 60.0))
    assert near.motion is MotionType.walk_to and near.walk_kick is WalkKick.long and near.kick_foot is Foot.left
    assert near.kick_direction == pytest.approx(0.0, abs=p.walk_kick_long_max_angle)


@pytest.mark.parametrize("direction", [-0.6, -0.3, 0.3, 0.6])
def test_a_turned_walk_kick_needs_no_turn_of_the_robot_and_kicks_with_the_outer_foot(direction: float) -> None:
    p = replace(KickParameters(), walk_kick=True)
    out = MotionRequest()
    ball = BallModel(valid=True, x=800.0, y=-100.0)
    approach_and_kick(ball, direction, p, out, WalkKick.short)
    assert out.motion is MotionType.walk_to and out.target_rotation == pytest.approx(0.0)
    assert out.kick_foot is (Foot.left if direction > 0 else Foot.right)
    # the ball lies on the kick's line through the kicking foot at the pose walked to
    side = p.foot_offset if out.kick_foot is Foot.left else -p.foot_offset
    dx, dy = ball.x - out.target_x, ball.y - out.target_y - side
    assert math.atan2(dy, dx) == pytest.approx(direction, abs=1e-9)
    wide = MotionRequest()
    approach_and_kick(ball, 1.2, p, wide, WalkKick.short)  # beyond what the kick turns: the robot turns the rest
    assert wide.target_rotation == pytest.approx(1.2 - p.walk_kick_max_angle)


def test_without_walk_kick_the_keyframe_kick_stays() -> None:
    p = replace(KickParameters(), walk_kick=False)
    out = MotionRequest()
    approach_and_kick(BallModel(valid=True, x=p.behind, y=p.foot_offset), 0.0, p, out)
    assert out.motion is MotionType.kick and out.walk_kick is WalkKick.none


# ------------------------------------------------------------------------------------ ground truth
@pytest.mark.slow
@pytest.mark.parametrize("engine", ["mujoco", "pybullet"])
@pytest.mark.parametrize(("direction", "kick", "seed", "least_mm"), [(0.0, WalkKick.long, 1, 800.0), (0.0, WalkKick.short, 0, 300.0),
                                                                     (45.0, WalkKick.short, 1, 200.0), (-45.0, WalkKick.short, 2, 200.0)])
def test_a_walk_kick_sends_the_ball_where_asked_without_stopping_or_falling(engine: str, direction: float, kick: WalkKick, seed: int,
                                                                            least_mm: float) -> None:
    trial = kick_trial(engine, seed, direction, kick)
    assert trial.falls == 0
    assert math.isfinite(trial.request_to_moving_s)  # it kicked
    assert trial.distance_mm >= least_mm
    assert abs(trial.direction_error_deg) <= 12.0


@pytest.mark.slow
@pytest.mark.parametrize("seed", [0, 1])
def test_the_striker_with_its_cameras_walks_to_the_ball_and_kicks_it_towards_the_goal_out_of_the_walk(seed: int) -> None:
    """The whole program (perception, ball model, ``Striker``) in the default scene, judged on ground truth:
    from (-1500, 0) to the ball on the centre spot, walk kicks towards the opponent goal, no fall."""
    sim = Simulation("mujoco", scene="default", cameras="on", seed=str(seed), overrides=['cognition.providers.MotionRequest="Striker"'])
    lying = [False, 0]

    def watch(s: Simulation) -> None:
        down = s.platform.posture() != "upright"
        lying[1] += int(down and not lying[0])
        lying[0] = down

    try:
        sim.run(20.0, watch)
        kicks = sim.blackboard("motion")[WalkingEngineOutput].kicks
        x, y = sim.platform.ball_position()
    finally:
        sim.close()
    assert lying[1] == 0
    assert kicks >= 1
    assert x > 2000.0 and abs(y) < x  # played well on towards the opponent goal (+x)
