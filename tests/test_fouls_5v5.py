"""Fouls found in 10-minute 5v5 matches between two Tafel teams (issue 32), each fixed in ``SoccerBehavior`` or the
head's search and checked here through the mocked blackboard: the situation from the match, before and after."""

from __future__ import annotations

import math

from tafel.core.testing import ModuleHarness
from tafel.modules.behavior.options.soccer import FREE_KICK_DISTANCE
from tafel.modules.behavior.set_play_ball import placed_ball
from tafel.modules.behavior.soccer_behavior import SoccerBehavior
from tafel.representations import field as pitch
from tafel.representations.game import GameState, RobotInfo, SetPlay, State, TeamInfo
from tafel.representations.modeling import BallModel, RobotPose
from tafel.representations.motion_control import MotionInfo, MotionRequest, MotionType, WalkKick
from tafel.representations.obstacles import Obstacle, Obstacles
from tafel.representations.team import PlayerRole, Role, TeamMates


def playing(set_play: SetPlay = SetPlay.none, kicking_team: int = 1) -> GameState:
    team = TeamInfo(team_number=1, goalkeeper=1, players=[RobotInfo() for _ in range(20)])
    return GameState(state=State.playing, set_play=set_play, teams=[team, TeamInfo(team_number=2)], team_number=1, player_number=3,
                     kicking_team=kicking_team)


def test_at_the_opponents_goal_kick_the_team_keeps_from_where_the_rules_put_the_ball() -> None:
    """5v5 seed 2 (0764ade, 413.3 to 418.3 s): the striker chased the ball over the opponents' goal line; the referee put
    it on the corner of their goal area, 0.5 m behind the robot, which did not see it there. Its ball model still showed
    the ball where it went out, and it kept 0.75 m from that, not from the ball: illegal position at the goal kick. Now
    a ball not seen since the set play began is where the rules put it."""
    pose = RobotPose(valid=True, x=3709.0, y=-1559.0, rotation=0.3)
    out_at = (4500.0, -1520.0)  # where the ball went out, and its model still shows it
    spot = (pitch.LENGTH / 2 - pitch.GOAL_AREA_LENGTH, -pitch.GOAL_AREA_WIDTH / 2)
    assert placed_ball(SetPlay.goal_kick, out_at) == [spot]
    harness = ModuleHarness(SoccerBehavior, playing(), PlayerRole(role=Role.defender), pose,
                            BallModel(valid=True, seen=True, x=pose.to_robot(*out_at)[0], y=pose.to_robot(*out_at)[1]),
                            TeamMates(), MotionInfo(), Obstacles())
    harness.execute()
    harness.set(playing(SetPlay.goal_kick, kicking_team=2))
    for frame in range(30):
        bx, by = pose.to_robot(*out_at)
        harness.set(BallModel(valid=True, seen=False, x=bx, y=by, time_since_seen=0.1 + frame / 30))
        out = harness.execute(1)[MotionRequest]
    assert out.motion is MotionType.walk_to
    tx, ty = pose.to_field(out.target_x, out.target_y)
    # on its way out: the target leads away from the placed ball (the first step of a detour, or the spot outside)
    assert math.dist((tx, ty), spot) > math.dist((pose.x, pose.y), spot) + 50.0
    assert harness.module.set_play_ball() == spot


def test_a_ball_seen_since_the_set_play_began_is_where_it_is() -> None:
    pose = RobotPose(valid=True, x=2000.0, y=0.0)
    harness = ModuleHarness(SoccerBehavior, playing(), PlayerRole(role=Role.defender), pose, BallModel(valid=True, seen=True, x=2500.0, y=-1500.0),
                            TeamMates(), MotionInfo(), Obstacles())
    harness.execute(1)
    harness.set(playing(SetPlay.goal_kick, kicking_team=2))
    harness.execute(10)
    harness.set(BallModel(valid=True, seen=True, x=1000.0, y=-300.0, time_since_seen=0.0))
    harness.execute(1)
    assert harness.module.set_play_ball() == (3000.0, -300.0)
    assert placed_ball(SetPlay.goal_kick, (4500.0, 200.0)) == [(3900.0, 1100.0), (3900.0, -1100.0)]  # either side
    assert placed_ball(SetPlay.corner_kick, (-4600.0, 900.0)) == [(-4500.0, 3000.0)]
    assert placed_ball(SetPlay.kick_in, (1200.0, -3100.0)) == [(1200.0, -3000.0)]
    assert FREE_KICK_DISTANCE == 750.0


def test_no_keyframe_kick_while_a_robot_stands_close_behind_the_kicker() -> None:
    """5v5 seed 1 (2218338): a keyframe kick started with an opponent 340 mm behind-right of the kicker, out of its view;
    the kick's sway over the standing foot walked into it (pushing). ``keep_from_pushing`` holds back walks only. Now
    a robot within ``kick_clearance`` beside or behind the kicker allows only the walk kick, which leads away from it;
    ahead of the kicker (the ball between) or farther it does not matter."""
    pose = RobotPose(valid=True, x=1000.0, y=0.0, rotation=0.0)

    def request(*robots: tuple[float, float]) -> MotionRequest:
        obstacles = Obstacles(obstacles=[Obstacle(x, y) for x, y in robots])
        harness = ModuleHarness(SoccerBehavior, playing(), PlayerRole(role=Role.striker), pose,
                                BallModel(valid=True, seen=True, x=190.0, y=50.0), TeamMates(), MotionInfo(), obstacles)
        return harness.execute(3)[MotionRequest]

    assert request().motion is MotionType.kick  # alone: the keyframe kick, as before
    assert request((700.0, 0.0)).motion is MotionType.kick  # ahead, beyond the ball
    assert request((-300.0, -600.0)).motion is MotionType.kick  # behind, but beyond kick_clearance
    for rx, ry in ((-240.0, -240.0), (0.0, 360.0), (-440.0, 0.0)):  # behind-right (the match's), beside, behind
        out = request((rx, ry))
        assert out.motion is MotionType.walk_to, (rx, ry)
        assert out.target_x * rx + out.target_y * ry <= 0.0, (rx, ry)  # the walk leads away from it (or past it)
    assert request((-440.0, 0.0)).walk_kick is not WalkKick.none  # beyond push_distance: the walk kick, a step forward
