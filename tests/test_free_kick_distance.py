"""The opponents' free kicks when the ball is not in sight (issue 32: the simulated referee called the 0.75 m
of a kick-in), through the mocked blackboard."""

from __future__ import annotations

import math

from tafel.core.testing import ModuleHarness
from tafel.modules.behavior.soccer_behavior import SoccerBehavior
from tafel.representations.behavior import ActivationGraph
from tafel.representations.game import GameState, RobotInfo, SetPlay, State, TeamInfo
from tafel.representations.modeling import BallModel, RobotPose
from tafel.representations.motion_control import MotionInfo, MotionRequest, MotionType
from tafel.representations.team import PlayerRole, Role, TeamMates


def game(set_play: SetPlay = SetPlay.none, kicking_team: int = 1) -> GameState:
    team = TeamInfo(team_number=1, players=[RobotInfo() for _ in range(20)])
    return GameState(state=State.playing, teams=[team, TeamInfo(team_number=2)], team_number=1, player_number=2,
                     kicking_team=kicking_team, set_play=set_play)


def test_at_the_opponents_kick_in_a_striker_that_lost_the_ball_leaves_where_it_was_last_known() -> None:
    """The striker chased the ball over the touchline; the referee puts it back there for the opponents'
    kick-in while the robot does not see it. It walks away from where the ball was last known, instead of
    turning on the spot beside it (before: no ball, no distance kept, and the referee called the 0.75 m)."""
    pose = RobotPose(valid=True, x=1000.0, y=2700.0, rotation=math.pi / 2)  # facing the touchline
    ball_field = (1000.0, 3000.0)
    ball = BallModel(valid=True, seen=True, x=pose.to_robot(*ball_field)[0], y=pose.to_robot(*ball_field)[1])
    harness = ModuleHarness(SoccerBehavior, game(), PlayerRole(role=Role.striker), pose, ball, TeamMates(), MotionInfo())
    harness.execute()
    harness.set(game(SetPlay.kick_in, kicking_team=2), BallModel())  # out, placed back, not seen
    for _ in range(3):
        out = harness.execute()[MotionRequest]
    assert out.motion is MotionType.walk_to
    bx, by = pose.to_robot(*ball_field)
    assert bx * out.target_x + by * out.target_y < 0.0  # the way leads away from where the ball was
    assert ("Striker", "wait_outside") in [(o.name, o.state) for o in harness[ActivationGraph].options]
