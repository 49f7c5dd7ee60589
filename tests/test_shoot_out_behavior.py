"""The penalty shoot-out's striker (``ShootOut`` in ``modules/behavior/options/soccer.py``) through the mocked
blackboard: a shot is one touch, so after its kick the striker stands, wherever the ball goes."""

from __future__ import annotations

import pytest

from tafel.core.testing import ModuleHarness
from tafel.modules.behavior.options.soccer import SHOT_SETTLE_S
from tafel.modules.behavior.soccer_behavior import SoccerBehavior
from tafel.representations.behavior import ActivationGraph
from tafel.representations.game import GamePhase, GameState, RobotInfo, State, TeamInfo
from tafel.representations.modeling import BallModel, RobotPose
from tafel.representations.motion_control import MotionInfo, MotionRequest, MotionType
from tafel.representations.team import PlayerRole, Role, TeamMates

#: the striker on the edge of the penalty area, the ball on the penalty mark 0.35 m ahead of it
POSE, MARK = RobotPose(valid=True, x=2850.0, y=0.0), BallModel(valid=True, seen=True, x=350.0, y=0.0)


def shoot_out_playing() -> GameState:
    """A penalty shot's PLAYING: team 1 (this robot's, player 2) kicks."""
    teams = [TeamInfo(team_number=1, players=[RobotInfo() for _ in range(20)]), TeamInfo(team_number=2)]
    return GameState(state=State.playing, game_phase=GamePhase.penalty_shoot, teams=teams, team_number=1, player_number=2,
                     kicking_team=1)


def shoot_out_state(harness: ModuleHarness) -> str:
    return next(o.state for o in harness[ActivationGraph].options if o.name == "ShootOut")


def kick(harness: ModuleHarness, ball_after: BallModel) -> None:
    """The striker walks up to the ball and its kick plays for 0.8 s; the ball is then at ``ball_after``."""
    harness.advance(0.5)
    assert harness[MotionRequest].motion is MotionType.walk_to
    harness.set(MotionInfo(motion=MotionType.kick, busy=True, executing_request=True, requested=MotionType.kick))
    harness.advance(0.8)
    harness.set(MotionInfo(), ball_after)


@pytest.mark.parametrize("ball_after", [BallModel(valid=True, seen=True, x=700.0, y=100.0),  # a slow shot that stopped
                                        BallModel(valid=True, seen=True, x=3000.0, y=-300.0),  # on its way
                                        BallModel()])  # out of sight
def test_after_its_kick_the_shoot_out_striker_stands_and_plays_the_ball_no_more(ball_after: BallModel) -> None:
    harness = ModuleHarness(SoccerBehavior, shoot_out_playing(), PlayerRole(role=Role.striker), POSE, MARK, TeamMates(), MotionInfo())
    kick(harness, ball_after)
    for _ in range(int(10.0 / 0.5)):  # the shot goes on until the referee ends it: the striker stands all the while
        harness.advance(0.5)
        assert harness[MotionRequest].motion is MotionType.stand, (harness.time_s, shoot_out_state(harness))
    assert shoot_out_state(harness) == "kicked"


def test_a_kick_that_missed_the_ball_is_taken_again() -> None:
    harness = ModuleHarness(SoccerBehavior, shoot_out_playing(), PlayerRole(role=Role.striker), POSE, MARK, TeamMates(), MotionInfo())
    at_the_feet = BallModel(valid=True, seen=True, x=190.0, y=-50.0)  # the foot swung past it: it did not go
    kick(harness, at_the_feet)
    harness.advance(SHOT_SETTLE_S - 0.1)
    assert harness[MotionRequest].motion is MotionType.stand
    harness.advance(0.2)
    assert shoot_out_state(harness) == "shoot" and harness[MotionRequest].motion is not MotionType.stand


def test_a_mirrored_pose_does_not_turn_the_shot_round_the_striker_kicks_where_it_was_placed_facing() -> None:
    """The localization took the mirror image after the referee placed the robot (seen in a cameras-on shoot-out):
    the pose says the robot stands in its own half facing its own goal. The rules placed it facing the ball and
    the goal, so it walks up behind the ball and kicks ahead, at a corner, not round the ball and through it."""
    mirrored = RobotPose(valid=True, x=-POSE.x, y=0.0, rotation=3.13)
    for pose in (POSE, mirrored, RobotPose()):
        harness = ModuleHarness(SoccerBehavior, shoot_out_playing(), PlayerRole(role=Role.striker), pose, MARK, TeamMates(), MotionInfo())
        out = harness.execute()[MotionRequest]
        assert out.motion is MotionType.walk_to and out.target_x < MARK.x - 100.0, (pose, out)  # behind the ball
        assert 0.1 < abs(out.target_rotation) < 0.5, (pose, out)  # at a corner of the goal ahead
