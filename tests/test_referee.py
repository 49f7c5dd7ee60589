"""The simulated GameController (``tools/simulation/referee.py``) in a match's world without robot programs: robots
put where a test wants them, the referee ticked by hand, its packets read from the published layout."""

from __future__ import annotations

import math
import socket
from collections.abc import Iterator

import pytest

from tafel.platforms.match_world import MatchWorld, Side
from tafel.representations.game import Penalty, SetPlay, State
from tafel.tools.simulation.match import free_udp_port
from tafel.tools.simulation.referee import Player, Referee

TICK = 0.01


@pytest.fixture
def referee() -> Iterator[Referee]:
    """A 1v1 match world (team 1 attacks +x); nobody moves unless a test moves it."""
    players = [Player(team=0, number=1, index=0, side=Side(1.0)), Player(team=1, number=1, index=1, side=Side(-1.0))]
    world = MatchWorld([(-3000.0, -3000.0), (3000.0, -3000.0)])
    world.move_robot(0, -2000.0, 0.0, 0.0)
    world.move_robot(1, 2000.0, 0.0, math.pi)
    ref = Referee(world, (1, 2), players, 600.0, free_udp_port(), free_udp_port(), (free_udp_port(), free_udp_port()), ready_s=4.0)
    ref.now = 0.0
    yield ref
    ref.close()


def run(ref: Referee, seconds: float) -> None:
    for _ in range(int(round(seconds / TICK))):
        ref.now += TICK
        ref.tick(ref.now, TICK)


def until(ref: Referee, state: State, limit: float = 60.0) -> None:
    while ref.game.state is not state:
        assert ref.now < limit, f"no {state.name} within {limit} s: {[e.what for e in ref.events]}"
        run(ref, TICK)


def test_the_states_run_as_game_controller3_runs_them_with_standby_and_the_ready_clock(referee: Referee) -> None:
    until(referee, State.ready)
    run(referee, 1.0)
    assert referee.game.secondary_time == 3  # READY's own clock counts down
    until(referee, State.playing)
    assert [e.what for e in referee.events] == ["STANDBY", "READY", "SET", "PLAYING"]
    assert referee.clock == pytest.approx(600.0)  # a half's clock starts with its first PLAYING
    referee.world.move_ball(4600.0, 0.0)  # a goal: READY again, and now the clock runs in READY and SET
    run(referee, TICK)
    assert referee.game.state is State.ready and referee.score() == "1:0"
    run(referee, 2.0)
    assert referee.clock < 598.5


def test_team_messages_count_only_in_standby_ready_set_and_playing_and_illegal_ones_cost_the_score(referee: Referee) -> None:
    sender = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    port = referee.team_ports[0]
    try:
        sender.sendto(b"x" * 30, ("127.0.0.1", port))  # INITIAL: not counted
        run(referee, 0.1)
        assert referee.messages == [0, 0] and referee.messages_heard == [1, 0]
        until(referee, State.playing)
        referee.game.teams[0].score = 2
        sender.sendto(b"x" * 30, ("127.0.0.1", port))
        run(referee, 0.1)
        assert referee.messages == [1, 0] and referee.game.teams[0].message_budget == 1199
        sender.sendto(b"x" * 129, ("127.0.0.1", port))  # over 128 bytes: illegal communication
        run(referee, 0.1)
        assert referee.illegal_communication == [True, False] and referee.game.teams[0].score == 0
        assert any(f.reason == "illegal communication: 129 bytes" for f in referee.fouls)
        referee.world.move_ball(4600.0, 0.0)
        run(referee, TICK)
        assert referee.game.teams[0].score == 0  # its goals no longer count
    finally:
        sender.close()


def test_in_set_a_robot_in_the_other_half_is_penalized_15_s_counted_only_in_ready_and_playing(referee: Referee) -> None:
    until(referee, State.set)
    referee.world.move_robot(1, -500.0, 1000.0, math.pi)  # team 2's robot in team 1's half
    run(referee, referee.set_grace_s + 0.1)
    foul = referee.fouls[-1]
    assert (foul.team, foul.player, foul.penalty) == (2, 1, Penalty.illegal_position_in_set)
    robot = referee.game.teams[1].players[0]
    assert robot.penalty is Penalty.illegal_position_in_set and robot.secs_till_unpenalised == 15
    run(referee, 1.0)  # still SET: the penalty time stands
    assert robot.secs_till_unpenalised == 15
    until(referee, State.playing)
    run(referee, 15.1)
    assert robot.penalty is Penalty.none
    x, y, _ = referee.world.robot_pose(1)
    assert x > 0 and abs(abs(y) - 3000.0) < 10.0  # back on a touchline of its own half


def test_a_defender_in_the_centre_circle_at_the_kick_off_and_near_a_free_kick_is_penalized_45_s(referee: Referee) -> None:
    until(referee, State.playing)  # team 1 kicks off
    referee.world.move_robot(1, 500.0, 300.0, math.pi)
    run(referee, TICK)
    assert referee.fouls[-1].penalty is Penalty.illegal_position and referee.game.teams[1].players[0].secs_till_unpenalised == 45
    assert "centre circle" in referee.fouls[-1].reason
    referee.game.teams[1].players[0].penalty, referee.players[1].penalized_until_s = Penalty.none, -1.0  # back at once, for the test
    referee.world.move_ball(1000.0, 3200.0)  # out over the touchline: a kick-in
    referee.last_touch = 1
    referee.world.move_robot(1, 1500.0, 2500.0, math.pi)
    run(referee, TICK)
    assert referee.game.set_play is SetPlay.kick_in and referee.game.kicking_team == 1
    run(referee, referee.free_kick_grace_s + 0.1)
    foul = referee.fouls[-1]
    assert foul.penalty is Penalty.illegal_position and "0.75 m" in foul.reason and foul.team == 2
    assert referee.game.teams[1].players[0].secs_till_unpenalised == 55  # incremental: its team's second


def test_walking_into_an_opponent_away_from_the_ball_is_pushing(referee: Referee) -> None:
    until(referee, State.playing)
    referee.world.move_robot(0, -2000.0, 2000.0, 0.0)
    referee.world.move_robot(1, -1750.0, 2000.0, math.pi)
    referee.world.data.qvel[referee.world.robots[0].root_qvel] = 0.3  # team 1's robot walks into the other at 300 mm/s
    run(referee, TICK)
    foul = referee.fouls[-1]
    assert (foul.team, foul.player, foul.penalty) == (1, 1, Penalty.player_pushing) and "walked into team 2 player 1" in foul.reason
