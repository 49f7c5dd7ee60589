"""The modify values of the modules users tune live (walk, kick, ball model): a debug client pins one
with ``modify:set`` and the module does something else at once; released, it goes back."""

from __future__ import annotations

from tafel.core.testing import ModuleHarness
from tafel.debug.commands import ContextDebug
from tafel.debug.executors import RateMeter, instrument
from tafel.debug.protocol import parse
from tafel.modules.behavior.striker import Striker
from tafel.modules.modeling.kalman_ball_modeler import KalmanBallModeler
from tafel.modules.motion.walking_engine import WalkingEngine
from tafel.representations.modeling import BallModel
from tafel.representations.motion_control import MotionRequest, MotionSelection, MotionType, Odometry, WalkingEngineOutput
from tafel.representations.perception import BallPercept


def client(harness: ModuleHarness, context: str) -> ContextDebug:
    """The debug server's side of one context, on the harness's manager (as ``tafel run`` wires it)."""
    instrument(context, harness.manager, RateMeter())
    return ContextDebug(context, harness.manager)


def ask(debug: ContextDebug, line: str) -> str:
    status, answer = debug.execute(parse(line))
    assert status == "ok", answer
    return str(answer)


def test_a_pinned_step_duration_slows_the_walk_and_one_beyond_its_range_is_refused() -> None:
    request = MotionRequest(motion=MotionType.walk, walk_x=200.0)
    harness = ModuleHarness(WalkingEngine, request, MotionSelection(active=MotionType.walk), context="motion")
    debug = client(harness, "motion")
    harness.execute(frames=3)
    listed = ask(debug, "modify:list")
    assert "WalkingEngine:step_duration = 0.25" in listed and "WalkingEngine:foot_lift" in listed

    def phase_after(frames: int) -> float:
        harness.execute(frames=frames)
        return harness[WalkingEngineOutput].step_phase

    for _ in range(100):  # to the start of a step
        if phase_after(1) == 1.0:
            break
    normal = phase_after(10)
    ask(debug, "modify:set -name WalkingEngine:step_duration -value 0.5")
    for _ in range(100):
        if phase_after(1) == 1.0:
            break
    slow = phase_after(10)
    assert slow < 0.6 * normal, (normal, slow)  # the same time is half as far into a step twice as long
    assert "pinned to 0.5" in ask(debug, "modify:list")
    status, answer = debug.execute(parse("modify:set -name WalkingEngine:step_duration -value 9"))  # beyond its range
    assert status == "error" and "takes a number from 0.15 to 0.6" in answer, answer
    harness.execute(frames=1)
    assert harness.module.tuned.step_duration == 0.5  # refused: the value pinned before stays
    ask(debug, "modify:release -name WalkingEngine:step_duration")
    harness.execute(frames=1)
    assert harness.module.tuned.step_duration == 0.25


def test_a_pinned_kick_distance_changes_where_the_striker_walks_and_when_it_kicks() -> None:
    ball = BallModel(valid=True, x=2000.0, y=0.0)
    harness = ModuleHarness(Striker, ball, Odometry(), parameters={"walk_kick": False})  # the keyframe kick's distance
    debug = client(harness, "cognition")
    assert harness.execute()[MotionRequest].target_x == 2000.0 - 190.0
    ask(debug, "modify:set -name Kick:behind -value 300")
    assert harness.execute()[MotionRequest].target_x == 2000.0 - 300.0
    harness.set(BallModel(valid=True, x=300.0, y=50.0))  # the ball where the pinned distance kicks
    assert harness.execute()[MotionRequest].motion is MotionType.kick
    ask(debug, "modify:release -name Kick:behind")
    assert harness.execute()[MotionRequest].motion is MotionType.walk_to


def test_a_pinned_forget_time_keeps_the_ball_model_valid_longer() -> None:
    harness = ModuleHarness(KalmanBallModeler)
    debug = client(harness, "cognition")
    harness.set(BallPercept(seen=True, x=1500.0, y=0.0))
    harness.execute(frames=10)
    harness.set(BallPercept(seen=False))
    ask(debug, "modify:set -name KalmanBallModeler:forget_after -value 6")
    harness.advance(4.0)
    assert harness[BallModel].valid  # 4 s unseen: the default of 3 s would have forgotten it
    ask(debug, "modify:release -name KalmanBallModeler:forget_after")
    harness.execute(frames=1)
    assert not harness[BallModel].valid
