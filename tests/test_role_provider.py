"""RoleProvider in a team of two on the field: the goalkeeper leaves its goal to support while the ball is in
attack, and its teammate counts it as a field player meanwhile."""

from __future__ import annotations

from tafel.core.testing import ModuleHarness
from tafel.modules.behavior.role_provider import RoleProvider
from tafel.representations.game import GameState, Penalty, RobotInfo, State, TeamInfo
from tafel.representations.modeling import BallModel, RobotPose
from tafel.representations.team import PlayerRole, Role, TeamMate, TeamMates, TeamMessage

KEEPER_POSE = RobotPose(valid=True, x=-4200.0, y=0.0)  # on its goal line, facing the opponent goal


def game(player: int, on_field: int, state: State = State.playing) -> GameState:
    team = TeamInfo(team_number=1, goalkeeper=1, players=[RobotInfo() for _ in range(5)])
    for robot in team.players[on_field:]:
        robot.penalty = Penalty.substitute
    return GameState(state=state, teams=[team], team_number=1, player_number=player, players_per_team=5)


def said(player: int, time_to_ball: float, role: Role, ball_x: float | None = None) -> TeamMate:
    message = TeamMessage(team=1, player=player, pose_valid=True, time_to_ball=time_to_ball, role=role,
                          ball_seen=ball_x is not None, ball_x=ball_x or 0.0, ball_age=0.2)
    return TeamMate(message=message, age=0.3)


def keeper(on_field: int = 2, state: State = State.playing) -> ModuleHarness:
    mates = TeamMates(mates=[said(n, 3.0, Role.striker if n == 2 else Role.defender) for n in range(2, on_field + 1)])
    return ModuleHarness(RoleProvider, game(1, on_field, state), mates, KEEPER_POSE, BallModel(), PlayerRole(role=Role.goalkeeper))


def role_with_ball_at(harness: ModuleHarness, field_x: float) -> Role:
    """The keeper's role with its own sighting of the ball at ``field_x`` (mm, on the long axis)."""
    return harness.set(BallModel(valid=True, seen=True, x=field_x - KEEPER_POSE.x)).execute()[PlayerRole].role


def test_the_keeper_of_a_pair_supports_while_the_ball_is_in_attack_and_goes_back_when_it_returns() -> None:
    harness = keeper()
    assert role_with_ball_at(harness, 0.0) is Role.goalkeeper  # not far enough
    assert role_with_ball_at(harness, 1500.0) is Role.supporter  # the striker is quicker to the ball
    assert role_with_ball_at(harness, -500.0) is Role.supporter  # hysteresis: not yet behind keeper_back_x
    assert role_with_ball_at(harness, -1500.0) is Role.goalkeeper
    assert role_with_ball_at(harness, 0.0) is Role.goalkeeper  # and in again only beyond keeper_out_x


def test_with_more_players_or_before_playing_the_keeper_keeps_its_goal() -> None:
    assert role_with_ball_at(keeper(on_field=3), 2500.0) is Role.goalkeeper
    assert role_with_ball_at(keeper(state=State.ready), 2500.0) is Role.goalkeeper


def test_by_a_teammates_ball_the_keeper_goes_out_and_without_any_ball_it_goes_back() -> None:
    harness = keeper()
    harness.set(TeamMates(mates=[said(2, 3.0, Role.striker, ball_x=2000.0)]))
    assert harness.execute()[PlayerRole].role is Role.supporter
    harness.set(TeamMates(mates=[said(2, 3.0, Role.striker)]))
    assert harness.execute()[PlayerRole].role is Role.goalkeeper


def test_the_teammate_counts_the_keeper_as_a_field_player_while_it_says_it_is_out_and_the_ball_is_in_attack() -> None:
    def role_of_player_two(keeper_role: Role, ball_x: float) -> Role:
        harness = ModuleHarness(RoleProvider, game(2, 2), TeamMates(mates=[said(1, 2.0, keeper_role)]), RobotPose(valid=True),
                                BallModel(valid=True, x=ball_x), PlayerRole())  # 15 s away: the keeper is quicker
        return harness.execute()[PlayerRole].role

    assert role_of_player_two(Role.goalkeeper, 3000.0) is Role.striker
    assert role_of_player_two(Role.striker, 3000.0) is Role.supporter
    assert role_of_player_two(Role.striker, -3000.0) is Role.striker  # the ball is back: the keeper is too, whatever it said last


def test_the_keeper_of_a_pair_comes_out_as_soon_as_the_ball_is_in_the_opponent_half() -> None:
    """Issue 36: out only 0.5 m into the opponent half, the keeper came too late to be passed to in the midfield."""
    harness = keeper()
    assert role_with_ball_at(harness, -200.0) is Role.goalkeeper
    assert role_with_ball_at(harness, 300.0) is Role.supporter
