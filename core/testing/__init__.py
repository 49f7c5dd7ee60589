"""Testing support: one module on a mocked blackboard, with a clock, input sequences, approximate
comparison, access assertions, recorded situations, and hypothesis strategies.

    def test_the_ball_model_follows_a_rolling_ball(module_harness):
        harness = module_harness(KalmanBallModeler)
        harness.feed({BallPercept: [BallPercept(seen=True, x=1000.0 + 10 * i) for i in range(30)]})
        harness.execute()                      # 30 frames, FrameInfo advancing by 1/30 s each
        assert_close(harness[BallModel].x, 1290.0, abs=30.0)

The pytest plugin (registered through the ``pytest11`` entry point, so every project with Tafel
installed has it) offers ``run_module``, ``module_harness``, ``replay_module`` and ``log_slice``
fixtures, and resets process-wide debug state (requests, pins, drawings, plots) after every test.
Everything runs strict: an exception in the module fails the test with its own traceback.
"""


from tafel.core.testing.compare import assert_close, differences
from tafel.core.testing.harness import CONTEXT_RATES_HZ, RESET_HOOKS, ModuleHarness, context_of, run_module
from tafel.core.testing.replay import ReplayFrame, ReplayResult, replay_module
from tafel.core.testing.strategies import strategy_for

__all__ = ["CONTEXT_RATES_HZ", "RESET_HOOKS", "ModuleHarness", "ReplayFrame", "ReplayResult", "assert_close", "context_of",
           "differences", "replay_module", "run_module", "strategy_for"]
