"""SoccerBehavior through the mocked blackboard: what it asks of motion in every game state and role."""

from __future__ import annotations

import math

import pytest

from tafel.core.testing import ModuleHarness
from tafel.modules.behavior.soccer_behavior import SoccerBehavior
from tafel.representations.game import GameState, Penalty, RobotInfo, State, TeamInfo
from tafel.representations.modeling import BallModel, RobotPose
from tafel.representations.motion_control import MotionInfo, MotionRequest, MotionType
from tafel.representations.team import PlayerRole, Role, TeamMate, TeamMates, TeamMessage


def game(state: State, *, penalty: Penalty = Penalty.none, kicking_team: int = 2) -> GameState:
    team = TeamInfo(team_number=1, players=[RobotInfo() for _ in range(20)])
    team.players[1].penalty = penalty
    return GameState(state=state, teams=[team, TeamInfo(team_number=2)], team_number=1, player_number=2, kicking_team=kicking_team)


def request(state: State, role: Role = Role.striker, *, pose: RobotPose | None = None, ball: BallModel | None = None,
            mates: TeamMates | None = None, **options: object) -> MotionRequest:
    harness = ModuleHarness(SoccerBehavior, game(state, **options), PlayerRole(role=role), pose or RobotPose(valid=True, x=-3000.0, y=0.0),
                            ball or BallModel(), mates or TeamMates(), MotionInfo())
    return harness.execute()[MotionRequest]


@pytest.mark.parametrize("state", [State.initial, State.standby, State.set])
def test_it_stands_before_play(state: State) -> None:
    assert request(state, ball=BallModel(valid=True, x=500.0)).motion is MotionType.stand


def test_it_sits_when_the_game_is_finished_and_stands_still_while_penalized() -> None:
    assert request(State.finished).motion is MotionType.sit
    assert request(State.playing, ball=BallModel(valid=True, x=500.0), penalty=Penalty.player_pushing).motion is MotionType.stand


@pytest.mark.parametrize("role, kicking_team, position", [
    (Role.goalkeeper, 2, (-4200.0, 0.0)), (Role.striker, 2, (-1000.0, 0.0)), (Role.striker, 1, (-300.0, 0.0)),
    (Role.supporter, 1, (-1500.0, -1300.0)), (Role.defender, 1, (-2800.0, 1000.0)),
])
def test_in_ready_each_role_walks_to_its_kickoff_position(role: Role, kicking_team: int, position: tuple[float, float]) -> None:
    pose = RobotPose(valid=True, x=-3000.0, y=2500.0, rotation=math.pi / 2)
    out = request(State.ready, role, pose=pose, kicking_team=kicking_team)
    assert out.motion is MotionType.walk_to
    assert pose.to_field(out.target_x, out.target_y) == pytest.approx(position, abs=1e-6)
    assert math.remainder(pose.rotation + out.target_rotation, math.tau) == pytest.approx(0.0, abs=1e-9)  # facing the opponent goal


def test_in_ready_it_stands_once_there_and_looks_around_without_a_pose() -> None:
    assert request(State.ready, pose=RobotPose(valid=True, x=-1000.0, y=30.0)).motion is MotionType.stand
    lost = request(State.ready, pose=RobotPose(valid=False))
    assert lost.motion is MotionType.walk and lost.walk_x == 0.0 and lost.walk_rotation > 0


def test_the_striker_goes_for_the_ball_and_searches_by_turning_without_one() -> None:
    out = request(State.playing, ball=BallModel(valid=True, x=1500.0, y=0.0))
    assert out.motion is MotionType.walk_to and 1000.0 < out.target_x < 1500.0
    assert request(State.playing, ball=BallModel(valid=True, x=190.0, y=-50.0)).motion is MotionType.kick
    search = request(State.playing)
    assert search.motion is MotionType.walk and search.walk_rotation > 0


def test_without_its_own_sighting_the_striker_goes_by_a_teammates_ball() -> None:
    said = TeamMessage(team=1, player=3, pose_valid=True, ball_seen=True, ball_x=500.0, ball_y=1000.0, ball_age=0.5)
    out = request(State.playing, pose=RobotPose(valid=True, x=-2000.0, y=0.0), mates=TeamMates(mates=[TeamMate(said, age=0.4)]))
    assert out.motion is MotionType.walk_to and (out.target_x, out.target_y) == pytest.approx((2500.0, 1000.0))
    stale = TeamMates(mates=[TeamMate(said, age=5.0)])
    assert request(State.playing, pose=RobotPose(valid=True, x=-2000.0), mates=stale).motion is MotionType.walk  # too old: search


def test_the_goalkeeper_stays_between_ball_and_goal_and_clears_a_near_ball_in_its_area() -> None:
    pose = RobotPose(valid=True, x=-4200.0, y=0.0)
    far = request(State.playing, Role.goalkeeper, pose=pose, ball=BallModel(valid=True, x=5000.0, y=1000.0))
    x, y = pose.to_field(far.target_x, far.target_y)
    assert far.motion is MotionType.walk_to and x == pytest.approx(-4200.0) and 0.0 < y <= 500.0
    near = request(State.playing, Role.goalkeeper, pose=pose, ball=BallModel(valid=True, x=600.0, y=0.0))
    assert near.motion is MotionType.walk_to and near.target_x > 300.0  # goes for it


def test_supporters_and_defenders_keep_their_distance_from_the_ball() -> None:
    pose = RobotPose(valid=True, x=-1000.0, y=0.0)
    ball = BallModel(valid=True, x=2000.0, y=1500.0)  # on the field: (1000, 1500)
    for role in (Role.supporter, Role.defender):
        out = request(State.playing, role, pose=pose, ball=ball)
        x, y = pose.to_field(out.target_x, out.target_y)
        assert out.motion is MotionType.walk_to and math.hypot(x - 1000.0, y - 1500.0) > 1000.0 and x < 1000.0, role
