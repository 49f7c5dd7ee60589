"""The MuJoCo platform: the simulated NAO on an SPL field, rendered headless with EGL (or OSMesa)."""

from __future__ import annotations

import ctypes.util
import os
import sys
from typing import Any

import numpy as np

from tafel.core.runtime.platform import PlatformError
from tafel.platforms.robot_model import SERVO_GAIN, VIEWER_ONLY_GROUP, fsr_sites, joint_motor, mjcf, mjcf_assets, torque_range
from tafel.platforms.simulated import TIMESTEP, SimulatedRobotPlatform
from tafel.representations.field import BALL_RADIUS
from tafel.representations.motion import JOINT_NAMES

SERVO_DAMPING_RATIO = 0.02  # kv = ratio * kp (s): damps the servos without making them sluggish


def choose_gl_backend() -> str:
    """Headless rendering: EGL where libEGL exists, else OSMesa; MUJOCO_GL set by the user wins."""
    if os.environ.get("MUJOCO_GL"):
        return os.environ["MUJOCO_GL"]
    backend = "egl" if ctypes.util.find_library("EGL") else "osmesa" if ctypes.util.find_library("OSMesa") else "egl"
    os.environ["MUJOCO_GL"] = backend
    return backend


GL_BACKEND = choose_gl_backend()
import mujoco  # noqa: E402 - MUJOCO_GL must be set before mujoco is imported


class MujocoRobot:
    """One robot of a MuJoCo model, found by its names' prefix (``robot_model.robot_prefix``): its joints,
    servos, sensors, torso and cameras. The one-robot platform has one; a match's world has several."""

    def __init__(self, model: Any, prefix: str = "") -> None:
        self.model, self.prefix = model, prefix
        joints = [model.joint(prefix + name).id for name in JOINT_NAMES]
        self.joint_qpos = np.array([model.jnt_qposadr[j] for j in joints])
        self.joint_dof = np.array([model.jnt_dofadr[j] for j in joints])
        self.actuator = np.array([model.actuator(prefix + name).id for name in JOINT_NAMES])
        self.stall_torque, self.no_load_speed = np.array([joint_motor(name) for name in JOINT_NAMES]).T
        self.sensor = {name: model.sensor(prefix + name).adr[0] for name in ("accelerometer", "gyroscope")}
        self.fsr = [model.sensor(prefix + name).adr[0] for side in "LR" for name, _ in fsr_sites(side)]
        self.torso = model.body(prefix + "torso").id
        self.root_qpos = model.jnt_qposadr[model.joint(prefix + "root").id]
        self.root_qvel = model.jnt_dofadr[model.joint(prefix + "root").id]
        self.set_gains(np.zeros(len(JOINT_NAMES)))

    def camera(self, name: str) -> str:
        """The MuJoCo name of the ``top`` or ``bottom`` camera."""
        return f"{self.prefix}{name}_camera"

    def camera_rotation(self, data: Any, name: str) -> np.ndarray:
        """The ``top`` or ``bottom`` camera's orientation (3x3; columns forward, left, up in the world).
        MuJoCo's camera axes are right, up and back."""
        right, up, back = data.cam_xmat[self.model.camera(self.camera(name)).id].reshape(3, 3).T
        return np.column_stack([-back, -right, up])

    def joint_angles(self, data: Any) -> np.ndarray:
        return data.qpos[self.joint_qpos].copy()

    def joint_torques(self, data: Any) -> np.ndarray:
        return data.actuator_force[self.actuator].copy()

    def imu(self, data: Any) -> tuple[np.ndarray, np.ndarray]:
        acc, gyro = self.sensor["accelerometer"], self.sensor["gyroscope"]
        return data.sensordata[acc : acc + 3].copy(), data.sensordata[gyro : gyro + 3].copy()

    def foot_forces(self, data: Any) -> np.ndarray:
        return data.sensordata[self.fsr].copy()

    def torso_pose(self, data: Any) -> tuple[np.ndarray, np.ndarray]:
        return data.xpos[self.torso].copy(), data.xmat[self.torso].reshape(3, 3).copy()

    def drive(self, data: Any, targets: np.ndarray, stiffness: np.ndarray) -> None:
        if not np.array_equal(stiffness, self._gains_for):
            self.set_gains(stiffness)
        data.ctrl[self.actuator] = targets

    def set_gains(self, stiffness: np.ndarray) -> None:
        """Stiffness 0..1 per joint -> servo gains (0: the joint is limp)."""
        self._gains_for = stiffness.copy()
        kp = stiffness * SERVO_GAIN
        self.model.actuator_gainprm[self.actuator, 0] = kp
        self.model.actuator_biasprm[self.actuator, 1] = -kp
        self.model.actuator_biasprm[self.actuator, 2] = -kp * SERVO_DAMPING_RATIO


    def place(self, data: Any, position_m: np.ndarray, quaternion_wxyz: np.ndarray) -> None:
        """Put the torso at ``position_m`` turned by ``quaternion_wxyz``, at rest (call mj_forward after)."""
        q, v = self.root_qpos, self.root_qvel
        data.qpos[q : q + 3] = position_m
        data.qpos[q + 3 : q + 7] = quaternion_wxyz
        data.qvel[v : v + 6] = 0.0


class TorqueLimits:
    """The motors' torque falls with their speed: every robot's limits for the next physics step, set
    at once (call before every step; one array operation for all robots costs what one robot's does)."""

    def __init__(self, model: Any, robots: list[MujocoRobot]) -> None:
        self.model = model
        self.dof = np.concatenate([r.joint_dof for r in robots])
        self.actuator = np.concatenate([r.actuator for r in robots])
        self.stall_torque = np.concatenate([r.stall_torque for r in robots])
        self.no_load_speed = np.concatenate([r.no_load_speed for r in robots])
        self._limits = np.empty((len(self.actuator), 2))

    def apply(self, data: Any) -> None:
        self._limits[:, 0], self._limits[:, 1] = torque_range(data.qvel[self.dof], self.stall_torque, self.no_load_speed)
        self.model.actuator_forcerange[self.actuator] = self._limits


class MujocoBall:
    """The ball of a MuJoCo model (its free joint and body are named ``ball``)."""

    def __init__(self, model: Any) -> None:
        self.model = model
        self.qpos = model.jnt_qposadr[model.joint("ball").id]
        self.qvel = model.jnt_dofadr[model.joint("ball").id]
        self.body = model.body("ball").id

    def position(self, data: Any) -> tuple[float, float]:
        """On the field (mm)."""
        x, y = data.qpos[self.qpos : self.qpos + 2] * 1000.0
        return float(x), float(y)

    def velocity(self, data: Any) -> tuple[float, float]:
        """Over the ground (mm/s)."""
        vx, vy = data.qvel[self.qvel : self.qvel + 2] * 1000.0
        return float(vx), float(vy)

    def place(self, data: Any, x_mm: float, y_mm: float, velocity_mm_s: tuple[float, float] = (0.0, 0.0)) -> None:
        """Put it at (x, y) on the ground, still or rolling (spinning as it rolls) at ``velocity_mm_s``."""
        vx, vy = velocity_mm_s[0] / 1000.0, velocity_mm_s[1] / 1000.0
        data.qpos[self.qpos : self.qpos + 7] = [x_mm / 1000.0, y_mm / 1000.0, 0.05, 1.0, 0.0, 0.0, 0.0]
        data.qvel[self.qvel : self.qvel + 6] = [vx, vy, 0.0, -vy / (BALL_RADIUS / 1000.0), vx / (BALL_RADIUS / 1000.0), 0.0]
        mujoco.mj_forward(self.model, data)


def set_render_flags(renderer: Any, shadows: bool) -> None:
    """How a camera renders the scene: the hall's shadows as the realism level says, no mirror-like floor."""
    renderer.scene.flags[mujoco.mjtRndFlag.mjRND_SHADOW] = int(shadows)
    renderer.scene.flags[mujoco.mjtRndFlag.mjRND_REFLECTION] = 0


def offscreen_size(sizes: dict[str, tuple[int, int]]) -> tuple[int, int]:
    """The model's offscreen buffer (px): room for the largest camera image, and at least 640x480."""
    return max(640, *(w for w, _ in sizes.values())), max(480, *(h for _, h in sizes.values()))


def close_renderers(renderers: dict[str, Any]) -> None:
    """Close MuJoCo renderers; closing must never raise (it also runs after errors)."""
    for renderer in renderers.values():
        try:
            renderer.close()
        except Exception:  # noqa: BLE001 - the GL stack raises several kinds
            pass
    renderers.clear()


class MujocoCameras:
    """One robot's ``top`` and ``bottom`` cameras, rendered headless from a MuJoCo model (a renderer each)."""

    def __init__(self, model: Any, robot: MujocoRobot, sizes: dict[str, tuple[int, int]], shadows: bool | None) -> None:
        """``sizes``: camera -> (width, height) px; ``shadows`` None keeps MuJoCo's own render flags."""
        self.model, self.robot = model, robot
        self.renderers: dict[str, Any] = {}
        try:
            for camera in ("top", "bottom"):
                width, height = sizes[camera]
                renderer = mujoco.Renderer(model, height, width)
                if shadows is not None:
                    set_render_flags(renderer, shadows)
                self.renderers[camera] = renderer
        except Exception as exc:  # noqa: BLE001 - the GL stack raises several kinds
            self.close()
            raise PlatformError(
                f"MuJoCo cannot render headless with MUJOCO_GL={GL_BACKEND} ({exc}); install EGL (Debian: libegl1 "
                "libegl-mesa0) or OSMesa (libosmesa6) and set MUJOCO_GL=egl or osmesa, or run with --cameras off"
            ) from None

    def render(self, data: Any, camera: str) -> np.ndarray:
        """``camera``'s image of ``data`` as its kinematics last left it (height x width x 3 RGB uint8)."""
        renderer = self.renderers[camera]
        renderer.update_scene(data, camera=self.robot.camera(camera))
        return renderer.render().copy()

    def mask(self, data: Any, camera: str, body: int) -> np.ndarray:
        """Which pixels of ``camera``'s image show ``body`` (height x width bool), from the segmentation render."""
        renderer = self.renderers[camera]
        renderer.enable_segmentation_rendering()
        try:
            renderer.update_scene(data, camera=self.robot.camera(camera))
            segments = renderer.render()
        finally:
            renderer.disable_segmentation_rendering()
        geoms = [g for g in range(self.model.ngeom) if self.model.geom_bodyid[g] == body]
        return (segments[:, :, 1] == mujoco.mjtObj.mjOBJ_GEOM) & np.isin(segments[:, :, 0], geoms)

    def close(self) -> None:
        close_renderers(self.renderers)


class MujocoDrawing:
    """Another engine's world drawn by MuJoCo's renderer: the same field, hall, robot and ball built from
    the same description (``robot_model.mjcf``), posed from the other engine's state before each image.
    PyBullet's CPU renderer takes about 15 ms of CPU for a 320x240 image and 55 ms for 640x480; this
    one 1.5 and 3 ms here (EGL on Mesa), so a PyBullet simulation with cameras can keep real time."""

    def __init__(self, sizes: dict[str, tuple[int, int]], ball_color: str, look: Any, shadows: bool) -> None:
        xml = mjcf(offscreen=offscreen_size(sizes), ball_color=ball_color, look=look, shadows=shadows)
        self.model = mujoco.MjModel.from_xml_string(xml, mjcf_assets(ball_color, look))
        self.data = mujoco.MjData(self.model)
        self.robot = MujocoRobot(self.model)
        self.ball = MujocoBall(self.model)
        self.cameras = MujocoCameras(self.model, self.robot, sizes, shadows)

    def joint_address(self, name: str) -> int | None:
        """Where joint ``name``'s angle sits in ``qpos`` (None: this model has no such joint)."""
        try:
            return int(self.model.jnt_qposadr[self.model.joint(name).id])
        except KeyError:
            return None

    def pose(self, torso_position_m: np.ndarray, torso_wxyz: np.ndarray, angles: dict[int, float],
             ball_position_m: np.ndarray, ball_wxyz: np.ndarray) -> None:
        """Put what moves where the other engine has it: the torso's frame, joint angles (rad) by ``qpos``
        address (``joint_address``), the ball's centre and turn."""
        qpos, root, ball = self.data.qpos, self.robot.root_qpos, self.ball.qpos
        qpos[root : root + 3], qpos[root + 3 : root + 7] = torso_position_m, torso_wxyz
        qpos[ball : ball + 3], qpos[ball + 3 : ball + 7] = ball_position_m, ball_wxyz
        for address, angle in angles.items():
            qpos[address] = angle
        mujoco.mj_kinematics(self.model, self.data)
        mujoco.mj_camlight(self.model, self.data)

    def render(self, camera: str) -> np.ndarray:
        return self.cameras.render(self.data, camera)

    def ball_mask(self, camera: str) -> np.ndarray:
        return self.cameras.mask(self.data, camera, self.ball.body)

    def close(self) -> None:
        self.cameras.close()


class MujocoPlatform(SimulatedRobotPlatform):
    name = "mujoco"
    engine = "MuJoCo"
    description = "MuJoCo physics: NAO V6-like robot, SPL field and ball, rendered cameras"

    def __init__(self, options: dict[str, Any] | None = None) -> None:
        super().__init__(options)
        self.model: Any = None
        self.data: Any = None
        self.renderers: MujocoCameras | None = None
        self.viewer: Any = None

    def build(self, contexts: frozenset[str], viewer: bool) -> None:
        xml = mjcf(offscreen=offscreen_size(self.sizes), timestep=TIMESTEP, ball_color=self.ball_color,
                   look=self.scene_look, shadows=self.shadows)
        self.model = mujoco.MjModel.from_xml_string(xml, mjcf_assets(self.ball_color, self.scene_look))
        self.data = mujoco.MjData(self.model)
        self.robot = MujocoRobot(self.model)
        self.torque_limits = TorqueLimits(self.model, [self.robot])
        self.ball = MujocoBall(self.model)
        self.move_ball(*self.initial_ball, self.initial_ball_velocity)
        if self.cameras and "cognition" in contexts:
            self._open_renderers()
        if viewer:
            self._open_viewer()

    def _open_renderers(self) -> None:
        try:
            self.renderers = MujocoCameras(self.model, self.robot, self.sizes, self.shadows)
        except PlatformError:
            self.stop()
            raise

    def _open_viewer(self) -> None:
        try:
            import mujoco.viewer

            self.viewer = mujoco.viewer.launch_passive(self.model, self.data)
            with self.viewer.lock():
                self.viewer.opt.geomgroup[VIEWER_ONLY_GROUP] = 1  # the goal nets: the viewer shows them, the cameras do not
        except Exception as exc:  # noqa: BLE001 - no GLFW, no display server, ...
            print(f"mujoco: cannot open the viewer ({exc}); running headless", file=sys.stderr)

    def stop(self) -> None:
        super().stop()
        if self.renderers is not None:
            self.renderers.close()
            self.renderers = None
        if self.viewer is not None:
            try:
                self.viewer.close()
            except Exception:  # noqa: BLE001
                pass
            self.viewer = None

    # ---------------------------------------------------------------------------------- engine

    def joint_angles(self) -> np.ndarray:
        return self.robot.joint_angles(self.data)

    def joint_torques(self) -> np.ndarray:
        return self.robot.joint_torques(self.data)

    def imu(self) -> tuple[np.ndarray, np.ndarray]:
        return self.robot.imu(self.data)

    def foot_forces(self) -> np.ndarray:
        return self.robot.foot_forces(self.data)

    def render(self, camera: str) -> np.ndarray:
        return self.open_cameras().render(self.data, camera)

    def open_cameras(self) -> MujocoCameras:
        if self.renderers is None:
            raise PlatformError("the cameras are off (--cameras off): nothing renders")
        return self.renderers

    def camera_rotation(self, camera: str) -> np.ndarray:
        return self.robot.camera_rotation(self.data, camera)

    def pose_joints(self, angles: np.ndarray) -> None:
        self.data.qpos[self.robot.joint_qpos] = angles
        self.data.qvel[self.robot.joint_dof] = 0.0
        mujoco.mj_forward(self.model, self.data)

    def ball_mask(self, camera: str) -> np.ndarray:
        return self.open_cameras().mask(self.data, camera, self.ball.body)

    def world_state(self) -> np.ndarray:
        return self.data.qpos.copy()

    def render_state(self, state: np.ndarray, cameras: tuple[str, ...]) -> dict[str, np.ndarray]:
        now = self.data.qpos.copy()
        self.data.qpos[:] = state
        mujoco.mj_kinematics(self.model, self.data)
        mujoco.mj_camlight(self.model, self.data)
        images = {camera: self.render(camera) for camera in cameras}
        # back to the present; the next step recomputes everything else from qpos and qvel
        self.data.qpos[:] = now
        mujoco.mj_kinematics(self.model, self.data)
        mujoco.mj_camlight(self.model, self.data)
        return images

    def drive(self, targets: np.ndarray, stiffness: np.ndarray) -> None:
        self.robot.drive(self.data, targets, stiffness)

    def torso_pose(self) -> tuple[np.ndarray, np.ndarray]:
        return self.robot.torso_pose(self.data)

    def ball_position(self) -> tuple[float, float]:
        return self.ball.position(self.data)

    def move_ball(self, x_mm: float, y_mm: float, velocity_mm_s: tuple[float, float] = (0.0, 0.0)) -> None:
        self.ball.place(self.data, x_mm, y_mm, velocity_mm_s)

    def place_robot(self, position_m: np.ndarray, quaternion_wxyz: np.ndarray) -> None:
        self.robot.place(self.data, position_m, quaternion_wxyz)
        mujoco.mj_forward(self.model, self.data)

    def apply_push(self, force_n: np.ndarray) -> None:
        self.data.xfrc_applied[self.robot.torso, :3] = force_n

    def step_physics(self, steps: int) -> None:
        for _ in range(steps):
            self.torque_limits.apply(self.data)
            mujoco.mj_step(self.model, self.data)
        self.data.xfrc_applied[self.robot.torso, :3] = 0.0  # a push lasts the steps it was applied for
        if self.viewer is not None and self.viewer.is_running():
            self.viewer.sync()
