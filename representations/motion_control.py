"""What cognition asks of motion, what motion reports back, and what the motion engines hand over.

Cognition writes one ``MotionRequest``; motion decides what runs (``MotionSelection``), each engine
computes its joint targets, and the combinator blends them into the one ``JointCommand``. Motion
reports back in ``MotionInfo`` (what runs), ``Odometry`` (how far the walk carried the robot) and
``FallState``. Getting up is never requested: it follows a fall by itself.
"""

from __future__ import annotations

import enum
import math

import numpy as np

from tafel.core import array, bounded, representation
from tafel.representations.geometry import Pose2D
from tafel.representations.motion import JOINT_COUNT


class MotionType(enum.Enum):
    """What motion does. ``getup`` and ``fall`` are motion's own choices, never requested."""

    stand = 0
    walk = 1
    walk_to = 2
    kick = 3
    sit = 4
    getup = 5
    fall = 6


class Foot(enum.Enum):
    left = 0
    right = 1


class WalkKick(enum.Enum):
    """A kick out of the walk (``MotionRequest.walk_kick``): ``short`` passes or dribbles, ``long`` shoots."""

    none = 0
    short = 1
    long = 2


@representation
class MotionRequest:
    """The motion cognition wants (behaviour writes it every frame).

    - ``stand``; ``sit`` (safe, then limp);
    - ``walk`` at ``walk_x``, ``walk_y`` (mm/s) and ``walk_rotation`` (rad/s), clipped to the walk's limits;
    - ``walk_to`` the pose ``target_x``, ``target_y`` (mm) and ``target_rotation`` (rad) relative to the
      robot, decelerating on arrival;
    - ``kick`` with ``kick_foot`` towards ``kick_direction`` (rad, robot frame; 0 is straight ahead): the
      keyframe kick, from standing;
    - ``walk``/``walk_to`` with ``walk_kick`` (short or long): the next step of ``kick_foot`` kicks towards
      ``kick_direction`` without stopping (the walk's kick, up to its ``max_direction`` either side).
    """

    motion: MotionType = MotionType.stand
    walk_x: float = bounded(-1000.0, 1000.0)
    walk_y: float = bounded(-1000.0, 1000.0)
    walk_rotation: float = bounded(-10.0, 10.0)
    target_x: float = bounded(-20000.0, 20000.0)
    target_y: float = bounded(-20000.0, 20000.0)
    target_rotation: float = bounded(-math.pi, math.pi)
    kick_foot: Foot = Foot.left
    kick_direction: float = bounded(-math.pi, math.pi)
    walk_kick: WalkKick = WalkKick.none

    def status_text(self) -> str:
        kick = f", {self.walk_kick.name} kick {self.kick_foot.name}" if self.walk_kick is not WalkKick.none else ""
        if self.motion is MotionType.walk:
            return f"request walk {self.walk_x:.0f},{self.walk_y:.0f} mm/s {self.walk_rotation:.2f} rad/s{kick}"
        if self.motion is MotionType.walk_to:
            return f"request walk_to {self.target_x:.0f},{self.target_y:.0f} mm {self.target_rotation:.2f} rad{kick}"
        if self.motion is MotionType.kick:
            return f"request kick {self.kick_foot.name}"
        return f"request {self.motion.name}"


@representation
class MotionSelection:
    """Which motion runs and with what share of the joint commands while one blends into the next."""

    active: MotionType = MotionType.stand
    #: share (0..1) of each motion in this frame's joint command, by MotionType value; they add up to 1
    weights: np.ndarray = bounded(0.0, 1.0, array_shape=(len(MotionType),))
    #: the motion the request asks for
    requested: MotionType = MotionType.stand
    #: why another motion runs than the one asked for ("" when the request runs), e.g. "getting up first"
    waiting_for: str = ""


@representation
class MotionInfo:
    """What motion does: the running motion, whether that carries out the request, the walk's phase."""

    motion: MotionType = MotionType.stand
    #: True once the requested motion runs (False while motion finishes another, or gets up)
    executing_request: bool = False
    support_foot: Foot = Foot.left
    #: 0..1 through the current step (0 when not walking)
    step_phase: float = bounded(0.0, 1.0)
    #: a kick or get-up in progress (behaviour waits for it)
    busy: bool = False
    #: the motion the request asks for
    requested: MotionType = MotionType.stand
    #: why the request does not run yet ("" when it runs), from ``MotionSelection``
    waiting_for: str = ""

    def status_text(self) -> str:
        """``motion stand``, or what was asked and why it waits: ``motion stand (asked walk: getting up first)``."""
        if self.executing_request:
            return f"motion {self.motion.name}"
        return f"motion {self.motion.name} (asked {self.requested.name}: {self.waiting_for or 'blending into it'})"


@representation
class Odometry:
    """The robot's pose change since the program started, accumulated from the walk's own foot
    placements and the torso's yaw rate: x, y (mm) and rotation (rad) in the frame the robot had at the
    start. Ground truth is never used. Differences of two readings give the motion between them
    (``now.as_pose2d().relative_to(before.as_pose2d())``)."""

    x: float = 0.0
    y: float = 0.0
    rotation: float = 0.0

    def as_pose2d(self) -> Pose2D:
        """The robot's pose in the odometry frame, to compute with."""
        return Pose2D(self.x, self.y, self.rotation)


class FallPhase(enum.Enum):
    upright = 0
    staggering = 1
    falling = 2
    lying_front = 3
    lying_back = 4
    lying_side = 5
    getting_up = 6


class FallDirection(enum.Enum):
    none = 0
    front = 1
    back = 2
    left = 3
    right = 4


@representation
class FallState:
    """Whether the robot stands, staggers, falls (and which way), lies (on which side) or gets up."""

    phase: FallPhase = FallPhase.upright
    direction: FallDirection = FallDirection.none
    #: s in the current phase
    duration: float = bounded(0.0, 1e6)

    @property
    def upright(self) -> bool:
        return self.phase in (FallPhase.upright, FallPhase.staggering)

    @property
    def lying(self) -> bool:
        return self.phase in (FallPhase.lying_front, FallPhase.lying_back, FallPhase.lying_side)


@representation
class WalkingEngineOutput:
    """The walk's joint targets (rad) and stiffness (0..1), with where it stands in its step cycle."""

    position: np.ndarray = array((JOINT_COUNT,))
    stiffness: np.ndarray = bounded(0.0, 1.0, array_shape=(JOINT_COUNT,))
    #: the walk is at a standstill, in the stand pose: another motion may take over without a jerk
    standing: bool = True
    support_foot: Foot = Foot.left
    step_phase: float = bounded(0.0, 1.0)
    #: the walk_to target is reached (within its tolerances)
    target_reached: bool = False
    #: the current step is a kick (``MotionRequest.walk_kick``)
    kicking: bool = False
    #: walk kicks made since the start
    kicks: int = 0


@representation
class KeyframeOutput:
    """The keyframe player's joint targets and which motion it plays."""

    position: np.ndarray = array((JOINT_COUNT,))
    stiffness: np.ndarray = bounded(0.0, 1.0, array_shape=(JOINT_COUNT,))
    #: name of the motion file being played ("" when idle)
    motion: str = ""
    #: s into the motion
    time: float = bounded(0.0, 1e6)
    #: the motion has played to its end, or was aborted
    done: bool = True
    #: the motion stopped early: the torso was tilted more than a keyframe's ``abort_if_tilted`` allows
    aborted: bool = False
