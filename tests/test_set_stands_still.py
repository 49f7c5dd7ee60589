"""SET, through the mocked blackboard: the robot that walked to its place in READY stands from SET's first frame to
its last, whatever its role, the set play and what it knows (the rules' motion in SET is 15 s in place)."""

from __future__ import annotations

import pytest

from tafel.core.testing import ModuleHarness
from tafel.modules.behavior.soccer_behavior import SoccerBehavior
from tafel.representations.game import GameState, RobotInfo, SetPlay, State, TeamInfo
from tafel.representations.modeling import BallModel, RobotPose
from tafel.representations.motion_control import MotionInfo, MotionRequest, MotionType
from tafel.representations.team import PlayerRole, Role, TeamMates


def game(state: State, set_play: SetPlay, kicking_team: int) -> GameState:
    teams = [TeamInfo(team_number=1, players=[RobotInfo() for _ in range(20)]), TeamInfo(team_number=2)]
    return GameState(state=state, set_play=set_play, teams=teams, team_number=1, player_number=2, kicking_team=kicking_team)


@pytest.mark.parametrize("set_play, kicking_team, knows", [(SetPlay.none, 1, "all"), (SetPlay.none, 2, "nothing"),
                                                            (SetPlay.penalty_kick, 1, "all"), (SetPlay.penalty_kick, 2, "all")])
@pytest.mark.parametrize("role", list(Role))
def test_in_set_every_robot_stands_from_the_first_frame(role: Role, kicking_team: int, set_play: SetPlay, knows: str) -> None:
    pose = RobotPose(valid=True, x=-2500.0, y=1500.0, rotation=0.5) if knows == "all" else RobotPose()
    ball = BallModel(valid=True, seen=True, x=2000.0, y=-800.0) if knows == "all" else BallModel()
    harness = ModuleHarness(SoccerBehavior, game(State.ready, set_play, kicking_team), PlayerRole(role=role), pose, ball, TeamMates(),
                            MotionInfo(motion=MotionType.walk, executing_request=True, requested=MotionType.walk))
    harness.advance(1.0)
    assert harness[MotionRequest].motion is not MotionType.stand  # on its way in READY
    harness.set(game(State.set, set_play, kicking_team))
    for _ in range(20):  # 2 s of SET
        harness.advance(0.1)
        assert harness[MotionRequest].motion is MotionType.stand, harness.time_s
