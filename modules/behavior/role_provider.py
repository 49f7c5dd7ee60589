"""RoleProvider: who keeps the goal, who goes to the ball and who supports, agreed through team messages."""

from __future__ import annotations

import math
from dataclasses import dataclass

from tafel.core import Module, bounded, provides, requires, uses
from tafel.representations.game import GameState, Penalty, State
from tafel.representations.modeling import BallModel, RobotPose
from tafel.representations.motion_control import FallState
from tafel.representations.team import Intention, PlayerRole, Role, TeamMates


@requires(GameState, TeamMates)
@uses(BallModel, FallState, RobotPose)
@provides(PlayerRole)
class RoleProvider(Module):
    """Every robot computes the same assignment from what the team said, so exactly one field player goes
    to the ball:

    - The goalkeeper is the team's goalkeeper by the GameController (player 1 by default). A robot
      that is its team's only player on the field plays striker instead: alone by the GameController
      (every other player penalized), or, without the GameController's team, alone by the messages (a
      teammate that is fallen or quiet for a while does not take the goalkeeper out of its goal).
    - In READY and SET nobody sends (messages are spent in PLAYING only), so the field players the
      GameController has on the field take the roles by their numbers: the lowest strikes, the next
      supports, the others defend.
    - The striker is the field player with the shortest time to the ball (each robot's own estimate,
      shared in its messages). The current striker counts ``stay_bonus`` s quicker, so that the role
      does not flicker between two robots at about the same distance. A robot that does not know where
      the ball is has no time; if nobody knows, the last striker stays, or the lowest player number.
    - The next quickest is the supporter; the others defend.
    - A team of two on the field (the GameController's players not penalized, or without it, one teammate
      heard) is a goalkeeper and a striker, and nobody to pass to. So there the goalkeeper leaves its goal
      while the ball is in attack: once the ball (its own sighting, else a teammate's) is beyond
      ``keeper_out_x``, it takes part as a field player (usually the supporter, waiting ahead of the ball
      for a pass), and it goes back to its goal when the ball is behind ``keeper_back_x`` again or nobody
      knows where it is. Its teammate counts it as a field player while its messages say so and the ball
      (as the teammate knows it) is beyond ``keeper_back_x``: a keeper gone back is not waited for.

    Teammates heard within ``mate_timeout`` s that are neither penalized nor fallen take part.
    """

    game_state: GameState
    team_mates: TeamMates
    ball_model: BallModel
    fall_state: FallState
    robot_pose: RobotPose
    player_role: PlayerRole

    @dataclass
    class Parameters:
        walk_speed: float = bounded(50.0, 1000.0, 200.0)
        """mm/s the walk makes on average, for the time to the ball"""
        turn_speed: float = bounded(0.1, 5.0, 0.8)
        """rad/s"""
        stay_bonus: float = bounded(0.0, 20.0, 2.0)
        """s the current striker counts quicker"""
        mate_timeout: float = bounded(0.5, 30.0, 4.0)
        """s after a teammate's last message that it still takes part"""
        keeper_out_x: float = bounded(-4500.0, 4500.0, 0.0)
        """field mm: in a team of two on the field, the goalkeeper plays as a field player once the ball is beyond this"""
        keeper_back_x: float = bounded(-4500.0, 4500.0, -1000.0)
        """field mm: a goalkeeper playing as a field player keeps its goal again once the ball is behind this"""
        team_ball_age: float = bounded(0.0, 30.0, 3.0)
        """s: a teammate's ball older than this does not count for where the ball is"""

    parameters: Parameters

    def __init__(self) -> None:
        self.keeper_out = False
        """the goalkeeper of a team of two plays as a field player (the ball is in attack)"""

    def execute(self) -> None:
        game, out = self.game_state, self.player_role
        out.time_to_ball = self.time_to_ball()
        if game.penalized or game.state in (State.initial, State.finished):
            out.role, out.intention, self.keeper_out = Role.none, Intention.none, False
            return
        team = game.own_team()
        keeper = team.goalkeeper if team is not None and team.goalkeeper else 1
        mates = [m.message for m in self.team_mates.fresh(self.parameters.mate_timeout) if not (m.message.penalized or m.message.fallen)]
        on_field = self.on_field()
        alone = not mates if on_field is None else on_field == [game.player_number]
        pair = len(mates) == 1 if on_field is None else len(on_field) == 2
        ball_x = self.ball_x() if pair and game.state is State.playing else None
        p = self.parameters
        self.keeper_out = game.player_number == keeper and ball_x is not None and ball_x > (p.keeper_back_x if self.keeper_out else p.keeper_out_x)
        keeper_may_play = ball_x is not None and ball_x > p.keeper_back_x  # a teammate's view: its keeper may be out
        if game.player_number == keeper and not alone and not self.keeper_out:
            out.role, out.intention = Role.goalkeeper, Intention.keep_goal
            return
        if on_field is not None and game.state in (State.ready, State.set):  # nobody talks: by the numbers
            place = [n for n in on_field if n != keeper or alone].index(game.player_number)
        else:
            me = (game.player_number, out.time_to_ball, out.role is Role.striker)
            field_players = [me, *((m.player, m.time_to_ball, m.role is Role.striker) for m in mates
                                   if m.player != keeper or (keeper_may_play and m.role in (Role.striker, Role.supporter)))]
            order = sorted(field_players, key=lambda player: self.rank(*player))
            place = [player for player, _, _ in order].index(game.player_number)
        out.role = Role.striker if place == 0 else Role.supporter if place == 1 else Role.defender
        out.intention = (Intention.play_ball if self.ball_model.valid else Intention.search_ball) if place == 0 else Intention.take_position

    def on_field(self) -> list[int] | None:
        """The numbers of the team's players on the field by the GameController (this robot among them, in
        order), or None when it does not say (no team size, or this robot not in it)."""
        game, team = self.game_state, self.game_state.own_team()
        if team is None or game.players_per_team <= 0:
            return None
        numbers = [n for n, robot in enumerate(team.players[: game.players_per_team], start=1) if robot.penalty is Penalty.none]
        return numbers if game.player_number in numbers else None

    def ball_x(self) -> float | None:
        """Where the ball is along the field (mm, the opponent goal at +x): the own sighting, else a teammate's;
        None when nobody knows."""
        ball, pose = self.ball_model, self.robot_pose
        if ball.valid and pose.valid:
            return ball.field_position(pose)[0]
        heard = self.team_mates.freshest_ball(self.parameters.team_ball_age)
        return None if heard is None else heard.x

    def rank(self, player: int, time_to_ball: float, striker: bool) -> tuple[float, int, int]:
        """Sort key: time to the ball (unknown last), the striker's bonus, then the last striker, then the number."""
        seconds = time_to_ball - (self.parameters.stay_bonus if striker else 0.0) if time_to_ball >= 0 else math.inf
        return seconds, 0 if striker else 1, player

    def time_to_ball(self) -> float:
        """s this robot needs to reach the ball: walk and turn, plus the time to get up; -1 if no ball."""
        ball, p = self.ball_model, self.parameters
        if not ball.valid:
            return -1.0
        seconds = math.hypot(ball.x, ball.y) / p.walk_speed + abs(math.atan2(ball.y, ball.x)) / p.turn_speed
        return seconds + (5.0 if not self.fall_state.upright else 0.0)
