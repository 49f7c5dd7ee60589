"""The SPL rules a referee checks, each through the modules that must keep it (``ModuleHarness``, with the
GameController's packets built from its published layout) and, where the issue asks, with physics."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from tafel.core.framework.manager import Blackboard
from tafel.core.testing import ModuleHarness
from tafel.modules.behavior.look_at_ball_behavior import LookAtBallBehavior
from tafel.modules.behavior.soccer_behavior import SoccerBehavior
from tafel.modules.communication.game_state_provider import GameStateProvider
from tafel.modules.motion.head_motion import HeadMotion
from tafel.modules.motion.status_leds import StatusLeds
from tafel.platforms.network import GameNetwork, NetworkSettings
from tafel.representations.behavior import HeadMotionRequest
from tafel.representations.game import (
    Datagram,
    GameControllerPackets,
    GameControllerReturn,
    GamePhase,
    GameState,
    Penalty,
    RobotInfo,
    State,
    TeamInfo,
)
from tafel.representations.infrastructure import CognitionStatus, FrameInfo
from tafel.representations.modeling import BallModel, RobotPose
from tafel.representations.motion import HEAD_PITCH, HEAD_YAW, HeadJointTargets, JointSensorData, LedRequest
from tafel.representations.motion_control import MotionInfo, MotionRequest, MotionType
from tafel.representations.team import OutgoingTeamMessage, PlayerRole, Role, TeamMates
from tests.support.simulation import Simulation
from tests.test_game_controller import packet  # built from the published layout, never from the code under test


def game(state: State = State.playing, *, penalty: Penalty = Penalty.none) -> GameState:
    """This robot (team 1, player 2) in ``state``, with ``penalty``."""
    team = TeamInfo(team_number=1, players=[RobotInfo() for _ in range(20)])
    team.players[1].penalty = penalty
    return GameState(state=state, teams=[team, TeamInfo(team_number=2, players=[RobotInfo() for _ in range(20)])],
                     team_number=1, player_number=2, heard=True)


# ------------------------------------------------------------------------------ penalized means still
def test_a_penalized_robot_asks_for_no_head_motion_whatever_the_ball_does_until_unpenalized() -> None:
    harness = ModuleHarness(LookAtBallBehavior, game(), BallModel(valid=True, seen=True, x=2000.0, y=0.0), RobotPose(valid=True))
    harness.execute(10)
    harness.set(game(penalty=Penalty.player_pushing))
    held = []
    for k in range(300):  # 10 s: the ball rolls round the robot, then is lost (the head would search)
        angle = 0.01 * k
        ball = BallModel(valid=k < 150, seen=k < 150, x=2000.0 * math.cos(angle), y=2000.0 * math.sin(angle))
        request = harness.set(ball).execute()[HeadMotionRequest]
        held.append((request.yaw, request.pitch, request.max_speed))
    assert all(speed == 0.0 for _, _, speed in held)
    assert len({(yaw, pitch) for yaw, pitch, _ in held}) == 1
    harness.set(game(), BallModel(valid=True, seen=True, x=0.0, y=2000.0))
    assert harness.execute(3)[HeadMotionRequest].max_speed > 0.0  # unpenalized: it looks again


def test_head_motion_holds_the_head_where_it_is_at_a_request_of_speed_zero() -> None:
    sensors = JointSensorData()
    sensors.position[HEAD_YAW], sensors.position[HEAD_PITCH] = 0.4, 0.1
    harness = ModuleHarness(HeadMotion, sensors, HeadMotionRequest(yaw=-1.5, pitch=0.3, max_speed=0.0))
    targets = [(t.yaw, t.pitch) for t in (harness.execute()[HeadJointTargets] for _ in range(100))]
    assert targets == [(0.4, 0.1)] * 100


@pytest.mark.slow
def test_with_physics_a_penalized_robot_holds_every_joint_still_until_the_chest_button_unpenalizes_it() -> None:
    sim = Simulation("mujoco", scene="default", cameras="off", sensor_noise="0")
    button = sim.platform.commands()["sim:button"][1]
    move_ball = sim.platform.commands()["sim:move_ball"][1]
    try:
        sim.run(3.0)  # playing: walking to the ball
        button({})  # manual mode: penalized
        sim.run(2.0)  # the walk stops and the robot stands
        assert sim.blackboard("cognition")[GameState].penalized
        move_ball({"x": "-2500", "y": "-1500", "vx": "0", "vy": "1200"})  # the ball rolls across in front of it
        joints: list[np.ndarray] = []
        sim.run(5.0, lambda s: joints.append(s.platform.joint_angles()))
        spread = np.ptp(np.array(joints), axis=0)
        assert spread[HEAD_YAW] < 0.01 and spread.max() < 0.03, spread.round(3)
        button({})  # unpenalized: it looks for the ball again
        head: list[float] = []
        sim.run(3.0, lambda s: head.append(float(s.platform.joint_angles()[HEAD_YAW])))
        assert np.ptp(head) > 0.1
    finally:
        sim.close()


# ------------------------------------------------------------------------------- the chest LED
#: the rules' colours (R, G, B) of the chest in each state (the GameController's numbers)
RULES_CHEST = {0: (0, 0, 0), 5: (0, 1, 1), 1: (0, 0, 1), 2: (1, 1, 0), 3: (0, 1, 0), 4: (0, 0, 0)}


def heard(data: bytes) -> GameState:
    """What GameStateProvider makes of one packet for team 12, player 3."""
    received = GameControllerPackets(datagrams=[Datagram(data=data, host="10.0.0.1", received_ns=0)], team_number=12, player_number=3)
    return ModuleHarness(GameStateProvider, received).execute()[GameState]


@pytest.mark.parametrize("state", sorted(RULES_CHEST))
@pytest.mark.parametrize("alive", [True, False])
def test_the_chest_shows_the_game_state_in_the_rules_colours_whether_or_not_cognition_runs(state: int, alive: bool) -> None:
    game = heard(packet(state=state))
    chest = ModuleHarness(StatusLeds, game, CognitionStatus(alive=alive)).execute()[LedRequest].chest
    assert tuple(chest) == RULES_CHEST[state]


@pytest.mark.parametrize("state", sorted(RULES_CHEST))
def test_the_chest_is_red_while_penalized_in_any_state(state: int) -> None:
    game = heard(packet(state=state, penalties={(0, 2): (2, 40)}))  # team 12's player 3: pushing, 40 s
    assert game.penalized
    assert tuple(ModuleHarness(StatusLeds, game, CognitionStatus(alive=True)).execute()[LedRequest].chest) == (1, 0, 0)


@pytest.mark.slow
def test_in_the_program_the_chest_follows_the_manual_mode_initial_penalized_playing() -> None:
    sim = Simulation("mujoco", scene="default", cameras="off", overrides=["parameters.GameStateProvider.start_state=\"initial\""])
    button = sim.platform.commands()["sim:button"][1]
    try:
        chests = []
        for _ in range(3):
            sim.run(0.5)
            chests.append(tuple(sim.blackboard("motion")[LedRequest].chest))
            button({})
        assert chests == [(0, 0, 0), (1, 0, 0), (0, 1, 0)]  # INITIAL off, PLAYING penalized red, PLAYING green
    finally:
        sim.close()


# ------------------------------------------------------------------------------- return packets
class CountingNetwork(GameNetwork):
    """The platform's network with the socket left out: what it would send, and when (ns)."""

    def __init__(self) -> None:
        super().__init__(NetworkSettings(team_number=1, player_number=2))
        self.game_controller = object()  # type: ignore[assignment]  # anything: transmit below never uses it
        self.sent_at: list[int] = []
        self.now_ns = 0

    def transmit(self, sock: object, data: bytes, address: tuple[str, int]) -> bool:
        self.sent_at.append(self.now_ns)
        return True


@given(st.lists(st.integers(1, 700_000_000), min_size=1, max_size=60))
def test_the_platform_lets_at_most_two_return_packets_leave_in_any_second_and_refuses_no_more_than_that(gaps: list[int]) -> None:
    network, board = CountingNetwork(), Blackboard()
    for rep in (GameControllerReturn, OutgoingTeamMessage, FrameInfo):
        board.ensure(rep)
    board.set(GameControllerReturn(data=b"x" * 32, host="127.0.0.1"))
    refused_at = []
    for now in itertools.accumulate(gaps):
        network.now_ns = now
        board.set(FrameInfo(time_ns=now))
        before = len(network.sent_at)
        network.send(board)
        if len(network.sent_at) == before:
            refused_at.append(now)
    sent = network.sent_at
    assert all(later - earlier >= 1_000_000_000 for earlier, later in zip(sent, sent[2:]))  # never three within a second
    for now in refused_at:  # and each refusal was needed: two had left within the second before
        assert sum(now - 1_000_000_000 < t <= now for t in sent) == 2
    assert (network.returns_sent, network.returns_refused) == (len(sent), len(refused_at))


# ------------------------------------------------------------------------------- penalty shoot-out
@pytest.mark.parametrize("penalty", [Penalty.none, Penalty.substitute])
def test_between_penalty_shots_the_robots_stand_for_the_referee_to_place_them_and_sit_only_when_a_half_ends(penalty: Penalty) -> None:
    """GameController3 ends each penalty shot with FINISHED; the referee then places the next shot's robots,
    which must be on their feet for it (a sitting robot put down falls over)."""
    motions = {}
    for phase in (GamePhase.penalty_shoot, GamePhase.normal):
        finished = game(State.finished, penalty=penalty)
        finished.game_phase = phase
        harness = ModuleHarness(SoccerBehavior, finished, PlayerRole(role=Role.striker), RobotPose(valid=True, x=2900.0),
                                BallModel(valid=True, seen=True, x=300.0), TeamMates(), MotionInfo())
        motions[phase] = harness.execute(3)[MotionRequest].motion
    assert motions == {GamePhase.penalty_shoot: MotionType.stand, GamePhase.normal: MotionType.sit}
