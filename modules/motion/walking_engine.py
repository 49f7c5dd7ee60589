"""WalkingEngine: an omnidirectional walk in the family of rUNSWift's Walk2014.

No dynamics model: each step moves the swing foot from where it is to half a step ahead along a smooth
curve, lifted in the middle, while the support foot slides back linearly; the legs follow through the
analytic inverse kinematics. The torso sways over the support foot, the gyroscope damps the ankles, and
the support foot changes when the foot pressure says the swing foot has landed (or a step has taken
too long). Odometry is the support foot's motion and the gyroscope's yaw rate, so it needs no ground
truth. A request with a ``walk_kick`` makes the next step of the kicking foot a kick (``walk_kicks``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from tafel.core import Module, bounded, provides, requires
from tafel.debug import Canvas, DebugRequest, ModifyParameters, Plot
from tafel.modules.motion.inverse_kinematics import apply_leg_angles, leg_angles, pose, rot_x, rot_y
from tafel.modules.motion.stand_motion import stand_pose
from tafel.modules.motion.walk_kicks import KickStep, kick_swing, load_walk_kicks
from tafel.representations.geometry import Pose2D
from tafel.representations.infrastructure import FrameInfo
from tafel.representations.motion import JOINT_COUNT, JOINT_INDEX, FsrData, InertialSensorData
from tafel.representations.motion_control import (
    Foot,
    MotionRequest,
    MotionSelection,
    MotionType,
    Odometry,
    WalkingEngineOutput,
    WalkKick,
)
from tafel.representations.nao import HIP_OFFSET_Z

WALKING = (MotionType.walk, MotionType.walk_to)
ARMS = [JOINT_INDEX[n] for n in ("LShoulderPitch", "RShoulderPitch")]
STAND = stand_pose()  # arms and head while walking; apply_leg_angles copies it
#: the parameters tried live while the robot walks: modify values WalkingEngine:NAME (pin, watch, release)
TUNED = ("step_duration", "hip_height", "torso_offset_x", "foot_lift", "sway", "gyro_pitch_gain", "gyro_roll_gain", "arm_swing")


@requires(MotionRequest, MotionSelection, FrameInfo, InertialSensorData, FsrData)
@provides(WalkingEngineOutput, Odometry)
class WalkingEngine(Module):
    motion_request: MotionRequest
    motion_selection: MotionSelection
    frame_info: FrameInfo
    inertial_sensor_data: InertialSensorData
    fsr_data: FsrData
    walking_engine_output: WalkingEngineOutput
    odometry: Odometry

    draw_steps = DebugRequest("planned footsteps and the walk target on the robot canvas; the capture plots")
    tuning = ModifyParameters(TUNED, "tried live while the robot walks: modify:set WalkingEngine:NAME")
    capture_x = Plot("mm the capture point is ahead of where the walk expects it (while draw_steps is on)")
    capture_y = Plot("mm the capture point is left of where the walk expects it (while draw_steps is on)")
    phase = Plot("share of the current step done, 0..1")

    @dataclass
    class Parameters:
        step_duration: float = bounded(0.15, 0.6, 0.25)
        """s per step"""
        hip_height: float = bounded(180.0, 240.0, 226.0)
        """mm of the hip joints above the ground while walking"""
        torso_offset_x: float = bounded(-40.0, 40.0, 0.0)
        """mm the torso stands ahead of the feet"""
        foot_lift: float = bounded(0.0, 40.0, 22.0)
        """mm the swing foot rises"""
        sway: float = bounded(0.0, 40.0, 25.0)
        """mm the torso moves sideways over the support foot"""
        max_forward: float = bounded(0.0, 400.0, 320.0)
        """mm/s"""
        max_backward: float = bounded(0.0, 400.0, 150.0)
        """mm/s"""
        max_sideways: float = bounded(0.0, 300.0, 220.0)
        """mm/s"""
        max_turn: float = bounded(0.0, 3.0, 2.0)
        """rad/s"""
        max_acceleration: float = bounded(10.0, 2000.0, 400.0)
        """mm/s^2 by which the walking speed may change"""
        max_turn_acceleration: float = bounded(0.1, 20.0, 4.0)
        """rad/s^2 by which the turning speed may change"""
        gyro_pitch_gain: float = bounded(-1.0, 1.0, 0.08)
        """rad of ankle pitch per rad/s of pitch rate, on the support foot"""
        gyro_roll_gain: float = bounded(-1.0, 1.0, 0.05)
        """rad of ankle roll per rad/s of roll rate, on the support foot"""
        switch_after: float = bounded(0.3, 1.0, 0.75)
        """share of a step after which landing (foot pressure) ends it"""
        landing_share: float = bounded(0.05, 0.95, 0.4)
        """share of the weight on the swing foot that counts as its landing"""
        longest_step: float = bounded(1.0, 3.0, 1.0)
        """step durations after which a step ends without a landing"""
        leg_stiffness: float = bounded(0.0, 1.0, 1.0)
        arm_swing: float = bounded(0.0, 1.0, 0.3)
        """rad of shoulder pitch per 100 mm of step"""
        odometry_scale: float = bounded(0.5, 1.5, 1.0)
        """share of the feet's planned motion the robot really makes (the feet slip a little); measured per platform"""
        target_gain: float = bounded(0.1, 5.0, 1.5)
        """1/s: walk_to speed per mm (and rad) still to go"""
        target_tolerance: float = bounded(5.0, 300.0, 40.0)
        """mm (and tolerance / 400 rad) within which walk_to has arrived"""
        turn_in_place_beyond: float = bounded(0.5, math.pi, math.pi / 2)
        """rad: a walk_to target far behind whose rotation differs more than this from the heading is turned to in place
        first, not walked to backwards and blind: not a step of the way (behind, nothing is seen; a step that way while
        turning brought the torso up to 108 mm/s towards a robot standing there, the rules' pushing, in both engines)"""
        turn_in_place_step: float = bounded(0.0, 400.0, 45.0)
        """mm of the way to a target beside (face_beside_beyond) walked while turning to face it: that way is seen"""
        face_beside_beyond: float = bounded(0.5, math.pi, math.radians(60.0))
        """rad: a walk_to target far (over 400 mm) beside the heading by more than this is faced nearly in place first
        (robots are seen within 100 degrees: a walk within 60 of the heading sees 40 beyond its way; walked to fast
        sideways, the turn to face it got only what the sideways speed left, and a robot 20 degrees beyond the way
        was seen only when touched: 5v5 seed 1, 79.5 s)"""
        com_height: float = bounded(100.0, 500.0, 280.0)
        """mm of the centre of mass above the ground: turns the torso's tilt and its rate into where the body goes"""
        balance_x_gain: float = bounded(0.0, 3.0, 1.0)
        """share of the forward (or backward) capture-point error the swing foot steps further"""
        balance_y_gain: float = bounded(0.0, 3.0, 1.0)
        """share of the sideways capture-point error the swing foot steps further"""
        balance_deadband: float = bounded(0.0, 100.0, 60.0)
        """mm of capture-point error the walk's own rocking makes: no step adjustment within it"""
        max_adjust_x: float = bounded(0.0, 200.0, 80.0)
        """mm the swing foot may step further forward or back than planned"""
        max_adjust_y: float = bounded(0.0, 200.0, 60.0)
        """mm the swing foot may step further sideways than planned (never across the other foot)"""
        adjust_until: float = bounded(0.1, 1.0, 0.6)
        """share of a step after which its landing place stays as it is"""
        level_swing: float = bounded(0.0, 1.5, 0.5)
        """share of the torso's backward tilt (beyond ``level_deadband``) the swing foot is turned back by, about the
        torso: tipped onto its heels, the robot lands the foot flatter and further back, not where the tilted leg points"""
        level_deadband: float = bounded(0.0, 0.3, 0.05)
        """rad of backward tilt the walk's own rocking makes: only the tilt beyond it turns the swing foot"""
        hurry: float = bounded(0.0, 0.05, 0.01)
        """per mm of capture-point error beyond the deadband, how much faster the step goes (it lands sooner)"""
        max_hurry: float = bounded(1.0, 3.0, 1.6)
        """the fastest a step may go, as a multiple of its duration's speed"""
        kick_rearm: float = bounded(0.2, 5.0, 1.0)
        """s after a walk kick before the same request kicks again (a new request kicks at once)"""
        kick_window_near: float = bounded(0.0, 200.0, 60.0)
        """mm beyond a walk_to target (the ball nearer) up to which a walk kick is made, its line shifted back"""
        kick_window_far: float = bounded(0.0, 200.0, 20.0)
        """mm short of a walk_to target (the ball farther) from which a walk kick is made: the leg reaches little farther"""
        kick_tolerance: float = bounded(5.0, 100.0, 15.0)
        """mm within which walk_to has arrived while a walk kick is asked for"""
        kick_max_sideways: float = bounded(0.0, 300.0, 50.0)
        """mm/s of sideways walking towards the kicking foot's side beyond which no walk kick starts"""
        kick_window_y: float = bounded(0.0, 100.0, 40.0)
        """mm beside a walk_to target within which a walk kick is made"""

    parameters: Parameters

    def __init__(self) -> None:
        self.support = Foot.left  # the first swing foot is the right one
        self.phase_s = 0.0
        self.step = np.zeros(3)  # forward, left (mm), turn (rad) of the current step
        self.velocity = np.zeros(3)  # the walk's speed (mm/s, mm/s, rad/s), approaching the request within the accelerations
        self.start = {Foot.left: np.zeros(3), Foot.right: np.zeros(3)}  # foot offsets (x, y, yaw) at step start
        self.now = {Foot.left: np.zeros(3), Foot.right: np.zeros(3)}
        self.walking = False
        self.started = False  # a step has begun since the walk last stood still
        self.gyro = np.zeros(2)
        self.target: np.ndarray | None = None  # walk_to target in odometry coordinates
        self.last_target = np.full(3, np.nan)
        self.last_ns: int | None = None
        self.tuned = self.parameters  # this frame's parameters, with the modify values pinned by a debug client
        self.adjust = np.zeros(2)  # mm forward, left the swing foot steps beyond the plan, to catch the body
        self.reference = np.zeros(2)  # the torso's roll and pitch (rad) while walking undisturbed, a slow mean
        self.rates = np.zeros(2)  # roll and pitch rate (rad/s), lightly filtered
        self.support_level = np.zeros(2)  # roll, pitch (rad) the support foot landed turned back by
        self.tilt = np.zeros(2)  # the torso's roll and pitch (rad) beyond the reference
        self.levelled = {Foot.left: np.zeros(2), Foot.right: np.zeros(2)}  # roll, pitch (rad) each foot is turned back by
        self.kicks: dict[WalkKick, KickStep] = load_walk_kicks()
        self.kick: KickStep | None = None  # the current step's kick
        self.kick_direction = 0.0  # rad, robot frame, of the current step's kick
        self.kicked_ns: int | None = None  # when the last walk kick began, until the request drops it
        self.steps = 0  # steps since the walk last stood still
        self.kick_offset = (0.0, 0.0)  # mm the kick's line is shifted: the walk_to target not quite reached

    def execute(self) -> None:
        self.tuned = self.tuning.apply(self.parameters)
        p, out = self.tuned, self.walking_engine_output
        now_ns = self.frame_info.time_ns
        dt = (now_ns - self.last_ns) * 1e-9 if self.last_ns is not None and now_ns > self.last_ns else 0.01
        self.last_ns = now_ns
        # the turn comes from the gyroscope: feet slip when they turn, the torso's yaw rate does not
        yaw_rate = float(self.inertial_sensor_data.gyroscope[2])
        self.odometry.rotation = math.remainder(self.odometry.rotation + yaw_rate * dt, math.tau)
        selected = self.motion_selection.active in WALKING
        pending = selected and self.kick_pending(now_ns)
        velocity, reached = self.requested_velocity(pending) if selected else (np.zeros(3), False)
        out.target_reached = reached
        if not self.walking and not np.any(velocity) and not pending:  # not selected, or nowhere to go: stand in the walk's pose
            self.rest()
            return
        self.walking = True
        phase = min(1.0, self.phase_s / self.duration())  # where the last frame left the step
        swing = Foot.right if self.support is Foot.left else Foot.left
        pressure = self.fsr_data.pressure
        left, right = float(np.sum(pressure[:4])), float(np.sum(pressure[4:]))
        swing_load = left if swing is Foot.left else right
        landed = swing_load > p.landing_share * (left + right)  # the swing foot carries its share: it has landed
        switch_after = max(p.switch_after, self.kick.put_down_from) if self.kick else p.switch_after
        if self.phase_s == 0.0 or self.phase_s >= p.longest_step * self.duration() - 1e-9 or (phase >= switch_after and landed):
            at_rest = not np.any(velocity) and not np.any(self.velocity) and not np.any(self.step) and not pending
            if at_rest and self.phase_s > 0.0 and all(np.allclose(v, 0.0, atol=1e-9) for v in self.now.values()):
                self.rest()  # a standstill with the feet together: stop stepping
                self.walking = False
                return
            self.begin_step(velocity, pending, now_ns)
            swing = Foot.right if self.support is Foot.left else Foot.left
        beyond = self.balance(dt, phase)
        self.phase_s += dt * min(p.max_hurry, 1.0 + p.hurry * float(np.hypot(*beyond)))  # pushed: land sooner
        phase = min(1.0, self.phase_s / self.duration())  # this frame's: the last frame of a step reaches 1
        support_before = self.now[self.support].copy()
        toe = 0.0
        if self.kick is not None:
            self.now[swing], lift, toe = kick_swing(self.kick, phase, self.start[swing], self.goal(swing), self.kick_direction, swing,
                                                    self.kick_offset)
            lean = self.kick.sway * min(1.0, 2.0 * math.sin(math.pi * phase))  # over the support foot all the kick long
        else:
            smooth = 0.5 - 0.5 * math.cos(math.pi * phase)
            self.now[swing] = self.start[swing] + (self.goal(swing) - self.start[swing]) * smooth
            lift, lean = p.foot_lift * math.sin(math.pi * phase), p.sway * math.sin(math.pi * phase)
        self.now[self.support] = self.start[self.support] + (self.goal(self.support) - self.start[self.support]) * phase
        self.accumulate_odometry(support_before, self.now[self.support])
        sway = lean * (1.0 if self.support is Foot.left else -1.0)
        self.set_joints(swing, lift, sway, phase, toe)
        out.support_foot, out.step_phase = self.support, phase
        out.standing, out.kicking = False, self.kick is not None

    def capture_error(self, dt: float) -> np.ndarray:
        """Where the body is going (mm forward, left) beyond where the walk's own rocking takes it: the
        capture point of a linear inverted pendulum of ``com_height``, from the torso's tilt and its rate
        (the IMU), relative to the tilt the walk has when nobody pushes."""
        p, imu = self.tuned, self.inertial_sensor_data
        angles = np.asarray(imu.angles[:2], dtype=float)
        self.rates = 0.5 * self.rates + 0.5 * np.asarray(imu.gyroscope[:2], dtype=float)
        self.reference += (angles - self.reference) * min(1.0, dt / 2.0)  # 2 s: a push does not move it
        tilt = self.tilt = angles - self.reference
        settle = math.sqrt(p.com_height / 9810.0)  # s: the pendulum's time constant
        roll, pitch = tilt + settle * self.rates  # the tilt turns the stiff leg, and the landing place with it
        return np.array([p.com_height * pitch, -p.com_height * roll])  # leaning right: the body goes right

    def balance(self, dt: float, phase: float) -> np.ndarray:
        """Step adjustment: the swing foot lands further in the direction the body is pushed, as far as
        the capture-point error beyond the deadband and the limits allow (never across the other foot),
        until ``adjust_until`` of the step. Returns the error beyond the deadband (mm forward, left)."""
        p = self.tuned
        error = self.capture_error(dt)
        beyond = np.sign(error) * np.maximum(np.abs(error) - p.balance_deadband, 0.0)
        if phase < p.adjust_until:
            swing = Foot.right if self.support is Foot.left else Foot.left
            side = 1.0 if swing is Foot.left else -1.0
            limit = np.array([p.max_adjust_x, p.max_adjust_y])
            wanted = np.clip(beyond * np.array([p.balance_x_gain, p.balance_y_gain]), -limit, limit)
            planned_y = float(self.step[1]) * 0.5
            support_y = -planned_y
            inward = (support_y - planned_y) * side - 10.0  # mm it may go towards the support foot (<= 0: none)
            wanted[1] = max(wanted[1] * side, min(inward, 0.0)) * side
            self.adjust += np.clip(wanted - self.adjust, -800.0 * dt, 800.0 * dt)  # mm/s the landing place moves
        if self.draw_steps:
            self.capture_x.add(float(error[0]))
            self.capture_y.add(float(error[1]))
        return beyond

    def requested_velocity(self, kicking: bool = False) -> tuple[np.ndarray, bool]:
        """(forward mm/s, left mm/s, turn rad/s) within the limits, and whether a walk_to target is reached."""
        p, request = self.parameters, self.motion_request
        if request.motion is not MotionType.walk_to:
            self.target, self.last_target = None, np.full(3, np.nan)  # the next walk_to is a new one
        if request.motion is MotionType.walk:
            velocity = np.array([request.walk_x, request.walk_y, request.walk_rotation])
        elif request.motion is MotionType.walk_to:
            velocity, reached = self.towards_target(kicking)
            if reached:
                return np.zeros(3), True
        else:
            return np.zeros(3), False
        limits = np.array([p.max_forward if velocity[0] >= 0 else p.max_backward, p.max_sideways, p.max_turn])
        share = float(np.sqrt(np.sum((velocity / np.maximum(limits, 1e-6)) ** 2)))  # within an ellipsoid
        return (velocity / share if share > 1.0 else velocity), False

    def towards_target(self, kicking: bool = False) -> tuple[np.ndarray, bool]:
        """Speed towards the walk_to target, kept in odometry coordinates while the request stays the same;
        with a walk kick to make, arrived only within ``kick_tolerance`` (the kick needs the ball in place)."""
        request, odometry, p = self.motion_request, self.odometry, self.parameters
        wanted = np.array([request.target_x, request.target_y, request.target_rotation])
        here = odometry.as_pose2d()
        if self.target is None or not np.allclose(wanted, self.last_target):
            self.target = np.array(tuple(here * Pose2D(*wanted)))
            self.last_target = wanted
        x, y = here.to_local(self.target[0], self.target[1])
        turn = math.remainder(self.target[2] - odometry.rotation, math.tau)
        if self.draw_steps:
            self.draw_steps.canvas(Canvas.ROBOT).robot_pose(float(self.target[0]), float(self.target[1]), float(self.target[2]), color="yellow")
        tolerance = min(p.target_tolerance, p.kick_tolerance) if kicking else p.target_tolerance
        if math.hypot(x, y) < tolerance and abs(turn) < p.target_tolerance / 400:
            return np.zeros(3), True
        distance = math.hypot(x, y)
        far = distance > 400.0  # far away: face the target first, then turn to its rotation
        heading = math.atan2(y, x) if far and x > -200 else turn
        behind = far and x <= -200 and abs(turn) > p.turn_in_place_beyond  # behind, to be faced: nothing is seen there
        beside = far and x > -200 and abs(heading) > p.face_beside_beyond  # beside: little is seen beyond the way
        if behind or beside:  # turn first
            step = 0.0 if behind else p.turn_in_place_step
            x, y = x * step / distance, y * step / distance
        return np.array([x, y, heading]) * p.target_gain, False

    def duration(self) -> float:
        """s of the current step: a kick's own, else ``step_duration``."""
        return self.kick.duration if self.kick is not None else self.tuned.step_duration

    def kick_pending(self, now_ns: int) -> bool:
        """A walk kick is asked for and not yet made (the same request kicks again after ``kick_rearm``)."""
        request = self.motion_request
        if request.walk_kick is WalkKick.none or request.motion not in WALKING:
            self.kicked_ns = None
            return False
        return self.kicked_ns is None or (now_ns - self.kicked_ns) * 1e-9 >= self.parameters.kick_rearm

    def kick_reach(self, foot: Foot) -> tuple[float, float] | None:
        """Where the walk_to target (the kicking pose) still is (mm ahead, left), when a kick from here
        reaches the ball; None when not. A ``walk`` request kicks from where the robot is: (0, 0)."""
        p = self.parameters
        side = 1.0 if foot is Foot.left else -1.0
        if self.velocity[1] * side > p.kick_max_sideways or abs(self.velocity[2]) > 0.3:
            return None  # still stepping out to the kicking foot's side, or turning: it would swing off its line
        if self.motion_request.motion is not MotionType.walk_to or self.target is None:
            return (0.0, 0.0)
        x, y = self.odometry.as_pose2d().to_local(float(self.target[0]), float(self.target[1]))
        turn = math.remainder(float(self.target[2]) - self.odometry.rotation, math.tau)
        if -p.kick_window_near <= x <= p.kick_window_far and abs(y) <= p.kick_window_y and abs(turn) < 0.2:
            return (0.0, 0.0)  # near enough: a shifted line measured worse (the swing is shorter, odometry drifts)
        return None

    def begin_step(self, velocity: np.ndarray, pending: bool = False, now_ns: int = 0) -> None:
        """The swing foot has landed: it supports now, and the next step is planned (a kick when one is
        pending and the kicking foot swings)."""
        p = self.tuned
        self.steps = self.steps + 1 if self.phase_s > 0.0 else 0
        rocking = self.steps >= 2 and self.kick is None  # two walk steps ended: the torso sways in rhythm
        if self.phase_s > 0.0 or self.started:
            self.support = Foot.right if self.support is Foot.left else Foot.left
        self.started = True
        self.phase_s = 0.0
        self.adjust = np.zeros(2)  # the foot that now swings starts with its own plan
        self.support_level = self.levelled[self.support].copy()  # landed turned back: it rights the torso over this step
        self.start = {foot: offset.copy() for foot, offset in self.now.items()}
        swing = Foot.right if self.support is Foot.left else Foot.left
        limit = np.array([p.max_acceleration, p.max_acceleration, p.max_turn_acceleration]) * p.step_duration
        self.velocity = self.velocity + np.clip(velocity - self.velocity, -limit, limit)
        # forward every step; sideways and turning steps open with the foot on that side (twice as long),
        # and the next step closes the feet again
        wanted = self.velocity * p.step_duration * np.array([1.0, 2.0, 2.0])
        side = 1.0 if swing is Foot.left else -1.0
        if wanted[1] * side < 0:
            wanted[1] = 0.0
        if wanted[2] * side < 0:
            wanted[2] = 0.0
        self.step = wanted
        self.kick = None
        request = self.motion_request
        offset = self.kick_reach(swing)
        if pending and rocking and swing is request.kick_foot and offset is not None:  # never out of a standstill
            self.kick, self.kick_offset = self.kicks[request.walk_kick], offset
            widest = self.kick.max_direction
            self.kick_direction = min(widest, max(-widest, float(request.kick_direction)))
            self.kicked_ns = now_ns
            self.walking_engine_output.kicks += 1
            self.step = np.array([min(max(float(wanted[0]), 0.0), self.kick.landing), 0.0, 0.0])  # a straight step
        if self.draw_steps:
            goal = self.goal(swing)
            self.draw_steps.canvas(Canvas.ROBOT).rectangle(float(goal[0]) - 50, float(goal[1]) - 25 + side * 50,
                                                           float(goal[0]) + 100, float(goal[1]) + 25 + side * 50, color="white")

    def goal(self, foot: Foot) -> np.ndarray:
        """Where a foot ends this step (x, y mm, yaw rad, relative to its place beside the torso)."""
        swing = self.support is not foot
        sign = 0.5 if swing else -0.5
        goal = self.step * sign
        if swing:
            goal[:2] += self.adjust
        return goal

    def set_joints(self, swing: Foot, lift: float, sway: float, phase: float, toe: float = 0.0) -> None:
        p, out = self.tuned, self.walking_engine_output
        height = p.hip_height + HIP_OFFSET_Z
        soles = {}
        back = min(float(self.tilt[1]) + p.level_deadband, 0.0)  # tipped back onto the heels, beyond the walk's own rocking
        self.levelled[swing] = np.array([0.0, p.level_swing * back])
        self.levelled[self.support] = self.support_level * (1.0 - phase)  # the torso rises back over the step
        for foot, side in ((Foot.left, 1.0), (Foot.right, -1.0)):
            x, y, yaw = self.now[foot]
            z = -height + (lift if foot is swing else 0.0)
            soles[foot] = level(pose(x - p.torso_offset_x, side * 50.0 + y - sway, z, pitch=toe if foot is swing else 0.0, yaw=yaw),
                                self.levelled[foot])
        angles = leg_angles(soles[Foot.left], soles[Foot.right])
        # gyroscope feedback on the support ankle: lean against the torso's rotation
        self.gyro = 0.7 * self.gyro + 0.3 * np.asarray(self.inertial_sensor_data.gyroscope[:2], dtype=float)
        prefix = "L" if self.support is Foot.left else "R"
        angles[f"{prefix}AnklePitch"] += p.gyro_pitch_gain * self.gyro[1]
        angles[f"{prefix}AnkleRoll"] += p.gyro_roll_gain * self.gyro[0]
        position = apply_leg_angles(STAND, angles)
        swing_x = self.now[Foot.left][0] - self.now[Foot.right][0]
        position[ARMS[0]] += p.arm_swing * swing_x / 100.0  # the arm opposite the forward foot swings forward
        position[ARMS[1]] -= p.arm_swing * swing_x / 100.0
        out.position = position
        out.stiffness = np.full(JOINT_COUNT, p.leg_stiffness)
        self.phase.add(phase)

    def accumulate_odometry(self, before: np.ndarray, after: np.ndarray) -> None:
        """The torso moves against the support foot: its backward slide is the robot's forward motion."""
        odometry = self.odometry
        dx, dy, _ = (before - after) * self.parameters.odometry_scale
        step_x, step_y = odometry.as_pose2d().rotated(dx, dy)
        odometry.x += step_x
        odometry.y += step_y

    def rest(self) -> None:
        """Not selected and not walking: stand in the walk's own pose, ready to start."""
        out = self.walking_engine_output
        self.now = {Foot.left: np.zeros(3), Foot.right: np.zeros(3)}
        self.step = np.zeros(3)
        self.velocity = np.zeros(3)
        self.phase_s = 0.0
        self.started = False
        self.adjust = np.zeros(2)
        # standing still is the undisturbed tilt: a fall and get-up while not walking must not leave the
        # step adjustment a stale tilt or rate (it lunged the first step after a get-up)
        self.reference = np.asarray(self.inertial_sensor_data.angles[:2], dtype=float).copy()
        self.rates = np.zeros(2)
        self.tilt = np.zeros(2)
        self.support_level = np.zeros(2)
        self.kick = None
        self.set_joints(Foot.right, 0.0, 0.0, 0.0)
        out.standing, out.step_phase, out.kicking = True, 0.0, False


def level(sole: np.ndarray, tilt: np.ndarray) -> np.ndarray:
    """``sole`` (torso frame) turned back by the torso's ``tilt`` (roll, pitch rad) about the torso: the pose
    it has in the upright torso frame, now in the tilted one."""
    if not np.any(tilt):
        return sole
    turn = np.eye(4)
    turn[:3, :3] = (rot_y(float(tilt[1])) @ rot_x(float(tilt[0]))).T
    return turn @ sole
