"""Team messages: the format (checked against a layout written here, not the code under test), the
teammates heard, pacing within the GameController's message budget, and roles agreed through them."""

from __future__ import annotations

import math
import struct

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tafel.core.testing import ModuleHarness
from tafel.modules.behavior.role_provider import RoleProvider
from tafel.modules.communication.game_state_provider import GameStateProvider
from tafel.modules.communication.team_mates_provider import TeamMatesProvider
from tafel.modules.communication.team_message_codec import TeamMessageError, pack_message, unpack_message
from tafel.modules.communication.team_message_sender import TeamMessageSender, send_interval
from tafel.representations.game import Datagram, GameControllerPackets, GameState, RobotInfo, State, TeamInfo
from tafel.representations.modeling import BallModel, RobotPose
from tafel.representations.team import (
    MAX_MESSAGE_BYTES,
    IncomingTeamMessages,
    Intention,
    OutgoingTeamMessage,
    PlayerRole,
    Role,
    TeamMate,
    TeamMates,
    TeamMessage,
)

# the layout of the README's table: header, version, team, player, flags, role, intention, sent (ms),
# x, y, rotation (1e-4 rad), ball x, y, ball age (10 ms), time to ball (10 ms), ball velocity x, y
LAYOUT = struct.Struct("<2sBBBBBBIhhhhhHHhh")


def test_a_message_is_thirty_bytes_laid_out_as_documented() -> None:
    message = TeamMessage(team=7, player=4, sent_ms=123456, pose_valid=True, ball_seen=True, x=-2500.0, y=1200.0, rotation=-1.5,
                          ball_x=300.0, ball_y=-800.0, ball_vx=-150.0, ball_vy=20.0, ball_age=0.37, role=Role.supporter,
                          intention=Intention.take_position, time_to_ball=6.5)
    data = pack_message(message)
    assert len(data) == LAYOUT.size == 30 <= MAX_MESSAGE_BYTES
    assert LAYOUT.unpack(data) == (b"TF", 1, 7, 4, 1 | 4, 3, 3, 123456, -2500, 1200, -15000, 300, -800, 37, 650, -150, 20)


@given(x=st.floats(-6000, 6000), y=st.floats(-4000, 4000), rotation=st.floats(-math.pi, math.pi), age=st.floats(0, 600),
       player=st.integers(1, 20), team=st.integers(1, 254), flags=st.integers(0, 15), role=st.sampled_from(Role),
       intention=st.sampled_from(Intention), time_to_ball=st.floats(0, 600), sent=st.integers(0, 2**32 - 1))
def test_every_field_survives_a_round_trip_within_its_resolution(x: float, y: float, rotation: float, age: float, player: int, team: int,
                                                                 flags: int, role: Role, intention: Intention, time_to_ball: float,
                                                                 sent: int) -> None:
    message = TeamMessage(team=team, player=player, sent_ms=sent, pose_valid=bool(flags & 1), fallen=bool(flags & 2),
                          ball_seen=bool(flags & 4), penalized=bool(flags & 8), x=x, y=y, rotation=rotation, ball_x=-y, ball_y=x,
                          ball_age=age, role=role, intention=intention, time_to_ball=time_to_ball)
    back = unpack_message(pack_message(message))
    assert (back.team, back.player, back.sent_ms, back.role, back.intention) == (team, player, sent, role, intention)
    assert (back.pose_valid, back.fallen, back.ball_seen, back.penalized) == (message.pose_valid, message.fallen, message.ball_seen,
                                                                              message.penalized)
    assert abs(back.x - x) <= 0.5 and abs(back.y - y) <= 0.5 and abs(back.ball_x + y) <= 0.5 and abs(back.ball_y - x) <= 0.5
    assert abs(math.remainder(back.rotation - rotation, math.tau)) <= 1e-4
    # half the 0.01 s resolution, and the float error of scaling by 100 (0.125 s rounds to 0.12 s)
    assert abs(back.ball_age - age) <= 0.005 + 1e-9 and abs(back.time_to_ball - time_to_ball) <= 0.005 + 1e-9


def test_values_beyond_a_field_are_clamped_and_unknown_times_stay_unknown() -> None:
    back = unpack_message(pack_message(TeamMessage(team=1, player=2, x=1e9, y=-math.inf, ball_x=math.nan, ball_age=-1.0, time_to_ball=1e9)))
    assert (back.x, back.y, back.ball_x, back.ball_age) == (32767.0, 0.0, 0.0, -1.0)
    assert back.time_to_ball == pytest.approx(655.34)


@pytest.mark.parametrize("data, complaint", [
    (b"", "0 bytes"), (b"XX" + bytes(28), "starting b'XX"), (pack_message(TeamMessage(team=1, player=2))[:-1], "29 bytes"),
    (b"TF\x02" + bytes(27), "version 1"), (LAYOUT.pack(b"TF", 1, 1, 0, 0, 0, 0, 0, *[0] * 9), "player number 0"),
    (LAYOUT.pack(b"TF", 1, 1, 2, 0, 9, 0, 0, *[0] * 9), "role 9"), (LAYOUT.pack(b"TF", 1, 1, 2, 64, 0, 0, 0, *[0] * 9), "flags 0x40"),
])
def test_bytes_that_are_not_a_message_say_what_is_wrong(data: bytes, complaint: str) -> None:
    with pytest.raises(TeamMessageError, match=complaint.replace("(", r"\(")):
        unpack_message(data)


# --------------------------------------------------------------------------- TeamMatesProvider
def datagram(data: bytes, at_ns: int) -> Datagram:
    return Datagram(data=data, host="10.0.1.3", port=10001, received_ns=at_ns)


def test_teammates_are_kept_by_player_with_their_age_and_bad_or_foreign_messages_are_counted() -> None:
    game = GameState(team_number=1, player_number=2)
    mate = pack_message(TeamMessage(team=1, player=4, x=100.0, role=Role.striker))
    own = pack_message(TeamMessage(team=1, player=2))
    foreign = pack_message(TeamMessage(team=9, player=4))
    harness = ModuleHarness(TeamMatesProvider, game, IncomingTeamMessages(datagrams=[datagram(mate, 0), datagram(own, 0),
                                                                                   datagram(foreign, 0), datagram(b"junk", 0)]))
    mates = harness.execute()[TeamMates]
    assert [m.message.player for m in mates.mates] == [4] and mates.received == 1 and mates.malformed == 2
    harness.set(IncomingTeamMessages())
    harness.advance(3.0)
    assert mates.mates[0].age == pytest.approx(3.0, abs=0.04) and mates.fresh(2.0) == [] and mates.mates[0].message.role is Role.striker
    harness.advance(7.5)
    assert harness.blackboard[TeamMates].mates == []  # forgotten after 10 s


# ----------------------------------------------------------------------------- pacing the budget
def playing_game(budget: int, players: int, remaining_s: float, first_half: bool, player: int) -> GameState:
    team = TeamInfo(team_number=1, message_budget=budget, players=[RobotInfo() for _ in range(20)])
    return GameState(heard=True, state=State.playing, players_per_team=players, secs_remaining=int(remaining_s), first_half=first_half,
                     teams=[team, TeamInfo(team_number=2, players=[RobotInfo() for _ in range(20)])], team_number=1, player_number=player)


@settings(max_examples=12, deadline=None)
@given(budget=st.integers(30, 1500), players=st.integers(1, 7), remaining=st.integers(60, 600), first_half=st.booleans())
def test_a_team_pacing_itself_never_exceeds_the_budget_and_keeps_sending_to_the_end(budget: int, players: int, remaining: int,
                                                                                     first_half: bool) -> None:
    """Every robot of a team runs TeamMessageSender; a GameController counts the budget down as they send
    and the clock down as the game goes (0.25 s frames: pacing depends on time, not on the frame rate)."""
    step = 0.25
    robots = [ModuleHarness(TeamMessageSender, playing_game(budget, players, remaining, first_half, n + 1), PlayerRole(),
                            RobotPose(), BallModel(), rate_hz=1 / step) for n in range(players)]
    left, clock, total = budget, float(remaining) + (600.0 if first_half else 0.0), 0
    last_message_at = 0.0
    while clock > 0:
        half_clock = clock - 600.0 if first_half and clock > 600.0 else clock
        for robot in robots:
            game = robot.blackboard[GameState]
            game.own_team().message_budget, game.secs_remaining = left, int(half_clock)
            game.first_half = first_half and clock > 600.0
            if robot.execute()[OutgoingTeamMessage].data:
                left, total, last_message_at = left - 1, total + 1, clock
        clock -= step
    assert total <= budget, f"sent {total} of a budget of {budget}"
    # With n messages each beyond the reserve, evenly spread, the last comes about 1/n of the game before the
    # end: with ten or more each it lies in the last 15 % (with two each it could not).
    if budget - 20 >= 10 * players:
        assert last_message_at <= 0.15 * (remaining + (600 if first_half else 0)) + 2 * players * step + 1.0


def test_the_interval_is_each_players_share_of_the_budget_over_the_time_left() -> None:
    assert send_interval(budget=1200, players=5, remaining_s=1200.0, reserve=0, min_interval=0.5) == pytest.approx(5.0)
    assert send_interval(budget=100, players=2, remaining_s=10.0, reserve=20, min_interval=1.0) == 1.0
    assert send_interval(budget=20, players=2, remaining_s=100.0, reserve=20, min_interval=1.0) == math.inf


def test_a_shorter_game_spends_its_budget_over_its_own_halves() -> None:
    """A practice game of 60-s halves, 60 s left in the first: with ``half_s`` 60 a robot of five takes its
    share of the 1200 messages over the 120 s of play left (the 1 s floor), not over the 660 s that the
    SPL's halves would leave."""
    sent = {}
    for half_s in (600.0, 60.0):
        harness = ModuleHarness(TeamMessageSender, playing_game(1200, 5, 60, True, 2), PlayerRole(), RobotPose(), BallModel(),
                                parameters={"half_s": half_s})
        harness.execute(300)  # 10 s; the interval is 5 * (60 + half_s) / 1180 s, at least 1 s
        sent[half_s] = sum(bool(m.data) for m in harness.history(OutgoingTeamMessage))
    assert sent[600.0] == 4  # every 2.8 s: at 0, 2.8, 5.6 and 8.4 s
    assert sent[60.0] == 10  # the 1 s floor: 0.5 s would be the share


def test_nothing_is_sent_outside_playing_and_without_a_game_controller_at_the_fallback_rate() -> None:
    game = playing_game(1200, 5, 600, True, 2)
    game.state = State.ready
    harness = ModuleHarness(TeamMessageSender, game, PlayerRole(), parameters={"interval_without_game_controller": 2.0})
    harness.execute(90)
    assert not any(m.data for m in harness.history(OutgoingTeamMessage))
    game = GameState(heard=False, state=State.playing, team_number=1, player_number=2)
    harness.set(game)
    harness.execute(181)  # 6 s
    assert sum(bool(m.data) for m in harness.history(OutgoingTeamMessage)) == 4  # at 0, 2, 4, 6 s
    assert unpack_message(harness.history(OutgoingTeamMessage)[-1].data).player == 2


@pytest.mark.slow
def test_the_budget_holds_over_a_game_in_which_one_robot_stops_hearing_the_game_controller() -> None:
    """Five robots, each GameStateProvider fed the GameController's packets (built from the published
    layout) every 0.5 s, each TeamMessageSender paced by what its provider makes of them; the
    GameController counts every message against the team's 1200. Player 3 goes deaf two minutes into
    the game and stays in PLAYING: it goes on pacing on the last budget it heard, still talking."""
    from tests.test_game_controller import packet

    step, half_s, budget, deaf_from_s = 0.5, 600.0, 1200, 120.0
    robots = [(ModuleHarness(GameStateProvider, rate_hz=1 / step),
               ModuleHarness(TeamMessageSender, PlayerRole(), RobotPose(), BallModel(), rate_hz=1 / step, parameters={"half_s": half_s}))
              for _ in range(5)]
    sent = [0] * 5
    for frame in range(int(2 * half_s / step)):
        now = frame * step
        first_half = now < half_s
        remaining = int(math.ceil((half_s if first_half else 2 * half_s) - now))
        data = packet(players=5, state=3, set_play=0, first_half=int(first_half), kicking=255, remaining=remaining, secondary=0,
                      teams=((1, 0, 1, 1, 0, 0, 0, max(0, budget - sum(sent))), (2, 1, 3, 1, 0, 0, 0, 1200)))
        for n, (provider, sender) in enumerate(robots):
            hears = not (n == 2 and now >= deaf_from_s)
            datagrams = [Datagram(data=data, host="10.0.0.1", received_ns=int(now * 1e9))] if hears else []
            game = provider.set(GameControllerPackets(datagrams=datagrams, team_number=1, player_number=n + 1)).execute()[GameState]
            sent[n] += bool(sender.set(game).execute()[OutgoingTeamMessage].data)
    assert not robots[2][0].blackboard[GameState].heard and robots[2][0].blackboard[GameState].state is State.playing
    assert sum(sent) <= budget, sent
    assert sent[2] > 30 + 100, sent  # about 30 before it went deaf, and it kept talking afterwards


# ------------------------------------------------------------------------------------- roles
def mate(player: int, time_to_ball: float, role: Role = Role.none, *, penalized: bool = False, age: float = 0.5) -> TeamMate:
    return TeamMate(message=TeamMessage(team=1, player=player, time_to_ball=time_to_ball, role=role, penalized=penalized), age=age)


def role_of(player: int, ball_mm: float | None, mates: list[TeamMate], *, keeper: int = 1, current: Role = Role.none) -> Role:
    team = TeamInfo(team_number=1, goalkeeper=keeper, players=[RobotInfo() for _ in range(20)])
    game = GameState(state=State.playing, teams=[team], team_number=1, player_number=player)
    ball = BallModel(valid=ball_mm is not None, x=ball_mm or 0.0)
    harness = ModuleHarness(RoleProvider, game, TeamMates(mates=mates), ball, PlayerRole(role=current))
    return harness.execute()[PlayerRole].role


@settings(max_examples=60)
@given(distances=st.lists(st.one_of(st.none(), st.floats(100.0, 9000.0)), min_size=2, max_size=5), striker=st.integers(0, 5))
def test_exactly_one_field_player_goes_to_the_ball_and_player_one_keeps_goal(distances: list[float | None], striker: int) -> None:
    """Each robot decides from what the others said (their time to the ball and role): all agree."""
    players = list(range(1, len(distances) + 1))
    times = {p: -1.0 if d is None else d / 200.0 for p, d in zip(players, distances)}  # the RoleProvider's own estimate for a ball ahead
    roles = {p: Role.striker if p == striker else Role.none for p in players}
    decided = {}
    for p, d in zip(players, distances):
        mates = [mate(q, times[q], roles[q]) for q in players if q != p]
        decided[p] = role_of(p, d, mates, current=roles[p])
    assert decided[1] is Role.goalkeeper
    assert sum(r is Role.striker for r in decided.values()) == 1, decided


def test_a_lone_goalkeeper_plays_striker_and_penalized_or_old_teammates_do_not_count() -> None:
    assert role_of(1, 2000.0, []) is Role.striker
    assert role_of(1, 2000.0, [mate(2, 50.0, penalized=True), mate(3, 1.0, age=10.0)]) is Role.striker
    assert role_of(2, 2000.0, [mate(3, 50.0)]) is Role.striker
    assert role_of(2, 2000.0, [mate(3, 5.0), mate(4, 50.0)]) is Role.supporter
    assert role_of(4, 2000.0, [mate(3, 5.0), mate(2, 6.0)]) is Role.defender


def test_the_striker_keeps_its_role_against_a_teammate_only_a_little_nearer() -> None:
    assert role_of(2, 2000.0, [mate(3, 9.5)], current=Role.striker) is Role.striker  # 10 s against 9.5 s: stays
    assert role_of(2, 2000.0, [mate(3, 5.0)], current=Role.striker) is Role.supporter  # much nearer: takes over
