"""The MuJoCo platform: a NAO-like robot on an SPL field, in lockstep with the runtime.

Motion gets joint positions, the IMU and foot pressure every 10 ms and drives position servos whose
gains follow the commanded stiffness; cognition gets both camera images, rendered headless (EGL, or
OSMesa where EGL is missing) at its own rate. Physics runs in fixed 2 ms steps, so a run is
deterministic for a given seed (which only seeds the small sensor noise).
"""

from __future__ import annotations

import argparse
import ctypes.util
import math
import os
import sys
from collections.abc import Mapping
from typing import Any, ClassVar

import numpy as np

from core.manager import Blackboard
from core.platform import Platform, PlatformError, PlatformOptionError
from platforms.robot_model import SERVO_GAIN, STANDING_HEIGHT, fsr_sites, mjcf
from representations.infrastructure import FrameInfo
from representations.motion import JOINT_NAMES, FsrData, InertialSensorData, JointCommand, JointSensorData
from representations.nao import HORIZONTAL_FOV, VERTICAL_FOV
from representations.perception import CameraImageBottom, CameraImageTop

GRAVITY = 9.81
SERVO_DAMPING_RATIO = 0.02  # kv = ratio * kp (s): damps the servos without making them sluggish
TIMESTEP = 0.002


def choose_gl_backend() -> str:
    """Headless rendering: EGL where libEGL exists, else OSMesa; MUJOCO_GL set by the user wins."""
    if os.environ.get("MUJOCO_GL"):
        return os.environ["MUJOCO_GL"]
    backend = "egl" if ctypes.util.find_library("EGL") else "osmesa" if ctypes.util.find_library("OSMesa") else "egl"
    os.environ["MUJOCO_GL"] = backend
    return backend


GL_BACKEND = choose_gl_backend()
import mujoco  # noqa: E402 - MUJOCO_GL must be set before mujoco is imported


def parse_pair(text: str, what: str) -> tuple[float, float]:
    try:
        x, y = (float(v) for v in str(text).split(","))
    except ValueError:
        raise PlatformOptionError(f"{what} takes X,Y in mm, e.g. 1000,300; got {text!r}") from None
    return x, y


def parse_resolution(text: str) -> tuple[int, int]:
    try:
        width, height = (int(v) for v in str(text).lower().split("x"))
    except ValueError:
        raise PlatformOptionError(f"--resolution takes WIDTHxHEIGHT, e.g. 320x240; got {text!r}") from None
    if not (16 <= width <= 4096 and 16 <= height <= 4096):
        raise PlatformOptionError(f"--resolution {text} is out of range (16..4096 pixels a side)")
    return width, height


class MujocoPlatform(Platform):
    name = "mujoco"
    description = "MuJoCo physics: NAO V6-like robot, SPL field, orange ball, rendered cameras"
    clock = "simulated"
    concurrent = False  # one world: images and joints must come from the same simulation
    provides: ClassVar[Mapping[str, tuple[type, ...]]] = {
        "motion": (FrameInfo, JointSensorData, InertialSensorData, FsrData),
        "cognition": (FrameInfo, CameraImageTop, CameraImageBottom),
    }
    consumes: ClassVar[Mapping[str, tuple[type, ...]]] = {"motion": (JointCommand,)}

    def __init__(self, options: Mapping[str, Any] | None = None) -> None:
        super().__init__(options)
        self.seed = int(self.options.get("seed") or 0)
        self.cameras = str(self.options.get("cameras", "on")).lower() not in ("off", "false", "0", "no")
        self.width, self.height = parse_resolution(self.options.get("resolution") or "320x240")
        self.initial_ball = parse_pair(self.options.get("ball") or "1000,300", "--ball")
        self.viewer_requested = bool(self.options.get("viewer"))
        self.model: Any = None
        self.data: Any = None
        self.renderers: dict[str, Any] = {}
        self.viewer: Any = None
        self.paused = False
        self.time_ns = 0
        self.last_steps = 0  # physics steps of the last advance (benchmarks read it)
        self.rng = np.random.default_rng(self.seed)

    @classmethod
    def add_arguments(cls, parser: argparse.ArgumentParser) -> None:
        parser.add_argument("--seed", type=int, default=0, help="mujoco: seed of the sensor noise")
        parser.add_argument("--cameras", choices=["on", "off"], default="on", help="mujoco: render the cameras")
        parser.add_argument("--resolution", default="320x240", help="mujoco: camera image size WIDTHxHEIGHT")
        parser.add_argument("--ball", default="1000,300", help="mujoco: ball start X,Y in mm on the field")
        parser.add_argument("--viewer", action="store_true", help="mujoco: open the MuJoCo viewer (needs a display)")

    # ---------------------------------------------------------------------------------- set-up
    def start(self, contexts: frozenset[str]) -> None:
        self.model = mujoco.MjModel.from_xml_string(mjcf(offscreen=(max(self.width, 640), max(self.height, 480)), timestep=TIMESTEP))
        self.data = mujoco.MjData(self.model)
        self._index()
        self.move_ball(*self.initial_ball)
        mujoco.mj_forward(self.model, self.data)
        if self.cameras and "cognition" in contexts:
            self._open_renderers()
        if self.viewer_requested:
            self._open_viewer()

    def _index(self) -> None:
        model = self.model
        self.joint_qpos = np.array([model.jnt_qposadr[model.joint(name).id] for name in JOINT_NAMES])
        self.joint_qvel = np.array([model.jnt_dofadr[model.joint(name).id] for name in JOINT_NAMES])
        self.actuator = np.array([model.actuator(name).id for name in JOINT_NAMES])
        self.stiffness = np.zeros(len(JOINT_NAMES))
        self.set_gains(self.stiffness)
        self.sensor = {name: (model.sensor(name).adr[0], model.sensor(name).dim[0]) for name in ("accelerometer", "gyroscope")}
        self.fsr = [model.sensor(name).adr[0] for side in "LR" for name, _ in fsr_sites(side)]
        self.torso = model.body("torso").id
        self.ball_qpos = model.jnt_qposadr[model.joint("ball").id]
        self.ball_qvel = model.jnt_dofadr[model.joint("ball").id]
        self.root_qpos = model.jnt_qposadr[model.joint("root").id]
        self.root_qvel = model.jnt_dofadr[model.joint("root").id]

    def _open_renderers(self) -> None:
        try:
            for camera in ("top", "bottom"):
                renderer = mujoco.Renderer(self.model, self.height, self.width)
                renderer.scene.flags[mujoco.mjtRndFlag.mjRND_SHADOW] = 0
                renderer.scene.flags[mujoco.mjtRndFlag.mjRND_REFLECTION] = 0
                self.renderers[camera] = renderer
        except Exception as exc:  # noqa: BLE001 - the GL stack raises several kinds
            self.stop()
            raise PlatformError(
                f"MuJoCo cannot render headless with MUJOCO_GL={GL_BACKEND} ({exc}); install EGL (Debian: libegl1 "
                "libegl-mesa0) or OSMesa (libosmesa6) and set MUJOCO_GL=egl or osmesa, or run with --cameras off"
            ) from None

    def _open_viewer(self) -> None:
        if not os.environ.get("DISPLAY") and not os.environ.get("WAYLAND_DISPLAY"):
            print("mujoco: --viewer needs a display (DISPLAY is not set); running headless", file=sys.stderr)
            return
        try:
            import mujoco.viewer

            self.viewer = mujoco.viewer.launch_passive(self.model, self.data)
        except Exception as exc:  # noqa: BLE001 - no GLFW, no display server, ...
            print(f"mujoco: cannot open the viewer ({exc}); running headless", file=sys.stderr)

    def stop(self) -> None:
        for renderer in self.renderers.values():
            try:
                renderer.close()
            except Exception:  # noqa: BLE001 - closing must never raise
                pass
        self.renderers = {}
        if self.viewer is not None:
            try:
                self.viewer.close()
            except Exception:  # noqa: BLE001
                pass
            self.viewer = None

    # ----------------------------------------------------------------------------------- world
    def advance(self, time_ns: int) -> None:
        steps = int(round((time_ns - self.time_ns) * 1e-9 / TIMESTEP))
        self.time_ns = time_ns
        self.last_steps = 0 if self.paused else max(steps, 0)
        if self.paused or steps <= 0:
            return
        for _ in range(steps):
            mujoco.mj_step(self.model, self.data)
        if self.viewer is not None and self.viewer.is_running():
            self.viewer.sync()

    def sense(self, context: str, blackboard: Blackboard, frame_number: int, time_ns: int) -> None:
        blackboard.set(FrameInfo(frame_number=frame_number, time_ns=time_ns))
        data = self.data
        if context == "motion":
            joints = blackboard[JointSensorData]
            joints.position = data.qpos[self.joint_qpos] + self.rng.normal(0.0, 0.0005, len(JOINT_NAMES))
            joints.stiffness = self.stiffness.copy()
            joints.current = np.abs(data.actuator_force[self.actuator]) / 10.0
            joints.temperature = np.full(len(JOINT_NAMES), 30.0)
            inertial = blackboard[InertialSensorData]
            adr, dim = self.sensor["accelerometer"]
            inertial.accelerometer = data.sensordata[adr : adr + dim].copy() + self.rng.normal(0.0, 0.02, 3)
            adr, dim = self.sensor["gyroscope"]
            inertial.gyroscope = data.sensordata[adr : adr + dim].copy() + self.rng.normal(0.0, 0.002, 3)
            inertial.angles = np.array(self.torso_angles())
            blackboard[FsrData].pressure = data.sensordata[self.fsr] / GRAVITY
        elif context == "cognition" and self.renderers:
            for camera, rep in (("top", CameraImageTop), ("bottom", CameraImageBottom)):
                renderer = self.renderers[camera]
                renderer.update_scene(data, camera=f"{camera}_camera")
                image = blackboard[rep]
                image.image = renderer.render().copy()
                image.horizontal_fov, image.vertical_fov = self.fov()

    def fov(self) -> tuple[float, float]:
        """(horizontal, vertical) field of view of the rendered images (rad)."""
        vertical = VERTICAL_FOV
        return 2 * math.atan(math.tan(vertical / 2) * self.width / self.height), vertical

    def act(self, context: str, blackboard: Blackboard) -> None:
        if context != "motion":
            return
        command = blackboard[JointCommand]
        stiffness = np.clip(np.asarray(command.stiffness, dtype=float), 0.0, 1.0)
        if not np.array_equal(stiffness, self.stiffness):
            self.set_gains(stiffness)
        self.data.ctrl[self.actuator] = command.position

    def set_gains(self, stiffness: np.ndarray) -> None:
        """Stiffness 0..1 per joint -> servo gains (0: the joint is limp)."""
        self.stiffness = stiffness.copy()
        kp = stiffness * SERVO_GAIN
        self.model.actuator_gainprm[self.actuator, 0] = kp
        self.model.actuator_biasprm[self.actuator, 1] = -kp
        self.model.actuator_biasprm[self.actuator, 2] = -kp * SERVO_DAMPING_RATIO

    # ------------------------------------------------------------------------- ground truth
    def torso_angles(self) -> tuple[float, float]:
        """Torso roll and pitch relative to the ground (rad)."""
        matrix = self.data.xmat[self.torso].reshape(3, 3)
        pitch = math.asin(max(-1.0, min(1.0, -matrix[2, 0])))
        roll = math.atan2(matrix[2, 1], matrix[2, 2])
        return roll, pitch

    def torso_height(self) -> float:
        """mm above the ground."""
        return float(self.data.xpos[self.torso][2]) * 1000.0

    def robot_pose(self) -> tuple[float, float, float]:
        """The torso on the field: x, y (mm) and heading (rad)."""
        matrix = self.data.xmat[self.torso].reshape(3, 3)
        x, y, _ = self.data.xpos[self.torso] * 1000.0
        return float(x), float(y), math.atan2(matrix[1, 0], matrix[0, 0])

    def ball_position(self) -> tuple[float, float]:
        """The ball on the field (mm)."""
        x, y = self.data.qpos[self.ball_qpos : self.ball_qpos + 2] * 1000.0
        return float(x), float(y)

    def ball_in_robot_frame(self) -> tuple[float, float]:
        """The ball relative to the robot (mm): the frame between the feet, turned with the torso."""
        bx, by = self.ball_position()
        x, y, heading = self.robot_pose()
        dx, dy = bx - x, by - y
        c, s = math.cos(-heading), math.sin(-heading)
        return dx * c - dy * s, dx * s + dy * c

    # ------------------------------------------------------------------------- manipulation
    def move_ball(self, x_mm: float, y_mm: float) -> None:
        """Put the ball at rest at (x, y) on the field."""
        q, v = self.ball_qpos, self.ball_qvel
        self.data.qpos[q : q + 7] = [x_mm / 1000.0, y_mm / 1000.0, 0.05, 1.0, 0.0, 0.0, 0.0]
        self.data.qvel[v : v + 6] = 0.0
        mujoco.mj_forward(self.model, self.data)

    def move_robot(self, x_mm: float, y_mm: float, heading: float = 0.0) -> None:
        """Put the robot upright at (x, y) on the field, facing ``heading`` (rad), legs as they are."""
        q, v = self.root_qpos, self.root_qvel
        height = self.data.qpos[q + 2] if self.data.qpos[q + 2] > 0.2 else STANDING_HEIGHT + 0.002
        self.data.qpos[q : q + 7] = [x_mm / 1000.0, y_mm / 1000.0, height, math.cos(heading / 2), 0.0, 0.0, math.sin(heading / 2)]
        self.data.qvel[v : v + 6] = 0.0
        mujoco.mj_forward(self.model, self.data)

    def commands(self) -> Mapping[str, tuple[str, Any]]:
        def ball(args: Mapping[str, Any]) -> str:
            x, y = float(args.get("x", 0)), float(args.get("y", 0))
            self.move_ball(x, y)
            return f"ball at x={x:.0f} y={y:.0f} mm"

        def robot(args: Mapping[str, Any]) -> str:
            x, y, heading = float(args.get("x", 0)), float(args.get("y", 0)), float(args.get("rotation", 0))
            self.move_robot(x, y, heading)
            return f"robot at x={x:.0f} y={y:.0f} mm, rotation {heading:.3f} rad"

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
                    f"rotation {heading:.3f} rad, torso height {self.torso_height():.0f} mm; ball x={bx:.0f} y={by:.0f} mm")

        return {
            "sim:move_ball": ("put the ball at -x X -y Y (mm, field)", ball),
            "sim:move_robot": ("put the robot at -x X -y Y (mm, field) -rotation R (rad)", robot),
            "sim:pause": ("stop the physics (the loops go on)", pause),
            "sim:resume": ("run the physics again", resume),
            "sim:status": ("where the robot and the ball are (ground truth)", status),
        }
