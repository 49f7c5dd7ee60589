"""Getting up (issue 36), in process on both simulators, judged by their ground truth over several seeds:
quick (the issue asks for 6 s, from the front and the back) and steady (still upright 2 s later), also when
the walk follows."""

from __future__ import annotations

import pytest

from tests.support.getting_up import TURNING, get_up, seeded_walk_s

ENGINES = ["mujoco", "pybullet"]
SEEDS = range(3)
#: s from being laid down to standing: the issue's target, 6 s on both sides. From the front at most 5.6 s
#: (MuJoCo) and 6.0 s (PyBullet) over 30 seeds (medians 6.2 and 6.4 s with the slower keyframes before, 8.3 to
#: 9.3 s before issue 36), from the back at most 4.9 and 5.3 s. A get-up that had to start again takes 3 s
#: more and fails the bound.
WITHIN_S = {"back": 6.0, "front": 6.0}


@pytest.mark.slow
@pytest.mark.parametrize("side", ["front", "back"])
@pytest.mark.parametrize("engine", ENGINES)
def test_getting_up_is_quick_and_the_robot_stays_up(engine: str, side: str) -> None:
    """Each seed lies with its own joint angles (laid down after walking its own 0 to 1 s). A get-up that
    had to start again (from the side it then lay on) takes too long."""
    results = {seed: get_up(engine, side, seed, seeded_walk_s(seed)) for seed in SEEDS}
    failed = {seed: result for seed, result in results.items() if not result.succeeded}
    assert not failed, f"did not get up, or fell again within 2 s: {failed}"
    slow = {seed: result.up_s for seed, result in results.items() if result.up_s is not None and result.up_s > WITHIN_S[side]}
    assert not slow, f"took longer than {WITHIN_S[side]} s: {slow}"


#: s of turning in place before being laid down: moments 0.08 s apart across about two steps each way
TURN_MOMENTS = [0.57 + 0.08 * i for i in range(10)]


@pytest.mark.slow
@pytest.mark.parametrize("engine", ENGINES)
def test_after_getting_up_from_the_back_the_walk_goes_on_without_falling(engine: str) -> None:
    """The striker searching for the ball turns in place; laid on its back at moments across its steps, it
    gets up and turns on: ground truth must see it stay upright for 2 s after standing, every time (this is
    ``test_walking.py::test_getting_up_from_lying[mujoco-back]``'s falling back, made repeatable)."""
    results = {round(moment, 2): get_up(engine, "back", index % 3, moment, before=TURNING, after=TURNING)
               for index, moment in enumerate(TURN_MOMENTS)}
    fell_again = {moment: result.up_s for moment, result in results.items() if result.up_s is not None and not result.stayed_up}
    never_up = [moment for moment, result in results.items() if result.up_s is None]
    assert not fell_again and not never_up, f"fell again after standing (laid down at s: stood at s): {fell_again}; never stood: {never_up}"
