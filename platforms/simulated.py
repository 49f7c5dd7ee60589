"""What every simulated NAO platform shares: options, the representations, sensing, acting, commands.

An engine (MuJoCo, PyBullet) only builds the world from the shared description and answers a handful
of questions (joint angles, IMU, foot forces, a camera image, where things are); this class turns the
answers into representations with the same units, frames and joint order for every engine.
"""

from __future__ import annotations

import argparse
import math
import os
import sys
from collections import deque
from collections.abc import Mapping
from typing import Annotated, Any, ClassVar

import numpy as np

from tafel.core.framework.manager import Blackboard
from tafel.core.framework.values import Range, convert, refusal
from tafel.core.runtime.platform import Platform, PlatformOptionError, seed_number
from tafel.platforms.actuators import ActuatorGuard
from tafel.platforms.field_world import BALL_COLORS, level_look
from tafel.platforms.network import NETWORK_INPUTS, NETWORK_OUTPUTS, NetworkedPlatform
from tafel.platforms.realism import LEVELS, CameraRealism, image_shift, parse_realism, realism_level
from tafel.platforms.robot_model import STANDING_HEIGHT
from tafel.representations import field
from tafel.representations.geometry import Pose2D
from tafel.representations.modeling import KnownPose
from tafel.representations.motion import (
    CHEST_BUTTON,
    JOINT_NAMES,
    FsrData,
    InertialSensorData,
    JointCommand,
    JointSensorData,
    TouchSensorData,
)
from tafel.representations.nao import VERTICAL_FOV
from tafel.representations.perception import CameraImageBottom, CameraImageTop

GRAVITY = 9.81
TIMESTEP = 0.002  # s of physics per step
PUSH_SECONDS = 0.1  # how long sim:push pushes
BUTTON_SECONDS = 0.1  # how long sim:button holds the chest button
LYING_HEIGHT = 0.12  # m of the torso above the ground when put down lying (it drops the last bit)


def _carpet() -> tuple[Any, ...]:
    """X and Y on the carpet, as element types with their ranges."""
    return Annotated[float, Range(-CARPET_X, CARPET_X)], Annotated[float, Range(-CARPET_Y, CARPET_Y)]


def parse_pair(text: str, what: str) -> tuple[float, float]:
    """``X,Y`` in mm on the carpet (``--ball``)."""
    on_carpet = f"X,Y in mm on the carpet (|X| <= {CARPET_X:g}, |Y| <= {CARPET_Y:g}), e.g. 1000,300"
    return convert(text, tuple[_carpet()], where=what, expected=on_carpet, error=PlatformOptionError)


#: mm/s of the fastest ball a scene may start with (a strong kick rolls off at about 5 m/s)
MAX_BALL_SPEED = 10000.0


def parse_velocity(text: str) -> tuple[float, float]:
    """``--ball-velocity``: ``VX,VY`` in mm/s, at most ``MAX_BALL_SPEED`` fast."""
    expected = f"VX,VY in mm/s, at most {MAX_BALL_SPEED:g} mm/s fast, e.g. 500,0"
    vx, vy = convert(text, tuple[float, float], where="--ball-velocity", expected=expected, error=PlatformOptionError)
    if math.hypot(vx, vy) > MAX_BALL_SPEED:
        raise refusal("--ball-velocity", expected, text, PlatformOptionError)
    return vx, vy


def parse_noise(value: Any) -> float:
    """``--sensor-noise``: a factor from 0 to 100 (None: 1, the NAO's noise)."""
    return 1.0 if value is None else convert(value, float, where="--sensor-noise", bounds=(0.0, 100.0), error=PlatformOptionError,
                                             expected="a factor from 0 to 100 (1: the NAO's noise, 0: none)")


#: the default scene: the robot in its own half facing the opponent goal, the ball on the centre spot
DEFAULT_START = "-1500,0,0"
DEFAULT_BALL = "0,0"


def parse_pose(text: str) -> tuple[float, float, float]:
    """``--start``: ``X,Y,ROT`` (mm, mm, rad) on the carpet; the rotation within one turn."""
    expected = f"X,Y,ROT (mm, mm, rad) on the carpet (|X| <= {CARPET_X:g}, |Y| <= {CARPET_Y:g}), e.g. -1500,0,0"
    x, y, rotation = convert(text, tuple[(*_carpet(), float)], where="--start", expected=expected, error=PlatformOptionError)
    return x, y, math.remainder(rotation, math.tau)


def parse_resolution(text: str) -> tuple[int, int]:
    """One camera's ``WIDTHxHEIGHT``, 16 to 4096 pixels a side."""
    side = Annotated[int, Range(16, 4096)]
    return convert(str(text).lower(), tuple[side, side], where="--resolution", separator="x", error=PlatformOptionError,
                   expected="WIDTHxHEIGHT with 16 to 4096 pixels a side, e.g. 320x240, or TOP,BOTTOM: 640x480,320x240")


def parse_resolutions(text: str) -> dict[str, tuple[int, int]]:
    """``--resolution``: ``WIDTHxHEIGHT`` for both cameras, or ``TOP,BOTTOM`` (``640x480,320x240``, as the NAO's
    cameras are usually set: the top one sees far, the bottom one the feet)."""
    parts = str(text).split(",")
    if len(parts) > 2:
        raise PlatformOptionError(f"--resolution takes WIDTHxHEIGHT or TOP,BOTTOM (e.g. 640x480,320x240), got {text!r}")
    top = parse_resolution(parts[0].strip())
    return {"top": top, "bottom": parse_resolution(parts[-1].strip())}


def has_display() -> bool:
    return bool(os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY"))


#: the cameras' image size, both (``--resolution``)
DEFAULT_RESOLUTION = "320x240"
MAX_PUSH = 500.0  # N: more would throw the robot off the field, not test a fall
#: how far from the centre spot things can be put (mm): the field and its border strip
CARPET_X = field.LENGTH / 2 + field.BORDER_STRIP
CARPET_Y = field.WIDTH / 2 + field.BORDER_STRIP


def number(args: Mapping[str, Any], name: str, default: float = 0.0, limit: float = math.inf) -> float:
    """A finite numeric debug command argument within ``±limit``, with an error that names it."""
    return convert(args.get(name, default), float, where=f"-{name}", bounds=(-limit, limit) if math.isfinite(limit) else None,
                   error=PlatformOptionError)


def switch(args: Mapping[str, Any], name: str) -> bool:
    """An on/off debug command argument: ``-NAME on`` (or true, yes, 1), or the bare word ``NAME``."""
    if name not in args:
        return False
    return args[name] == "" or convert(args[name], bool, where=f"-{name}", error=PlatformOptionError)


class SimulatedRobotPlatform(NetworkedPlatform, Platform):
    """Base of the simulator platforms: one world feeds both contexts in lockstep."""

    clock = "simulated"
    concurrent = False  # images and joints must come from the same simulated world
    default_network = "simulated"  # parallel simulations must not hear each other (tafel match asks for udp)
    provides: ClassVar[Mapping[str, tuple[type, ...]]] = {
        "motion": (JointSensorData, InertialSensorData, FsrData, TouchSensorData),
        "cognition": (CameraImageTop, CameraImageBottom, KnownPose, *NETWORK_INPUTS),
    }
    consumes: ClassVar[Mapping[str, tuple[type, ...]]] = {"motion": (JointCommand,), "cognition": NETWORK_OUTPUTS}
    #: the engine's name in help texts
    engine = ""

    def __init__(self, options: Mapping[str, Any] | None = None) -> None:
        super().__init__(options)
        self.seed = convert(self.options.get("seed") or 0, int, where="--seed", bounds=(0, 2**32 - 1), error=PlatformOptionError)
        self.cameras = convert(self.options.get("cameras", "on"), bool, where="--cameras", error=PlatformOptionError)
        #: camera -> (width, height) px of its images (--resolution)
        self.sizes = parse_resolutions(self.options.get("resolution") or DEFAULT_RESOLUTION)
        self.initial_ball = parse_pair(self.options.get("ball") or DEFAULT_BALL, "--ball")
        self.initial_ball_velocity = parse_velocity(self.options.get("ball_velocity") or "0,0")
        self.sensor_noise = parse_noise(self.options.get("sensor_noise"))
        self.ball_color = convert(self.options.get("ball_color") or "spl", str, where="--ball-color", choices=tuple(BALL_COLORS),
                                  error=PlatformOptionError)
        self.initial_pose = parse_pose(self.options.get("start") or DEFAULT_START)
        #: --realism: off (the plain render), mild or full (config/realism.toml): the cameras' pipeline and the scene's look
        self.realism = parse_realism(self.options.get("realism"))
        self.realism_level = realism_level(self.realism)
        self.camera_realism = {camera: CameraRealism(self.realism_level, self.seed, camera)
                               for camera in ("top", "bottom")} if self.realism_level else {}
        self.last_camera: dict[str, tuple[int, np.ndarray]] = {}  # camera -> (time_ns, rotation) at its last image
        level = self.realism_level
        #: what the engines add to the world with --realism (None: the plain scene)
        self.scene_look = level_look(self.seed, level)
        self.shadows = bool(level and level.shadows)
        self.viewer_requested = bool(self.options.get("viewer"))
        self.rng = np.random.default_rng(self.seed)
        self.stiffness = np.zeros(len(JOINT_NAMES))
        self.guard = ActuatorGuard(self.name)  # joint limits, 0..1, no NaN: whatever the modules send
        self.paused = False
        self.push_force = np.zeros(3)
        self.push_steps = 0  # physics steps the current push still lasts
        self.time_ns = 0
        self.last_steps = 0  # physics steps of the last advance (benchmarks read it)
        latency = convert(self.options.get("camera_latency_ms") or 0.0, float, where="--camera-latency-ms", bounds=(0.0, 1000.0),
                          unit="ms", error=PlatformOptionError)
        self.camera_latency_ns = int(round(latency * 1e6))
        #: (time_ns, engine state) of the recent physics steps, while images arrive late
        self.history: deque[tuple[int, Any]] = deque()
        self.button_until_ns = -1  # the chest button is held down until then (sim:button)
        #: goals scored by the robot's team (it attacks +x, towards the opponent goal) and against it
        self.score = [0, 0]
        self.ball_in_goal = 0  # field.goal_of of the ball after the last step: a goal counts when the ball gets in
        self.events: list[str] = []
        self.known_pose = KnownPose()  # told to the localization at the next cognition frame (sim:move_robot -reset on)
        self.tell_pose = False

    @classmethod
    def add_arguments(cls, parser: argparse.ArgumentParser) -> None:
        name = cls.name
        parser.add_argument("--seed", type=seed_number, default=0, help=f"{name}: seed of the sensor noise")
        parser.add_argument("--cameras", choices=["on", "off"], default="on", help=f"{name}: render the cameras")
        parser.add_argument("--resolution", default=DEFAULT_RESOLUTION,
                            help=f"{name}: camera image size WIDTHxHEIGHT for both, or TOP,BOTTOM (the NAO's: 640x480,320x240)")
        parser.add_argument("--ball", default=DEFAULT_BALL, help=f"{name}: ball start X,Y in mm on the field (default: the centre spot)")
        parser.add_argument("--ball-velocity", default="0,0", metavar="VX,VY",
                            help=f"{name}: the ball rolls off at VX,VY mm/s on the field (default: it lies still)")
        parser.add_argument("--sensor-noise", type=float, default=1.0, metavar="FACTOR",
                            help=f"{name}: scale of the joint, IMU and foot sensors' noise (default 1: the NAO's; 0: none)")
        parser.add_argument("--ball-color", choices=BALL_COLORS, default="spl",
                            help=f"{name}: spl (white with black patches, the default) or orange (the ball before 2016)")
        parser.add_argument("--start", default=DEFAULT_START, metavar="X,Y,ROT",
                            help=f"{name}: robot start pose, mm on the field and rad (default: {DEFAULT_START}, in its own half facing the opponent goal)")
        parser.add_argument("--viewer", action="store_true", help=f"{name}: open the {cls.engine} viewer (needs a display)")
        parser.add_argument("--camera-latency-ms", type=float, default=0.0, metavar="MS",
                            help=f"{name}: images are rendered at time t and delivered MS later, as on the NAO (30 to 40)")
        parser.add_argument("--realism", nargs="?", const="full", default="off", choices=LEVELS, metavar="LEVEL",
                            help=f"{name}: render what a real camera sees: off (default), mild or full (the bare option): "
                                 "exposure, white balance, noise, motion blur, vignetting, YUV422 and JPEG, a hall with "
                                 "clutter, goal nets, shadows, carpet greens; seeded by --seed (config/realism.toml)")

    def config_layers(self) -> list[str]:
        """The engine's layer, then ``orange_ball`` with ``--ball-color orange`` (it picks the orange detector)."""
        return [self.name, *(["orange_ball"] if self.ball_color == "orange" else [])]

    # ------------------------------------------------------------------ what an engine implements
    def build(self, contexts: frozenset[str], viewer: bool) -> None:
        """Create the world (robot at the field's centre facing +x, ball at ``initial_ball``); ``start``
        then puts the robot at ``initial_pose``."""
        raise NotImplementedError

    def step_physics(self, steps: int) -> None:
        raise NotImplementedError

    def joint_angles(self) -> np.ndarray:
        """Measured joint angles (rad) in ``JOINT_NAMES`` order."""
        raise NotImplementedError

    def joint_torques(self) -> np.ndarray:
        """Torques the servos apply (N m) in ``JOINT_NAMES`` order."""
        raise NotImplementedError

    def imu(self) -> tuple[np.ndarray, np.ndarray]:
        """(accelerometer m/s^2, gyroscope rad/s) in the torso frame."""
        raise NotImplementedError

    def foot_forces(self) -> np.ndarray:
        """Normal force (N) on the eight pressure sensors in FsrData order."""
        raise NotImplementedError

    def render(self, camera: str) -> np.ndarray:
        """The image of ``top`` or ``bottom`` (height x width x 3 RGB uint8)."""
        raise NotImplementedError

    def camera_rotation(self, camera: str) -> np.ndarray | None:
        """The camera's orientation now (3x3; columns forward, left, up in the world), for motion blur;
        None where the engine does not say (no blur)."""
        return None

    def world_state(self) -> Any:
        """The world as it is now, to render it later (only used with a camera latency)."""
        raise NotImplementedError

    def forget_state(self, state: Any) -> None:
        """Release a state from ``world_state`` that is no longer needed."""

    def render_state(self, state: Any, cameras: tuple[str, ...]) -> dict[str, np.ndarray]:
        """The cameras' images of the world as it was in ``state``; the world itself stays as it is now."""
        raise NotImplementedError

    def drive(self, targets: np.ndarray, stiffness: np.ndarray) -> None:
        """Position targets (rad) with stiffness 0..1 per joint in ``JOINT_NAMES`` order."""
        raise NotImplementedError

    def torso_pose(self) -> tuple[np.ndarray, np.ndarray]:
        """(position m, rotation 3x3) of the torso in the world."""
        raise NotImplementedError

    def ball_position(self) -> tuple[float, float]:
        """The ball on the field (mm)."""
        raise NotImplementedError

    def move_ball(self, x_mm: float, y_mm: float, velocity_mm_s: tuple[float, float] = (0.0, 0.0)) -> None:
        """Put the ball at (x, y) on the ground, lying still or rolling off at ``velocity_mm_s``."""
        raise NotImplementedError

    def place_robot(self, position_m: np.ndarray, quaternion_wxyz: np.ndarray) -> None:
        """Put the torso at ``position_m`` turned by ``quaternion_wxyz``, at rest."""
        raise NotImplementedError

    def pose_joints(self, angles: np.ndarray) -> None:
        """Set the joints to ``angles`` (rad, ``JOINT_NAMES`` order) at once, at rest: for rendering posed
        scenes (``tools.simulation.scene_frames``), not for moving the robot physically."""
        raise NotImplementedError

    def ball_mask(self, camera: str) -> np.ndarray:
        """Which pixels of ``camera``'s image show the ball (height x width bool): ground truth for detectors."""
        raise NotImplementedError

    def apply_push(self, force_n: np.ndarray) -> None:
        """Apply a horizontal force (N, world frame) to the torso during the next physics step."""
        raise NotImplementedError

    def move_robot(self, x_mm: float, y_mm: float, heading: float = 0.0, lying: str = "") -> None:
        """Put the robot at (x, y) facing ``heading``: standing at its height, or ``lying`` front or back."""
        position, _ = self.torso_pose()
        pitch = {"": 0.0, "front": math.pi / 2, "back": -math.pi / 2}[lying]
        height = LYING_HEIGHT if lying else position[2] if position[2] > 0.2 else STANDING_HEIGHT + 0.002
        cy, sy, cp, sp = math.cos(heading / 2), math.sin(heading / 2), math.cos(pitch / 2), math.sin(pitch / 2)
        self.place_robot(np.array([x_mm / 1000.0, y_mm / 1000.0, height]), np.array([cy * cp, -sy * sp, cy * sp, sy * cp]))

    # ------------------------------------------------------------------------------ platform
    def start(self, contexts: frozenset[str]) -> None:
        viewer = self.viewer_requested and has_display()
        if self.viewer_requested and not viewer:
            print(f"{self.name}: --viewer needs a display (DISPLAY is not set); running headless", file=sys.stderr)
        self.build(contexts, viewer)
        self.move_robot(*self.initial_pose)
        self.ball_in_goal = field.goal_of(*self.initial_ball)  # a ball that starts in a goal scores nothing
        if "cognition" in contexts:
            self.network.open()

    def stop(self) -> None:
        self.network.close()

    def advance(self, time_ns: int) -> None:
        self.step_world(time_ns)
        self.judge_goal()

    def take_events(self) -> list[str]:
        events, self.events = self.events, []
        return events

    def judge_goal(self) -> None:
        """A goal when the ball has got wholly over a goal line between the posts (``field.goal_of``, the
        rule the match's referee judges by); the ball lying in the net afterwards is no new goal."""
        where = field.goal_of(*self.ball_position())
        if where and where != self.ball_in_goal:
            self.score[0 if where > 0 else 1] += 1
            what = ("GOAL for the robot's team (the ball is in the opponent goal)" if where > 0
                    else "GOAL against the robot's team (the ball is in its own goal)")
            self.events.append(f"{what}: score {self.score[0]}:{self.score[1]}")
        self.ball_in_goal = where

    def step_world(self, time_ns: int) -> None:
        """The physics from the last ``advance`` to ``time_ns`` (none while paused), keeping each step's
        world while images arrive late."""
        steps = int(round((time_ns - self.time_ns) * 1e-9 / TIMESTEP))
        start_ns, self.time_ns = self.time_ns, time_ns
        self.last_steps = 0 if self.paused else max(steps, 0)
        if not self.last_steps:
            return
        while self.push_steps and self.last_steps:  # a push lasts PUSH_SECONDS of physics
            self.apply_push(self.push_force)
            self.step_physics(1)
            self.push_steps -= 1
            self.last_steps -= 1
            start_ns += int(round(TIMESTEP * 1e9))
        if not self.last_steps:
            return
        if not (self.camera_latency_ns and self.cameras):
            self.step_physics(self.last_steps)
            return
        for step in range(1, self.last_steps + 1):  # keep each step's world: images show the past
            self.step_physics(1)
            self.history.append((start_ns + int(round(step * TIMESTEP * 1e9)), self.world_state()))
        while len(self.history) > 1 and self.history[1][0] <= time_ns - self.camera_latency_ns:
            self.forget_state(self.history.popleft()[1])

    def sense(self, context: str, blackboard: Blackboard, frame_number: int, time_ns: int) -> None:
        if context == "motion":
            joints = blackboard[JointSensorData]
            joints.position = self.joint_angles() + self.rng.normal(0.0, 0.0005 * self.sensor_noise, len(JOINT_NAMES))
            self.guard.hold(joints.position)
            joints.stiffness = self.stiffness.copy()
            joints.current = np.abs(self.joint_torques()) / 10.0  # a rough N m -> A of the NAO's motors
            joints.temperature = np.full(len(JOINT_NAMES), 30.0)
            accelerometer, gyroscope = self.imu()
            inertial = blackboard[InertialSensorData]
            inertial.accelerometer = accelerometer + self.rng.normal(0.0, 0.02 * self.sensor_noise, 3)
            inertial.gyroscope = gyroscope + self.rng.normal(0.0, 0.002 * self.sensor_noise, 3)
            inertial.angles = np.array(self.torso_angles())
            blackboard[FsrData].pressure = self.foot_forces() / GRAVITY
            touch = np.zeros(len(TouchSensorData().pressed))
            touch[CHEST_BUTTON] = float(time_ns < self.button_until_ns)
            blackboard.set(TouchSensorData(pressed=touch))
            return
        self.network.receive(blackboard, time_ns)
        if context == "cognition":
            self.tell_known_pose(blackboard)
        if context == "cognition" and self.cameras:
            taken_ns, images = self.images(time_ns)
            if self.camera_realism:
                images = self.realistic(images, time_ns)
            for camera, rep in (("top", CameraImageTop), ("bottom", CameraImageBottom)):
                image = blackboard[rep]
                image.image = images[camera]
                image.time_ns = taken_ns
                image.horizontal_fov, image.vertical_fov = self.fov(camera)

    def realistic(self, images: dict[str, np.ndarray], time_ns: int) -> dict[str, np.ndarray]:
        """The rendered images as the real cameras would deliver them (``--realism``), blurred by how fast
        each camera turned since its last image (measured on the world as it is now)."""
        result = {}
        for camera, image in images.items():
            shift = (0.0, 0.0)
            rotation = self.camera_rotation(camera)
            if rotation is not None:
                last = self.last_camera.get(camera)
                if last is not None:
                    pipeline = self.camera_realism[camera]
                    shift = image_shift(last[1], rotation, (time_ns - last[0]) * 1e-9, pipeline.exposure_s, self.focal_px(camera))
                self.last_camera[camera] = (time_ns, rotation)
            result[camera] = self.camera_realism[camera](image, shift)
        return result

    def focal_px(self, camera: str = "top") -> tuple[float, float]:
        """(horizontal, vertical) focal length of ``camera``'s rendered images (px)."""
        horizontal, vertical = self.fov(camera)
        width, height = self.sizes[camera]
        return width / 2 / math.tan(horizontal / 2), height / 2 / math.tan(vertical / 2)

    def tell_known_pose(self, blackboard: Blackboard) -> None:
        """``KnownPose``: the last pose told, and after ``sim:move_robot -reset on`` a new one, where the
        robot is now (ground truth), so that the localization starts anew there."""
        if self.tell_pose:
            self.tell_pose = False
            x, y, heading = self.robot_pose()
            self.known_pose = KnownPose(serial=self.known_pose.serial + 1, x=x, y=y, rotation=heading)
        if self.known_pose.serial:
            blackboard.set(KnownPose(**vars(self.known_pose)))

    def images(self, time_ns: int) -> tuple[int, dict[str, np.ndarray]]:
        """(when taken, images) delivered at ``time_ns``: rendered ``camera_latency_ns`` earlier."""
        cameras = ("top", "bottom")
        if not (self.camera_latency_ns and self.history):
            return time_ns, {camera: self.render(camera) for camera in cameras}
        due = time_ns - self.camera_latency_ns
        taken_ns, state = self.history[0]
        for entry_ns, entry in self.history:
            if entry_ns > due:
                break
            taken_ns, state = entry_ns, entry
        return taken_ns, self.render_state(state, cameras)

    def act(self, context: str, blackboard: Blackboard) -> None:
        if context == "cognition":
            self.network.send(blackboard)
        if context != "motion":
            return
        command = blackboard[JointCommand]
        targets, self.stiffness = self.guard(command.position, command.stiffness)
        self.drive(targets, self.stiffness)

    def fov(self, camera: str = "top") -> tuple[float, float]:
        """(horizontal, vertical) field of view of ``camera``'s rendered images (rad): the vertical one is the
        NAO's, the horizontal one follows the image's width to height."""
        width, height = self.sizes[camera]
        return 2 * math.atan(math.tan(VERTICAL_FOV / 2) * width / height), VERTICAL_FOV

    # ------------------------------------------------------------------------- ground truth
    def torso_angles(self) -> tuple[float, float]:
        """Torso roll and pitch relative to the ground (rad)."""
        _, matrix = self.torso_pose()
        pitch = math.asin(max(-1.0, min(1.0, -matrix[2, 0])))
        return math.atan2(matrix[2, 1], matrix[2, 2]), pitch

    def torso_height(self) -> float:
        """mm above the ground."""
        return float(self.torso_pose()[0][2]) * 1000.0

    def posture(self) -> str:
        """upright, lying front, lying back or lying side, from the torso's orientation (ground truth)."""
        _, matrix = self.torso_pose()
        if matrix[2, 2] > 0.7:
            return "upright"
        if matrix[2, 0] < -0.7:
            return "lying front"
        if matrix[2, 0] > 0.7:
            return "lying back"
        return "lying side" if matrix[2, 2] < 0.5 else "tilted"

    def robot_pose(self) -> tuple[float, float, float]:
        """The torso on the field: x, y (mm) and heading (rad)."""
        position, matrix = self.torso_pose()
        return float(position[0]) * 1000.0, float(position[1]) * 1000.0, math.atan2(matrix[1, 0], matrix[0, 0])

    def ball_in_robot_frame(self) -> tuple[float, float]:
        """The ball relative to the robot (mm): the frame between the feet, turned with the torso."""
        return Pose2D(*self.robot_pose()).to_local(*self.ball_position())

    # ------------------------------------------------------------------------ debug commands
    def commands(self) -> Mapping[str, tuple[str, Any]]:
        def ball(args: Mapping[str, Any]) -> str:
            x, y = number(args, "x", limit=CARPET_X), number(args, "y", limit=CARPET_Y)
            velocity = number(args, "vx", limit=MAX_BALL_SPEED), number(args, "vy", limit=MAX_BALL_SPEED)
            self.move_ball(x, y, velocity)
            self.ball_in_goal = field.goal_of(x, y)  # put in a goal by hand: no goal scored
            return f"ball at x={x:.0f} y={y:.0f} mm" + (f", rolling at {velocity[0]:.0f},{velocity[1]:.0f} mm/s" if any(velocity) else "")

        def robot(args: Mapping[str, Any]) -> str:
            x, y = number(args, "x", limit=CARPET_X), number(args, "y", limit=CARPET_Y)
            heading = math.remainder(number(args, "rotation"), math.tau)
            lying = args.get("lying") or ""
            lying = lying and convert(lying, str, where="-lying", choices=("front", "back"), error=PlatformOptionError)
            reset = switch(args, "reset")
            self.move_robot(x, y, heading, lying)
            where = f"robot at x={x:.0f} y={y:.0f} mm, rotation {heading:.3f} rad" + (f", lying on its {lying}" if lying else "")
            if reset:
                self.tell_pose = True
                return where + "; the localization starts anew at this pose (KnownPose)"
            twin = f"x={-x:.0f} y={-y:.0f} mm, rotation {math.remainder(heading + math.pi, math.tau):.3f} rad"
            return (f"{where}. The field looks the same turned by 180 degrees ({twin} looks alike): carried where no rule "
                    "places a robot, the localization keeps RobotPose not valid until a teammate's ball or a placement "
                    "decides the side; add -reset on to tell it the true pose")

        def push(args: Mapping[str, Any]) -> str:
            fx, fy = number(args, "x", limit=MAX_PUSH), number(args, "y", limit=MAX_PUSH)
            self.push_force = np.array([fx, fy, 0.0])
            self.push_steps = int(round(PUSH_SECONDS / TIMESTEP))
            return f"pushing the torso with ({fx:.0f}, {fy:.0f}) N for {PUSH_SECONDS} s"

        def pause(args: Mapping[str, Any]) -> str:
            self.paused = True
            return "physics paused"

        def resume(args: Mapping[str, Any]) -> str:
            self.paused = False
            return "physics running"

        def status(args: Mapping[str, Any]) -> str:
            bx, by = self.ball_position()
            x, y, heading = self.robot_pose()
            return (f"time {self.time_ns * 1e-9:.3f} s{' (paused)' if self.paused else ''}; robot x={x:.0f} y={y:.0f} mm "
                    f"rotation {heading:.3f} rad, torso height {self.torso_height():.0f} mm, {self.posture()}; ball x={bx:.0f} y={by:.0f} mm"
                    + (f"; score {self.score[0]}:{self.score[1]} (the robot's team first)" if any(self.score) else ""))

        def button(args: Mapping[str, Any]) -> str:
            self.button_until_ns = self.time_ns + int(BUTTON_SECONDS * 1e9)
            return f"chest button pressed for {BUTTON_SECONDS} s"

        return {
            **self.network.commands(),
            "sim:button": ("press the chest button once (the rules' manual mode steps the game state without a GameController)", button),
            "sim:move_ball": ("put the ball at -x X -y Y (mm, field), rolling at -vx VX -vy VY (mm/s) if given", ball),
            "sim:move_robot": ("put the robot at -x X -y Y (mm, field) -rotation R (rad) [-lying front|back] [-reset on: "
                               "the localization starts anew at this pose]", robot),
            "sim:push": ("push the torso for 0.1 s with -x FX -y FY (N, field frame)", push),
            "sim:pause": ("stop the physics (the loops go on)", pause),
            "sim:resume": ("run the physics again", resume),
            "sim:status": ("where the robot and the ball are (ground truth)", status),
        }
