"""TeamMessageSender: tells the team where this robot is, where the ball is and what it is doing,
paced so that the team's message budget lasts the game."""

from __future__ import annotations

import math
from dataclasses import dataclass

from tafel.core import Module, bounded, provides, requires, uses
from tafel.modules.communication.game_controller_codec import SEND_SLACK_S
from tafel.modules.communication.team_message_codec import pack_message
from tafel.representations.game import GamePhase, GameState, Penalty, State
from tafel.representations.infrastructure import FrameInfo
from tafel.representations.modeling import BallModel, RobotPose
from tafel.representations.motion_control import FallState
from tafel.representations.team import OutgoingTeamMessage, PlayerRole, TeamMessage


def send_interval(budget: int, players: int, remaining_s: float, reserve: int, min_interval: float) -> float:
    """s between one robot's messages so that ``players`` robots sending alike spend at most
    ``budget - reserve`` messages in ``remaining_s``: each robot gets its share, spread evenly; inf
    when nothing may be sent."""
    usable = budget - reserve
    if usable <= 0:
        return math.inf
    return max(min_interval, max(1, players) * max(remaining_s, 0.0) / usable)


def remaining_game_s(game: GameState, half_s: float) -> float:
    """s of playing time left in the game: this half, and a second half of ``half_s`` while in the first."""
    rest = max(0.0, float(game.secs_remaining))
    return rest + half_s if game.first_half and game.game_phase is GamePhase.normal else rest


@requires(GameState, PlayerRole, FrameInfo)
@uses(RobotPose, BallModel, FallState)
@provides(OutgoingTeamMessage)
class TeamMessageSender(Module):
    """Sends while PLAYING. With a GameController, the interval is this robot's share of the team's
    ``messageBudget`` over the playing time left (``send_interval``): the players on the field (not
    substitutes) share it, and ``reserve`` messages are kept back for the end.

    When the GameController goes quiet (``heard`` false after it was heard), the pacing goes on from
    the last budget heard, as B-Human's and HULKs' do: each message this robot sends meanwhile counts
    as one from every player (they share alike), and the time left stays what was last heard, so the
    interval only grows and the team never spends more than its budget. A robot that never heard one
    (the rules' manual mode) sends every ``interval_without_game_controller`` s."""

    game_state: GameState
    player_role: PlayerRole
    frame_info: FrameInfo
    robot_pose: RobotPose
    ball_model: BallModel
    fall_state: FallState
    outgoing_team_message: OutgoingTeamMessage

    @dataclass
    class Parameters:
        reserve: int = bounded(0, 1000, 20)
        """messages of the budget never spent"""
        min_interval: float = bounded(0.1, 60.0, 1.0)
        """s: never more often than this"""
        interval_without_game_controller: float = bounded(0.1, 60.0, 2.0)
        half_s: float = bounded(1.0, 3600.0, 600.0)
        """s of one half: the SPL's 600; practice games with shorter halves set theirs (tafel match does)"""

    parameters: Parameters

    def __init__(self) -> None:
        self.last_sent_s = -math.inf
        self.ball_seen_s: float | None = None
        self.last_heard: tuple[int, int, float] | None = None  # budget, players, playing s left: the last pacing heard
        self.sent_since_heard = 0  # messages sent since the GameController was last heard

    def execute(self) -> None:
        game, out, now = self.game_state, self.outgoing_team_message, self.frame_info.time_s
        ball = self.ball_model
        if ball.valid:
            self.ball_seen_s = now - ball.time_since_seen
        out.data = b""
        if game.state is not State.playing:
            return
        interval = self.interval(game)
        if now - self.last_sent_s < interval - SEND_SLACK_S:
            return
        self.last_sent_s = now
        self.sent_since_heard += 1
        out.data = pack_message(self.message(game, now))
        out.sent += 1

    def interval(self, game: GameState) -> float:
        """s between this robot's messages: its share of the budget heard, or of the last one heard."""
        p, team = self.parameters, game.own_team()
        if game.heard and team is not None and not game.manual:
            players = sum(1 for robot in team.players[: max(1, game.players_per_team)] if robot.penalty is not Penalty.substitute)
            self.last_heard, self.sent_since_heard = (team.message_budget, players, remaining_game_s(game, p.half_s)), 0
        if self.last_heard is None:
            return p.interval_without_game_controller
        budget, players, remaining_s = self.last_heard
        return send_interval(budget - max(1, players) * self.sent_since_heard, players, remaining_s, p.reserve, p.min_interval)

    def message(self, game: GameState, now: float) -> TeamMessage:
        pose, ball, role = self.robot_pose, self.ball_model, self.player_role
        ball_x, ball_y = ball.field_position(pose)
        ball_vx, ball_vy = pose.as_pose2d().rotated(ball.vx, ball.vy)
        return TeamMessage(team=game.team_number, player=game.player_number, sent_ms=int(now * 1000), pose_valid=pose.valid,
                           fallen=not self.fall_state.upright, penalized=game.penalized, x=pose.x, y=pose.y, rotation=pose.rotation,
                           ball_seen=ball.valid, ball_x=ball_x, ball_y=ball_y, ball_vx=ball_vx, ball_vy=ball_vy,
                           ball_age=-1.0 if self.ball_seen_s is None else now - self.ball_seen_s,
                           role=role.role, intention=role.intention, time_to_ball=role.time_to_ball)
