"""The simulated GameController (``tools/simulation/referee.py``) in a match's world without robot programs: robots
put where a test wants them, the referee ticked by hand, its packets read from the published layout."""

from __future__ import annotations

import math
import socket
from collections.abc import Iterator

import mujoco
import numpy as np
import pytest

from tafel.platforms.match_world import MatchWorld, Side
from tafel.platforms.network import listening_socket
from tafel.representations.game import Penalty, SetPlay, State
from tafel.representations.motion import JOINT_NAMES
from tafel.tools.simulation.match import free_udp_port
from tafel.tools.simulation.officiating import Player
from tafel.tools.simulation.referee import Referee
from tafel.tools.simulation.set_plays import Call
from tests.test_game_controller import GAME, TEAM  # the published layout, never the code under test

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
    # the rules' re-entry point: 0.5 m outside the touchline nearest to where it was taken off (its right, at
    # world y > 0 for team 2), level with its own penalty mark (world x = 4500 - 1300), facing the field
    assert referee.world.robot_pose(1) == pytest.approx((3200.0, 3500.0, -math.pi / 2), abs=1.0)


def test_a_robot_put_back_where_another_stands_goes_along_the_touchline_and_standing_there_is_not_leaving_the_field(
        referee: Referee) -> None:
    until(referee, State.playing)
    referee.world.move_robot(0, -2000.0, -1500.0, 0.0)  # team 1's robot, on its right
    referee.penalize(referee.players[0], Penalty.request_for_pickup, referee.now)
    run(referee, 44.0)
    referee.game.teams[1].players[0].penalty, referee.players[1].penalized_until_s = Penalty.none, -1.0  # (inactive meanwhile)
    referee.world.move_robot(1, -3200.0, -3500.0, 0.0)  # an opponent on its re-entry point
    run(referee, 1.1)
    assert referee.game.teams[0].players[0].penalty is Penalty.none
    assert referee.world.robot_pose(0) == pytest.approx((-2800.0, -3500.0, math.pi / 2), abs=1.0)  # 0.4 m on, facing the field
    run(referee, 1.0)
    assert not [f for f in referee.fouls if f.penalty is Penalty.leaving_the_field]  # on the carpet, 0.5 m beyond the line


@pytest.mark.parametrize("x, y, left", [(0.0, 3500.0, False), (0.0, -3750.0, True), (5150.0, 0.0, False), (5250.0, 1000.0, True)])
def test_leaving_the_field_is_leaving_the_carpet_not_crossing_a_line(referee: Referee, x: float, y: float, left: bool) -> None:
    """The rules' 10.4 x 7.4 m carpet: 0.7 m beyond the lines."""
    until(referee, State.playing)
    referee.world.move_robot(1, x, y, 0.0)
    run(referee, TICK)
    assert bool([f for f in referee.fouls if f.penalty is Penalty.leaving_the_field]) == left, referee.fouls


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


def walk(ref: Referee, index: int, start: tuple[float, float], heading: float, velocity: tuple[float, float], seconds: float,
         sway: float = 0.0) -> None:
    """Move robot ``index`` from ``start`` (mm) at ``velocity`` (mm/s) for ``seconds``, facing ``heading``, its torso
    swaying ``sway`` mm sideways at 2 Hz (a walk's steps), the referee ticking."""
    for k in range(int(round(seconds / TICK)) + 1):
        t = k * TICK
        side = sway * math.sin(2 * math.pi * 2.0 * t)
        ref.world.move_robot(index, start[0] + velocity[0] * t - side * math.sin(heading),
                             start[1] + velocity[1] * t + side * math.cos(heading), heading)
        run(ref, TICK)


def test_walking_into_an_opponent_is_pushing_by_the_rule_book_even_in_a_duel_for_the_ball(referee: Referee) -> None:
    until(referee, State.playing)
    referee.world.move_robot(1, -1700.0, 2000.0, math.pi / 2)  # team 2's robot stands, facing along the touchline
    referee.world.move_ball(-1800.0, 2250.0)  # beside both: a duel near the ball no longer excuses a push
    walk(referee, 0, (-2200.0, 2000.0), 0.0, (300.0, 0.0), 0.6)  # team 1's walks into its side at 300 mm/s
    foul = referee.fouls[-1]
    assert (foul.team, foul.player, foul.penalty) == (1, 1, Penalty.player_pushing) and "walked into team 2 player 1" in foul.reason
    # within 0.5 m of the ball: a pushing free kick for the pushed team, the ball left where it is
    assert referee.game.set_play is SetPlay.pushing_free_kick and referee.game.kicking_team == 2
    assert referee.world.ball_position() == pytest.approx((-1800.0, 2250.0), abs=1.0)


@pytest.mark.parametrize("case", ["far from the ball", "into the pusher's penalty area", "during a free kick"])
def test_a_push_away_from_the_ball_or_into_the_own_penalty_area_or_in_a_free_kick_brings_no_free_kick(
        referee: Referee, case: str) -> None:
    """The rules: a pushing free kick only for a pusher within about 0.5 m of the ball; a push into the pusher's own
    penalty area would be a penalty kick (this referee does not run one), and a push during a free kick brings none."""
    until(referee, State.playing)
    start, to, ball = (-2200.0, 2000.0), (-1700.0, 2000.0), (-1800.0, 2250.0)
    if case == "far from the ball":
        ball = (1000.0, 0.0)
    elif case == "into the pusher's penalty area":  # a field player (the keeper there may touch)
        start, to, ball = (-3900.0, 500.0), (-3400.0, 500.0), (-3500.0, 750.0)
        referee.game.teams[0].goalkeeper = 2
    referee.world.move_ball(*ball)
    if case == "during a free kick":
        referee.start_set_play(SetPlay.kick_in, 0, *ball, referee.now)
    referee.world.move_robot(1, *to, math.pi / 2)
    walk(referee, 0, start, 0.0, (300.0, 0.0), 0.6)
    assert [(f.team, f.penalty) for f in referee.fouls] == [(1, Penalty.player_pushing)]
    assert referee.game.set_play is (SetPlay.kick_in if case == "during a free kick" else SetPlay.none)


@pytest.mark.parametrize("case", ["standing swaying", "front to front over the ball", "side on the way to the ball", "keeper in its area"])
def test_the_rule_books_exceptions_to_pushing_are_no_foul(referee: Referee, case: str) -> None:
    until(referee, State.playing)
    if case == "standing swaying":  # a walk's sway touches at 250 mm/s for an instant; over a step it goes nowhere
        referee.world.move_robot(1, -1700.0, 2000.0, math.pi)
        referee.world.move_ball(-3000.0, 2000.0)  # behind it: it is not on its way to the ball
        walk(referee, 0, (-1990.0, 2000.0), math.pi / 2, (0.0, 0.0), 2.0, sway=20.0)
    elif case == "front to front over the ball":
        referee.world.move_robot(1, -1700.0, 2000.0, math.pi)
        referee.world.move_ball(-1850.0, 2030.0)
        walk(referee, 0, (-2200.0, 2000.0), 0.0, (300.0, 0.0), 0.6)
    elif case == "side on the way to the ball":  # walking to the ball ahead, its shoulder brushes a robot beside it
        referee.world.move_robot(1, -1700.0, 2250.0, math.pi)
        referee.world.move_ball(-1000.0, 1900.0)
        walk(referee, 0, (-2200.0, 1950.0), 0.0, (300.0, 0.0), 2.0)
    else:  # team 1's keeper (player 1) in its penalty area
        referee.game.teams[0].goalkeeper = 1
        referee.world.move_robot(1, -3700.0, 500.0, math.pi)
        walk(referee, 0, (-4200.0, 500.0), 0.0, (300.0, 0.0), 0.6)
    assert not [f for f in referee.fouls if f.penalty is Penalty.player_pushing], referee.fouls


# ------------------------------------------------------------------------------- fallen, inactive, motion in SET
def lay(ref: Referee, index: int, x: float, y: float, how: str = "back") -> None:
    """Put a robot down as a fall leaves it (``back``: its torso 60 mm up, tilted 90 degrees) or sitting up
    (``sitting``: upright, 130 mm up), as a get-up passes through."""
    half = math.pi / 4
    height, quaternion = (0.06, [math.cos(half), 0.0, -math.sin(half), 0.0]) if how == "back" else (0.13, [1.0, 0.0, 0.0, 0.0])
    ref.world.robots[index].place(ref.world.data, np.array([x / 1000.0, y / 1000.0, height]), np.array(quaternion))
    mujoco.mj_forward(ref.world.model, ref.world.data)


def bend(ref: Referee, index: int, joint: str, angle: float) -> None:
    """Turn one of a robot's joints (rad), as its program would."""
    robot = ref.world.robots[index]
    ref.world.data.qpos[robot.joint_qpos[JOINT_NAMES.index(joint)]] = angle
    mujoco.mj_forward(ref.world.model, ref.world.data)


def attempt(ref: Referee, index: int, number: int) -> None:
    """One get-up that fails: the legs move, the robot sits up, then falls back and lies still for 1 s."""
    bend(ref, index, "LKneePitch", 0.5 * number)
    lay(ref, index, -2000.0, 0.0, "sitting")
    run(ref, 0.5)
    lay(ref, index, -2000.0, 0.0)
    run(ref, 1.0)


def test_a_fallen_robot_that_does_not_begin_to_get_up_within_5_s_is_penalized_45_s_not_incrementally(referee: Referee) -> None:
    until(referee, State.playing)
    lay(referee, 0, -2000.0, 0.0)
    run(referee, 4.9)
    assert referee.fouls == []
    run(referee, 0.2)
    foul = referee.fouls[-1]
    assert (foul.team, foul.player, foul.penalty, foul.reason) == (1, 1, Penalty.inactive_player, "fallen robot: no get-up within 5 s")
    assert referee.game.teams[0].players[0].secs_till_unpenalised == 45 and referee.incremental == [0, 0]
    assert referee.world.robot_pose(0)[1] < -3000.0  # removed: off the carpet


def test_a_fall_is_watched_across_ready_set_and_playing(referee: Referee) -> None:
    until(referee, State.ready)
    run(referee, 2.0)
    lay(referee, 0, -2000.0, 0.0)
    until(referee, State.set)
    run(referee, 2.9)
    assert referee.fouls == []
    run(referee, 0.2)  # 5 s since it fell, READY's 2 s and SET's 3 s
    assert (referee.fouls[-1].penalty, referee.fouls[-1].reason) == (Penalty.inactive_player, "fallen robot: no get-up within 5 s")


@pytest.mark.parametrize("disturbed", [False, True])
def test_a_fallen_robot_not_up_after_two_attempts_or_three_when_disturbed_is_penalized(referee: Referee, disturbed: bool) -> None:
    until(referee, State.playing)
    if disturbed:  # an opponent beside it
        referee.world.move_robot(1, -2000.0, 300.0, math.pi)
    lay(referee, 0, -2000.0, 0.0)
    run(referee, 1.0)
    attempt(referee, 0, 1)
    assert referee.fouls == [] and referee.fall_watches[0].failed == 1
    attempt(referee, 0, 2)
    if disturbed:
        assert referee.fouls == []
        attempt(referee, 0, 3)
    foul = referee.fouls[-1]
    assert (foul.player, foul.penalty, foul.reason) == (1, Penalty.inactive_player, f"fallen robot: not up after {3 if disturbed else 2} attempts")


def test_a_robot_that_gets_up_in_time_is_not_called_and_its_next_fall_counts_afresh(referee: Referee) -> None:
    until(referee, State.playing)
    for _ in range(3):
        lay(referee, 0, -2000.0, 0.0)
        run(referee, 3.0)
        attempt(referee, 0, 1)  # the first attempt fails; the second gets it up
        bend(referee, 0, "LKneePitch", 0.0)
        referee.world.move_robot(0, -2000.0, 0.0, 0.0)
        run(referee, 1.5)
        assert 0 not in referee.fall_watches
    assert referee.fouls == []


def test_a_robot_that_ceased_activity_for_10_s_is_inactive_moving_its_head_or_seeing_the_ball_is_active(referee: Referee) -> None:
    until(referee, State.playing)
    referee.world.move_robot(0, -2000.0, 0.0, math.pi)  # its back to the ball
    for step in range(1, 5):  # searching for the ball: the head turns now and then
        bend(referee, 0, "HeadYaw", 0.3 * (-1) ** step)
        run(referee, 5.0)
    assert referee.fouls == []  # and team 2's robot, standing still, looks at the ball all along
    run(referee, 5.0)
    assert referee.fouls == []
    run(referee, 0.1)  # 10 s since its head last moved
    foul = referee.fouls[-1]
    assert (foul.team, foul.player, foul.penalty, foul.reason) == (1, 1, Penalty.inactive_player, "inactive robot: no activity for 10 s")
    assert referee.incremental == [0, 0]


@pytest.mark.parametrize("how", ["walked", "turned"])
def test_a_robot_that_walks_in_set_is_penalized_15_s_in_place_head_motion_sway_and_getting_up_are_allowed(
        referee: Referee, how: str) -> None:
    until(referee, State.set)
    run(referee, referee.set_grace_s + 0.05)  # the places are taken
    bend(referee, 0, "HeadYaw", 0.8)  # looking round
    referee.world.move_robot(0, -1950.0, 30.0, 0.1)  # swaying
    lay(referee, 1, 2000.0, 0.0)  # team 2's robot falls and gets up 0.3 m away
    run(referee, 0.3)
    referee.world.move_robot(1, 2300.0, 0.0, math.pi)
    run(referee, 1.2)
    assert referee.fouls == [] and referee.game.state is State.set
    referee.world.move_robot(0, -1800.0, 0.0, 0.0) if how == "walked" else referee.world.move_robot(0, -2000.0, 0.0, 0.5)
    run(referee, TICK)
    foul = referee.fouls[-1]
    assert (foul.team, foul.player, foul.penalty, foul.reason) == (1, 1, Penalty.illegal_motion_in_set, "walked in SET")
    robot = referee.game.teams[0].players[0]
    assert (robot.penalty, robot.secs_till_unpenalised) == (Penalty.illegal_motion_in_set, 15) and referee.incremental == [0, 0]
    assert referee.world.robot_pose(0) == pytest.approx((-2000.0, 0.0, 0.0), abs=1.0)  # put back where it stood in SET, on the field
    until(referee, State.playing)
    run(referee, 14.9)
    assert robot.penalty is Penalty.illegal_motion_in_set  # counted in PLAYING only
    run(referee, 0.2)
    assert robot.penalty is Penalty.none and referee.world.robot_pose(0)[:2] == pytest.approx((-2000.0, 0.0), abs=1.0)  # where it stood
    assert len(referee.fouls) == 1


# ------------------------------------------------------------------------------- penalty shoot-out
def packets_heard(sock: socket.socket) -> list[tuple[tuple, list[tuple]]]:
    """Every GameController packet waiting on ``sock``, read with the published layout (the header's
    fields, then each team's fields and (penalty, seconds) per robot)."""
    heard = []
    while True:
        try:
            data = sock.recv(1024)
        except BlockingIOError:
            return heard
        header = GAME.unpack_from(data)
        teams = [TEAM.unpack_from(data, GAME.size + t * TEAM.size) for t in (0, 1)]
        heard.append((header, [(*team[:8], list(zip(team[8::2], team[9::2]))) for team in teams]))


def last_packet(ref: Referee, sock: socket.socket) -> dict:
    """The newest packet after half a second more of refereeing, by field name."""
    run(ref, 0.51)
    header, teams = packets_heard(sock)[-1]
    names = ("team", "colour", "keeper_colour", "goalkeeper", "score", "penalty_shot", "single_shots", "budget", "robots")
    return {"phase": header[6], "state": header[7], "set_play": header[8], "first_half": header[9], "kicking": header[10],
            "secs_remaining": header[11], "teams": [dict(zip(names, team)) for team in teams]}


@pytest.fixture
def shoot_out() -> Iterator[tuple[Referee, socket.socket]]:
    """A 2v2 world refereed as a penalty shoot-out alone (three shots each and sudden death, as the rules
    say), and a socket that hears the referee's packets."""
    players = [Player(team=t, number=n, index=2 * t + n - 1, side=Side(1.0 if t == 0 else -1.0)) for t in (0, 1) for n in (1, 2)]
    world = MatchWorld([(-3000.0, -3000.0), (-2000.0, -3000.0), (3000.0, -3000.0), (2000.0, -3000.0)])
    port = free_udp_port()
    ear = listening_socket(port)
    ref = Referee(world, (1, 2), players, 600.0, port, free_udp_port(), (free_udp_port(), free_udp_port()), shoot_out="only")
    ref.now = 0.0
    yield ref, ear
    ref.close()
    ear.close()


def take_shot(ref: Referee, outcome: str) -> None:
    """Wait for the shot's PLAYING, then let it end as ``outcome``: the ball into the goal, wide over the
    goal line, off a post, onto the keeper, into the field (where it stops), or left on the penalty mark
    until the time is up."""
    until(ref, State.playing, limit=ref.now + 10.0)
    sign = 1.0 if ref.game.kicking_team == 1 else -1.0  # the goal the kicking team attacks
    if outcome == "post":
        ref.world.move_ball(sign * 4460.0, 760.0)  # beside the post's centre (4550, 800)
        run(ref, TICK)
    spots = {"goal": (4600.0, 200.0), "wide": (4600.0, 1500.0), "post": (3000.0, 1500.0), "saved": (4250.0, 0.0),
             "missed": (2000.0, 1500.0)}
    if outcome in spots:
        ref.world.move_ball(sign * spots[outcome][0], spots[outcome][1])
    run(ref, {"time": 30.1, "goal": TICK, "wide": TICK}.get(outcome, 1.1))  # the others end when the ball stopped
    assert ref.game.state is State.finished and ref.shots[-1].outcome == outcome


def test_the_shoot_out_packets_say_penalty_shoot_who_kicks_and_who_plays_and_the_shots_alternate(
        shoot_out: tuple[Referee, socket.socket]) -> None:
    ref, ear = shoot_out
    start = last_packet(ref, ear)
    assert (start["phase"], start["state"], start["set_play"], start["first_half"], start["kicking"]) == (1, 0, 0, 0, 1)
    assert all(robot[0] == 14 for team in start["teams"] for robot in team["robots"][:2])  # everybody a substitute
    until(ref, State.set)
    first = last_packet(ref, ear)
    assert (first["phase"], first["state"], first["set_play"], first["kicking"], first["secs_remaining"]) == (1, 2, 0, 1, 30)
    kicking, keeping = first["teams"]
    assert [robot[0] for robot in kicking["robots"][:2]] == [14, 0] and kicking["penalty_shot"] == 1  # player 2 strikes
    assert [robot[0] for robot in keeping["robots"][:2]] == [0, 14] and keeping["goalkeeper"] == 1  # player 1 keeps
    # placed as the rules place them: the ball on team 2's penalty mark, the striker on the edge of the penalty
    # area facing the goal, the keeper on the goal line in the goal's centre
    assert ref.world.ball_position() == pytest.approx((3200.0, 0.0), abs=1.0)
    assert ref.world.robot_pose(1) == pytest.approx((2850.0, 0.0, 0.0), abs=5.0)
    x, y, heading = ref.world.robot_pose(2)
    assert (x, y, abs(heading)) == pytest.approx((4400.0, 0.0, math.pi), abs=5.0)
    take_shot(ref, "goal")
    scored = last_packet(ref, ear)
    assert scored["state"] == 4 and scored["teams"][0]["score"] == 1 and scored["teams"][0]["single_shots"] == 0b1
    until(ref, State.set)
    second = last_packet(ref, ear)  # the other team kicks, at the goal it attacks, with its own clock
    assert (second["state"], second["kicking"], second["secs_remaining"]) == (2, 2, 30)
    assert second["teams"][1]["penalty_shot"] == 1 and second["teams"][0]["goalkeeper"] == 1
    assert ref.world.ball_position() == pytest.approx((-3200.0, 0.0), abs=1.0)
    until(ref, State.playing)
    run(ref, 10.0)
    assert last_packet(ref, ear)["secs_remaining"] == 20  # the shot's clock runs in PLAYING
    run(ref, 20.0)
    assert ref.shots[-1].outcome == "time"  # 30 s and nobody kicked
    take_shot(ref, "goal")
    take_shot(ref, "wide")
    # 2:0 with one shot each left: team 2 can no longer draw level, so the shoot-out is over, as GameController3 decides
    run(ref, 2.1)
    assert ref.over and ref.winner == 1 and ref.shoot_out_score() == "2:0" and ref.score() == "0:0"
    assert [(s.team, s.striker, s.keeper, s.outcome) for s in ref.shots] == [(1, 2, 1, "goal"), (2, 2, 1, "time"), (1, 2, 1, "goal"),
                                                                             (2, 2, 1, "wide")]
    assert ref.events[-1].what == "SHOOT-OUT OVER 2:0, team 1 wins"


def test_a_level_shoot_out_goes_to_sudden_death_where_the_second_team_always_answers(shoot_out: tuple[Referee, socket.socket]) -> None:
    ref, _ = shoot_out
    ref.penalty_shots, ref.sudden_death_shots = 1, 2
    take_shot(ref, "goal")
    take_shot(ref, "goal")  # 1:1 after the regular shot each: sudden death
    take_shot(ref, "missed")
    assert not ref.over and ref.shots[-1].sudden_death
    take_shot(ref, "goal")  # the second team answers and wins
    run(ref, 2.1)
    assert ref.over and ref.winner == 2 and ref.shoot_out_score() == "1:2"


def test_in_sudden_death_the_better_ranked_shot_of_a_pair_wins_and_a_seeded_coin_decides_a_pair_still_level(
        shoot_out: tuple[Referee, socket.socket]) -> None:
    """The rules rank each sudden-death shot: goal, saved, post, wide, any other kick, no kick."""
    ref, _ = shoot_out
    ref.penalty_shots, ref.sudden_death_shots = 1, 3
    for outcome in ("goal", "goal", "post", "post", "missed", "missed"):  # 1:1, then two pairs that rank the same
        take_shot(ref, outcome)
    assert not ref.over and ref.winner is None
    take_shot(ref, "saved")
    take_shot(ref, "wide")  # saved ranks above wide: team 1 wins with the goals level
    run(ref, 2.1)
    assert ref.over and ref.winner == 1 and ref.shoot_out_score() == "1:1" and len(ref.shots) == 8
    assert ref.events[-1].what == "SHOOT-OUT OVER 1:1, team 1 wins (saved ranks above wide)"
    # level after every sudden-death shot: a coin toss, the same for the same seed, either team for some seed
    tosses = []
    for seed in (*range(8), 3):
        ref.seed = seed
        ref.shots[-2].outcome = ref.shots[-1].outcome = "time"
        ref.decide(ref.now)
        assert ref.events[-1].what.endswith("wins (a coin toss)")
        tosses.append(ref.winner)
    assert tosses[3] == tosses[-1] and set(tosses) == {1, 2}


def test_a_shoot_out_level_after_its_sudden_death_ends_with_a_coin_toss(shoot_out: tuple[Referee, socket.socket]) -> None:
    ref, _ = shoot_out
    ref.penalty_shots, ref.sudden_death_shots = 1, 1
    for outcome in ("missed", "missed", "time", "time"):
        take_shot(ref, outcome)
    run(ref, 2.1)
    assert ref.over and ref.winner in (1, 2) and ref.events[-1].what == f"SHOOT-OUT OVER 0:0, team {ref.winner} wins (a coin toss)"


def penalty_shot_playing(ref: Referee) -> tuple[float, int, int]:
    """The first shot's PLAYING: (the sign of the attacked goal's x, the striker's and the keeper's world index)."""
    until(ref, State.playing, limit=ref.now + 10.0)
    return 1.0, 1, 2  # team 1's player 2 kicks at +x, team 2's player 1 keeps


@pytest.mark.parametrize("where", ["in front of its line", "fallen"])
def test_a_keeper_off_its_line_or_fallen_before_the_kick_ends_the_shot_with_a_goal_and_a_foul(
        shoot_out: tuple[Referee, socket.socket], where: str) -> None:
    ref, _ = shoot_out
    _, _, keeper = penalty_shot_playing(ref)
    ref.world.move_robot(keeper, 4400.0, 400.0, math.pi)  # along its line: allowed
    run(ref, 1.0)
    assert ref.game.state is State.playing and ref.fouls == []
    if where == "fallen":
        ref.world.robots[keeper].place(ref.world.data, np.array([4.4, 0.4, 0.1]), np.array([1.0, 0.0, 0.0, 0.0]))
        mujoco.mj_forward(ref.world.model, ref.world.data)
    else:
        ref.world.move_robot(keeper, 3900.0, 400.0, math.pi)  # 0.6 m into the field
    run(ref, TICK)
    assert ref.game.state is State.finished and ref.shots[-1].outcome == "goal" and ref.shoot_out_score() == "1:0"
    foul = ref.fouls[-1]
    assert (foul.time_s, foul.team, foul.player, foul.penalty) == (pytest.approx(ref.now), 2, 1, Penalty.none)
    assert foul.reason == f"keeper {'fell' if where == 'fallen' else 'left its goal line'} before the penalty shot's kick: goal awarded"


def test_after_the_kick_the_keeper_may_leave_its_line_and_fall_for_long_without_a_call(shoot_out: tuple[Referee, socket.socket]) -> None:
    ref, _ = shoot_out
    _, _, keeper = penalty_shot_playing(ref)
    ref.world.move_ball(3600.0, 0.0)  # kicked, rolling slowly towards the touchline: the shot goes on
    run(ref, TICK)
    ref.world.robots[keeper].place(ref.world.data, np.array([3.9, 0.0, 0.1]), np.array([1.0, 0.0, 0.0, 0.0]))
    mujoco.mj_forward(ref.world.model, ref.world.data)
    for step in range(24):
        ref.world.move_ball(3600.0, 50.0 * step)
        run(ref, 0.5)
    assert ref.game.state is State.playing and ref.fouls == []  # 12 s down: the rules spare the keeper


@pytest.mark.parametrize("how", ["again", "dribbled"])
def test_the_striker_playing_the_ball_a_second_time_ends_the_shot(shoot_out: tuple[Referee, socket.socket], how: str) -> None:
    ref, _ = shoot_out
    _, striker, _ = penalty_shot_playing(ref)
    if how == "again":  # kicked 0.7 m, then walked after it
        ref.world.move_ball(3900.0, 0.0)
        run(ref, 1.0)
        ref.world.move_robot(striker, 3750.0, 0.0, 0.0)
    else:  # pushed along by its feet
        ref.world.move_ball(3700.0, 0.0)
        ref.world.move_robot(striker, 3550.0, 0.0, 0.0)
    run(ref, TICK)
    assert ref.game.state is State.finished and ref.shots[-1].outcome == "second touch" and ref.fouls == []
    assert ref.events[-2].what == "PENALTY SHOT 1 team 1 player 2: SECOND TOUCH"


def test_a_ball_kicked_before_the_shot_time_is_up_may_still_roll_in(shoot_out: tuple[Referee, socket.socket]) -> None:
    ref, _ = shoot_out
    penalty_shot_playing(ref)
    run(ref, 29.5)
    ref.world.move_ball(3700.0, 0.0)  # a late kick
    run(ref, 0.8)
    ref.world.move_ball(4200.0, 0.0)
    run(ref, 0.5)
    assert ref.game.state is State.playing and ref.clock == 0.0
    ref.world.move_ball(4600.0, 0.0)
    run(ref, TICK)
    assert ref.shots[-1].outcome == "goal"


@pytest.mark.parametrize("who", ["striker", "keeper"])
def test_walking_in_the_set_of_a_penalty_shot_is_motion_in_set_out_for_the_shot_and_without_its_striker_the_shot_ends(
        shoot_out: tuple[Referee, socket.socket], who: str) -> None:
    ref, _ = shoot_out
    until(ref, State.set)
    run(ref, 1.5)
    assert ref.fouls == []
    index, team, number, x = (1, 1, 2, 3100.0) if who == "striker" else (2, 2, 1, 4150.0)
    ref.world.move_robot(index, x, 0.0, 0.0)  # the striker walks up to the ball, the keeper off its line, before the whistle
    run(ref, TICK)
    foul = ref.fouls[-1]
    assert (foul.team, foul.player, foul.penalty, foul.reason) == (team, number, Penalty.illegal_motion_in_set, "walked in SET of a penalty shot")
    robot = ref.game.teams[team - 1].players[number - 1]
    assert (robot.penalty, robot.secs_till_unpenalised) == (Penalty.illegal_motion_in_set, 15)  # GameController3's 15 s
    if who == "striker":
        until(ref, State.finished)
        playing = next(e.time_s for e in ref.events if e.what == "PLAYING")
        assert ref.shots[-1].outcome == "foul" and ref.shots[-1].time_s == playing  # at PLAYING's first tick
    else:
        until(ref, State.playing)
        run(ref, 20.0)  # the 15 s do not run out within the shot: the keeper stays off and the shot goes on
        assert ref.game.state is State.playing and robot.penalty is Penalty.illegal_motion_in_set and len(ref.fouls) == 1


def test_a_striker_leaving_the_field_before_its_kick_is_penalized_and_its_shot_ends(shoot_out: tuple[Referee, socket.socket]) -> None:
    ref, _ = shoot_out
    _, striker, _ = penalty_shot_playing(ref)
    run(ref, 3.0)
    ref.world.move_robot(striker, 3000.0, 3800.0, 0.0)  # off the carpet
    run(ref, TICK)
    assert [(f.team, f.player, f.penalty) for f in ref.fouls] == [(1, 2, Penalty.leaving_the_field)]
    assert ref.shots[-1].outcome == "foul" and ref.game.state is State.finished


def test_a_called_free_kick_puts_the_ball_where_the_set_play_does_and_each_set_play_notes_how_near_the_defenders_came(
        referee: Referee) -> None:
    until(referee, State.playing)  # team 1 kicks off: team 2 is kept out of the centre circle
    referee.world.move_robot(1, 1200.0, 0.0, math.pi)
    run(referee, 1.0)
    kick_off = referee.restrictions[0]
    assert (kick_off.set_play, kick_off.kicking_team, kick_off.nearest_at_start_mm) == ("kick_off", 1, pytest.approx(2000.0, abs=5.0))
    assert kick_off.nearest_mm == pytest.approx(1200.0, abs=5.0) and kick_off.nearest_player == 1
    run(referee, 9.1)
    assert (kick_off.ended, kick_off.end_s) == ("10 s", pytest.approx(referee.events[-1].time_s + 10.0, abs=0.02))
    referee.calls = [Call(referee.now + 1.0, SetPlay.kick_in, 2)]
    run(referee, 1.05)
    assert referee.game.set_play is SetPlay.kick_in and referee.game.kicking_team == 2
    assert referee.world.ball_position() == pytest.approx((0.0, 2950.0), abs=1.0)  # on the touchline beside where it was
    kick_in = referee.restrictions[-1]
    assert (kick_in.set_play, kick_in.kicking_team, kick_in.ended) == ("kick_in", 2, "")
    assert kick_in.nearest_at_start_mm == pytest.approx(math.hypot(2000.0, 2950.0), abs=5.0)  # team 1's robot, from the ball
