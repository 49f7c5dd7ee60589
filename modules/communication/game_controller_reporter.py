"""GameControllerReporter: the return packet that tells the GameController how this robot is."""

from __future__ import annotations

import math
from dataclasses import dataclass

from tafel.core import Module, bounded, provides, requires, uses
from tafel.modules.communication.game_controller_codec import SEND_SLACK_S, ReturnPacket, encode_return
from tafel.representations.game import GameControllerReturn, GameState
from tafel.representations.infrastructure import FrameInfo
from tafel.representations.modeling import BallModel, RobotPose
from tafel.representations.motion_control import FallState


@requires(GameState, FrameInfo)
@uses(RobotPose, BallModel, FallState)
@provides(GameControllerReturn)
class GameControllerReporter(Module):
    """Every ``interval`` s, while a GameController is heard, a ``RoboCupGameControlReturnData`` for its
    address: player and team, whether the robot has fallen, its pose, and the ball (age, and position
    relative to the robot). The rules allow two a second; the platform refuses more."""

    game_state: GameState
    frame_info: FrameInfo
    robot_pose: RobotPose
    ball_model: BallModel
    fall_state: FallState
    game_controller_return: GameControllerReturn

    @dataclass
    class Parameters:
        interval: float = bounded(0.5, 10.0, 1.0)
        """s between return packets"""

    parameters: Parameters

    def __init__(self) -> None:
        self.last_sent_s = -math.inf
        self.ball_seen_s: float | None = None

    def execute(self) -> None:
        game, out, ball, now = self.game_state, self.game_controller_return, self.ball_model, self.frame_info.time_s
        if ball.valid:
            self.ball_seen_s = now - ball.time_since_seen
        out.data, out.host = b"", ""
        if not game.heard or not game.source or now - self.last_sent_s < self.parameters.interval - SEND_SLACK_S:
            return
        pose = self.robot_pose
        packet = ReturnPacket(player=game.player_number, team=game.team_number, fallen=not self.fall_state.upright,
                              x=pose.x, y=pose.y, rotation=pose.rotation,
                              ball_age=-1.0 if self.ball_seen_s is None else now - self.ball_seen_s,
                              ball_x=ball.x if ball.valid else 0.0, ball_y=ball.y if ball.valid else 0.0)
        out.data, out.host = encode_return(packet), game.source
        self.last_sent_s = now
