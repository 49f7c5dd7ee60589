"""The match's pass counter (``tools/simulation/passes.py``): completed passes and own goals from ground truth."""

from __future__ import annotations

from tafel.tools.simulation.passes import PassCounter

#: robots 0 and 1 play for team 0, robots 2 and 3 for team 1
TEAMS = [0, 0, 1, 1]
AWAY = (9000.0, 9000.0)


def roll(counter: PassCounter, start: tuple[float, float], end: tuple[float, float], robots: list, t0: float = 0.0,
         steps: int = 50, playing: bool = True) -> float:
    """The ball rolls from ``start`` to ``end`` in ``steps`` ticks of 10 ms; the robots stand still. Returns the time."""
    t = t0
    for k in range(steps + 1):
        t = t0 + 0.01 * k
        ball = (start[0] + (end[0] - start[0]) * k / steps, start[1] + (end[1] - start[1]) * k / steps)
        counter.observe(t, ball, robots, playing)
    return t


def test_a_ball_kicked_to_a_teammate_two_metres_away_is_one_pass_of_that_team() -> None:
    counter = PassCounter(TEAMS)
    robots = [(-200.0, 0.0), (2200.0, 0.0), AWAY, AWAY]
    roll(counter, (0.0, 0.0), (2000.0, 0.0), robots)
    assert counter.count(0) == 1 and counter.count(1) == 0
    done = counter.passes[0]
    assert (done.kicker, done.receiver) == (0, 1) and 1700.0 < done.distance_mm < 2100.0


def test_no_pass_when_the_ball_goes_too_short_an_opponent_touches_it_between_or_play_stops() -> None:
    short = PassCounter(TEAMS)  # 0.6 m: a scramble, not a pass
    roll(short, (0.0, 0.0), (600.0, 0.0), [(-200.0, 0.0), (800.0, 0.0), AWAY, AWAY])
    assert short.passes == []
    intercepted = PassCounter(TEAMS)  # the opponent on the way touches it first
    roll(intercepted, (0.0, 0.0), (3000.0, 0.0), [(-200.0, 0.0), (3200.0, 0.0), (1500.0, 100.0), AWAY])
    assert intercepted.passes == [] and intercepted.last_toucher == 1  # the teammate's touch came after the opponent's
    stopped = PassCounter(TEAMS)  # a goal kick's placement in between: not a pass
    robots = [(-200.0, 0.0), (2200.0, 0.0), AWAY, AWAY]
    t = roll(stopped, (0.0, 0.0), (1000.0, 0.0), robots)
    t = roll(stopped, (1000.0, 0.0), (1000.0, 0.0), robots, t, steps=5, playing=False)
    roll(stopped, (1000.0, 0.0), (2000.0, 0.0), robots, t)
    assert stopped.passes == []


def test_the_same_robot_dribbling_is_no_pass_and_a_placed_ball_breaks_the_chain() -> None:
    dribble = PassCounter(TEAMS)
    for k in range(300):  # the robot walks with the ball for 3 m
        x = 10.0 * k
        dribble.observe(0.01 * k, (x, 0.0), [(x - 200.0, 0.0), (3300.0, 0.0), AWAY, AWAY], True)
    assert dribble.passes == []
    placed = PassCounter(TEAMS)
    robots = [(-200.0, 0.0), (2200.0, 2000.0), AWAY, AWAY]
    placed.observe(0.0, (0.0, 0.0), robots, True)  # touched by robot 0
    placed.observe(0.01, (2000.0, 2000.0), robots, True)  # put beside robot 1 by the referee (a jump), not kicked
    assert placed.passes == []


def test_an_own_goal_is_a_goal_last_touched_by_the_conceding_team_not_a_failed_save() -> None:
    counter = PassCounter(TEAMS)
    counter.observe(0.0, (-4000.0, 0.0), [(-3800.0, 0.0), AWAY, AWAY, AWAY], True)  # team 0's robot plays it into its own goal
    assert counter.goal(conceding_team=0) and counter.own_goals == [1, 0]
    saved = PassCounter(TEAMS)  # team 1 shoots at team 0's goal (at -x); team 0's keeper on the line touches it, it goes in
    roll(saved, (-1900.0, 0.0), (-4600.0, 0.0), [(-4300.0, 0.0), AWAY, (-1750.0, 0.0), AWAY])
    assert saved.last_toucher == 0 and not saved.goal(conceding_team=0) and saved.own_goals == [0, 0]
    counter.observe(1.0, (4000.0, 0.0), [(3800.0, 0.0), AWAY, AWAY, AWAY], True)  # team 0 scores at the other end
    assert not counter.goal(conceding_team=1) and counter.own_goals == [1, 0]
