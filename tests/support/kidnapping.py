"""Kidnappings anywhere on the field, judged against simulator ground truth: for the slow end-to-end
test (``tests/test_localization.py``) and ``benchmarks/localization.py``.

The standing program with both cameras and the team's messages runs on a simulator. A teammate
(player 3, which only talks) reports once a second, through the simulated network, the ball where it
truly is, give or take 100 mm. The robot is carried to a random pose anywhere on the field, facing
anywhere, without telling the localization (``move_robot``, as a referee or a bad get-up does), and the
ball is put at a random place 0.5 to 4 m from it (today's detection range). The robot looks and turns
for the ball as the striker does (``SEARCH_TURN`` while its ball is not valid).
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass

import numpy as np

from tafel.modules.behavior.ball_search import SearchTurn
from tafel.modules.communication.team_message_codec import pack_message
from tafel.representations.modeling import BallModel, RobotPose
from tafel.representations.motion_control import MotionRequest, MotionType
from tafel.representations.perception import BallPercept
from tafel.representations.team import Role, TeamMates, TeamMessage
from tests.support.simulation import PERCEPTION, Simulation

WINDOW_S = 12.0  # s judged after each kidnapping
TEAMMATE = (0.0, -2800.0, math.pi / 2)  # where the talking teammate stands
SEARCH_TURN = 0.6  # rad/s: the striker's turn while it has no ball (SoccerBehavior.search_turn)
#: the standing program with the GameController's state and the teammates heard
WITH_TEAM = ["cognition.modules=" + json.dumps([*PERCEPTION, "LookAtBallBehavior", "GameStateProvider", "TeamMatesProvider",
                                                "tests.support.motion_requests:ConstantMotionRequest"])]


@dataclass
class Kidnapping:
    """How one kidnapping went: ``recovered_s`` until the pose was valid and within 200 mm and 10 degrees
    (None: not within the window); ``ended_mirrored`` when in the window's last second a valid pose was the
    twin (within 500 mm and 30 degrees of the truth turned about the centre spot); ``mirrored_valid_s``
    how long a valid pose was the twin; ``settled_s`` until the estimate, valid or not, was within 200 mm
    and 10 degrees of the truth or of its twin (the field's part), ``ball_seen_s`` until the ball was
    first seen (what the team's ball needs); None: not within the window."""

    pose: tuple[float, float, float]
    ball: tuple[float, float]
    recovered_s: float | None
    ended_mirrored: bool
    mirrored_valid_s: float
    settled_s: float | None = None
    ball_seen_s: float | None = None


def random_kidnap(rng: np.random.Generator) -> tuple[tuple[float, float, float], tuple[float, float]]:
    """A pose anywhere on the field, facing anywhere, and a ball on the field 0.5 to 4 m from it."""
    pose = (rng.uniform(-4300.0, 4300.0), rng.uniform(-2800.0, 2800.0), rng.uniform(-math.pi, math.pi))
    while True:
        ball = (rng.uniform(-4300.0, 4300.0), rng.uniform(-2800.0, 2800.0))
        if 500.0 <= math.hypot(ball[0] - pose[0], ball[1] - pose[1]) <= 4000.0:
            return pose, ball


def teammate_message(ball: tuple[float, float], time_s: float, rng: np.random.Generator) -> bytes:
    """What a teammate that sees the ball says: the ball where it is, give or take 100 mm."""
    return pack_message(TeamMessage(team=1, player=3, sent_ms=int(time_s * 1000), pose_valid=True, x=TEAMMATE[0], y=TEAMMATE[1],
                                    rotation=TEAMMATE[2], ball_seen=True, ball_x=ball[0] + rng.normal(0.0, 100.0),
                                    ball_y=ball[1] + rng.normal(0.0, 100.0), ball_age=0.2, role=Role.supporter))


class KidnapRun:
    """One seeded run: the program started at (-1500, 0) facing the opponent goal, then ``kidnap()`` as
    often as wanted. ``frame_ms`` collects the cognition frames' times."""

    def __init__(self, engine: str, seed: int) -> None:
        self.rng = np.random.default_rng(1000 + seed)
        self.sim = Simulation(engine, WITH_TEAM, start="-1500,0,0", ball="4000,2500")
        self.request = MotionRequest(motion=MotionType.stand)
        motion = self.sim.blackboard("motion")
        self.sim.runtime.runners["motion"].manager.before_frame.append(lambda: motion.set(self.request))
        self.heard_at = -math.inf
        self.search = SearchTurn()
        self.sim.run(5.0, self.tick)

    def tick(self, sim: Simulation) -> None:
        if sim.time >= self.heard_at + 1.0:  # the teammate's message, once a second
            self.heard_at = sim.time
            sim.platform.network.echo.append(teammate_message(sim.platform.ball_position(), sim.time, self.rng))
        cognition = sim.blackboard("cognition")
        ball = cognition[BallModel]
        if ball.valid:
            self.search.found()
            self.request = MotionRequest(motion=MotionType.stand)
            return
        side = self.search.direction(ball, cognition[RobotPose], cognition[TeamMates].freshest_ball(3.0))
        self.request = MotionRequest(motion=MotionType.walk, walk_rotation=side * SEARCH_TURN)

    def kidnap(self, to: tuple[tuple[float, float, float], tuple[float, float]] | None = None) -> Kidnapping:
        """Carry the robot to a random pose (or ``to``: pose and ball), the ball near it, and judge the
        next ``WINDOW_S`` s."""
        sim = self.sim
        pose, ball = to or random_kidnap(self.rng)
        sim.platform.move_robot(*pose)
        sim.platform.move_ball(*ball)
        moved, recovered, ended_mirrored, mirrored_valid_s = sim.time, None, False, 0.0
        settled = ball_seen = None
        while sim.time < moved + WINDOW_S - 1e-6:
            sim.run(0.1, self.tick)
            believed = sim.blackboard("cognition")[RobotPose]
            x, y, heading = sim.platform.robot_pose()
            right = (math.hypot(believed.x - x, believed.y - y) < 200.0
                     and abs(math.remainder(believed.rotation - heading, math.tau)) < math.radians(10.0))
            mirrored = (math.hypot(believed.x + x, believed.y + y) < 500.0
                        and abs(math.remainder(believed.rotation - heading - math.pi, math.tau)) < math.radians(30.0))
            if believed.valid and right and recovered is None:
                recovered = round(sim.time - moved, 2)
            twin_right = (math.hypot(believed.x + x, believed.y + y) < 200.0
                          and abs(math.remainder(believed.rotation - heading - math.pi, math.tau)) < math.radians(10.0))
            if settled is None and (right or twin_right):
                settled = round(sim.time - moved, 2)
            if ball_seen is None and sim.blackboard("cognition")[BallPercept].seen:
                ball_seen = round(sim.time - moved, 2)
            if believed.valid and mirrored:
                mirrored_valid_s += 0.1
                ended_mirrored |= sim.time > moved + WINDOW_S - 1.0
        return Kidnapping(pose, ball, recovered, ended_mirrored, round(mirrored_valid_s, 1), settled, ball_seen)

    def close(self) -> None:
        self.sim.close()
