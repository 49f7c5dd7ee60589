"""Where SoccerBehavior knows the ball to be when nobody of the team sees it: a teammate's ball (``team_ball``), and
at the opponents' set play (noted by ``note_set_play``), where the rules put it (``placed_ball``) until it is seen
again (``set_play_balls``).
Field mm, the own goal at -x."""

from __future__ import annotations

import math
from typing import Protocol

from tafel.representations import field as pitch
from tafel.representations.game import GameState, SetPlay
from tafel.representations.infrastructure import FrameInfo
from tafel.representations.modeling import BallModel, RobotPose
from tafel.representations.team import TeamMates

OPPONENT_PENALTY_MARK_X = pitch.LENGTH / 2 - pitch.PENALTY_MARK_DISTANCE
#: mm from the field's centre line a ball that went out over a goal line counts as on one side: nearer, the rules'
#: corner of either side may hold it (both are kept away from)
SIDE_UNSURE = 500.0


class SetPlayBallParameters(Protocol):
    """What these functions read of SoccerBehavior.Parameters."""

    team_ball_age: float


class NotedSetPlay(Protocol):
    """The opponents' set play SoccerBehavior noted (``note_set_play``), and the clock and ball it went by."""

    frame_info: FrameInfo
    set_play: tuple[SetPlay, int] | None
    set_play_s: float
    set_play_spots: list[tuple[float, float]]
    last_ball: tuple[float, float] | None


class SetPlayNoter(NotedSetPlay, Protocol):
    """What ``note_set_play`` reads of SoccerBehavior beside what it notes."""

    game_state: GameState

    def opponents_set_play(self) -> bool: ...


class SetPlayWatcher(NotedSetPlay, Protocol):
    """What ``set_play_balls`` reads of SoccerBehavior: the representations and the set play it noted."""

    ball_model: BallModel
    robot_pose: RobotPose
    team_mates: TeamMates

    @property
    def parameters(self) -> SetPlayBallParameters: ...

    def ball_on_field(self) -> tuple[float, float] | None: ...


def placed_ball(set_play: SetPlay, last: tuple[float, float] | None) -> list[tuple[float, float]]:
    """Where the rules put the ball at the opponents' ``set_play`` (field mm, the own goal at -x), the ball last
    known at ``last`` (where it went out): a goal kick on the corner of their goal area, a corner kick in the own
    field corner, each on the side it went out (both corners while that is unsure), a kick-in on the touchline beside
    where it went out, a penalty kick on the own penalty mark, a pushing free kick where the ball is. Empty when
    that cannot be told (no ball known)."""
    if set_play is SetPlay.penalty_kick:
        return [(-OPPONENT_PENALTY_MARK_X, 0.0)]
    if last is None:
        return []
    x, y = last
    sides = [math.copysign(1.0, y)] if abs(y) > SIDE_UNSURE else [1.0, -1.0]
    if set_play is SetPlay.goal_kick:
        return [(pitch.LENGTH / 2 - pitch.GOAL_AREA_LENGTH, side * pitch.GOAL_AREA_WIDTH / 2) for side in sides]
    if set_play is SetPlay.corner_kick:
        return [(-pitch.LENGTH / 2, side * pitch.WIDTH / 2) for side in sides]
    if set_play is SetPlay.kick_in:
        return [(max(-pitch.LENGTH / 2, min(pitch.LENGTH / 2, x)), math.copysign(pitch.WIDTH / 2, y))]
    return [last]


def note_set_play(b: SetPlayNoter) -> None:
    """An opponents' set play that begins: when, and where the rules put the ball (``placed_ball``), from where
    it was last known (before this frame: where it went out)."""
    game = b.game_state
    now = (game.set_play, game.kicking_team) if b.opponents_set_play() else None
    if now != b.set_play:
        b.set_play, b.set_play_s = now, b.frame_info.time_s
        b.set_play_spots = placed_ball(game.set_play, b.last_ball) if now is not None else []


def team_balls(team_mates: TeamMates) -> list[tuple[float, tuple[float, float]]]:
    """(s since seen, field mm) of every ball a teammate with a valid pose said it saw, in the order heard."""
    return [(m.age + m.message.ball_age, (m.message.ball_x, m.message.ball_y)) for m in team_mates.mates
            if m.message.ball_seen and m.message.pose_valid and 0.0 <= m.message.ball_age]


def team_ball(team_mates: TeamMates, max_age: float) -> tuple[float, float] | None:
    """The freshest ball a teammate with a valid pose saw (field mm), if seen at most ``max_age`` s ago."""
    heard = [ball for ball in team_balls(team_mates) if ball[0] <= max_age]
    return min(heard, key=lambda ball: ball[0])[1] if heard else None


def set_play_balls(b: SetPlayWatcher) -> list[tuple[float, float]]:
    """Where the ball of the opponents' set play is (field mm), to keep away from: the own sighting or a
    teammate's, if made since the set play began; else where the rules put it (``set_play_spots``: a ball that
    went out is put back by the referee, often beside the robot that chased it there, which may not see it
    then, and its model still shows it where it went out); else where it was last known."""
    ball, since = b.ball_model, b.frame_info.time_s - b.set_play_s
    if b.set_play is None:
        known = b.ball_on_field()
        return [known] if known is not None else []
    if ball.valid and ball.time_since_seen < since and b.robot_pose.valid:
        return [ball.field_position(b.robot_pose)]
    heard = [seen for seen in team_balls(b.team_mates) if seen[0] < min(since, b.parameters.team_ball_age)]
    if heard:
        return [min(heard, key=lambda seen: seen[0])[1]]
    if b.set_play_spots:
        return list(b.set_play_spots)
    return [b.last_ball] if b.last_ball is not None else []
