"""Striker: find the ball, walk behind it, kick it towards the opponent goal, follow it, repeat."""

from __future__ import annotations

from dataclasses import dataclass

from tafel.core import Module, bounded, provides, requires, uses
from tafel.debug import Canvas, DebugRequest
from tafel.modules.behavior.ball_search import SearchTurn
from tafel.modules.behavior.kicking import KickParameters, approach_and_kick, goal_direction, kick_tuning
from tafel.representations.infrastructure import FrameInfo
from tafel.representations.modeling import BallModel, RobotPose
from tafel.representations.motion_control import MotionInfo, MotionRequest, MotionType, Odometry, WalkKick
from tafel.representations.team import TeamMates


@requires(BallModel, Odometry, MotionInfo, FrameInfo)
@uses(RobotPose, TeamMates)
@provides(MotionRequest)
class Striker(Module):
    """The striker alone, without game states or team: ``SoccerBehavior`` plays the game and uses the
    same kicking (``kicking.approach_and_kick``). The kick goes from the ball to the opponent goal's
    centre, through ``RobotPose``, from anywhere on the field; while the pose is not valid, the way the
    robot faced at the start, by odometry.

    - No ball: turn on the spot (the head searches meanwhile), towards where the ball probably is
      (``ball_search.SearchTurn``: the team's ball while the pose is valid, else the last seen ball, else
      the way it turned last).
    - Ball: walk to the point ``behind`` mm behind it on the line of the kick, the kicking foot in line
      with the ball, facing the kick direction.
    - There, with the ball in front of the foot: kick, and wait for the kick to end.

    With ``walk_kick`` (the default here) the kick is the walk's long kick: the robot walks to the ball
    ``walk_kick_distance`` ahead of the kicking foot and kicks without stopping (``kicking.walk_kick_approach``);
    ``walk_kick = false`` keeps the keyframe kick.
    """

    ball_model: BallModel
    odometry: Odometry
    motion_info: MotionInfo
    frame_info: FrameInfo
    robot_pose: RobotPose
    team_mates: TeamMates
    motion_request: MotionRequest

    draw_target = DebugRequest("where the striker wants to stand, on the robot canvas")
    kick_tuning = kick_tuning()

    @dataclass
    class Parameters(KickParameters):
        search_turn: float = bounded(0.0, 2.0, 0.6)
        """rad/s while the ball is lost"""
        team_ball_age: float = bounded(0.0, 30.0, 3.0)
        """s: a teammate's ball reported this recently tells which way to turn"""
        walk_kick: bool = True
        """kick out of the walk; false: the keyframe kick from standing"""

    parameters: Parameters

    def __init__(self) -> None:
        self.search = SearchTurn()

    def execute(self) -> None:
        p, ball, out = self.parameters, self.ball_model, self.motion_request
        if self.motion_info.busy:  # a kick or get-up plays to its end
            return
        out.walk_kick = WalkKick.none  # a walk kick is asked for only in the frames that mean it
        if not ball.valid:
            side = self.search.direction(ball, self.robot_pose, self.team_mates.freshest_ball(p.team_ball_age))
            out.motion, out.walk_x, out.walk_y, out.walk_rotation = MotionType.walk, 0.0, 0.0, side * p.search_turn
            return
        self.search.found()
        target_x, target_y, direction = approach_and_kick(ball, goal_direction(ball, self.robot_pose, self.odometry),
                                                        self.kick_tuning.apply(p), out)
        if self.draw_target:
            self.draw_target.canvas(Canvas.ROBOT).robot_pose(target_x, target_y, direction, color="orange")
