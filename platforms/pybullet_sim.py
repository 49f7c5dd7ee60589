"""The PyBullet platform: the same robot, field and ball as MuJoCo, from the same description.

The robot is the URDF that ``platforms.robot_model`` generates from ``representations.nao``; the field
is built from the same ``field_parts``.

The cameras (``--renderer``): by default MuJoCo's renderer draws PyBullet's world (``MujocoDrawing``: the
same scene from the same description, posed from PyBullet's state before each image), at about 1.5 ms
of CPU per 320x240 image. ``--renderer pybullet`` keeps PyBullet's own CPU renderer (TinyRenderer, no
OpenGL at all: where EGL and OSMesa are missing, or to test perception on a second renderer's look);
``auto`` (the default) is MuJoCo where it can render headless, else PyBullet's.

PyBullet's renderer is most of a simulated second's work (about 15 ms of CPU per 320x240 image, 60 images a
second), and PyBullet holds the GIL while it renders, so a thread cannot help: with cameras on and a
spare core (more than one, and the last minute's load leaves one idle), a render worker
(``RenderWorker``, a process with a copy of the world that only renders) draws the top camera while
this process draws the bottom one. Only the poses of what moves (the robot's base and joints, the
ball) travel to it, a few hundred bytes a frame; its image comes back as raw bytes. The images are
the same as when one process renders both (``--render-worker off``). PyBullet's EGL renderer is no
help here: on Mesa's llvmpipe (no GPU) it is slower than the CPU renderer and loses
the mesh shapes (the ball's texture, the posts).
"""

from __future__ import annotations

import ctypes
import math
import multiprocessing
import os
import sys
import tempfile
from multiprocessing.connection import Connection
from typing import Any

import numpy as np

from tafel.core.runtime.platform import PlatformError, PlatformOptionError
from tafel.platforms.field_world import (
    NET_FRICTION,
    FieldPart,
    SceneLook,
    ball_mesh,
    ball_texture_png,
    carpet_texture_png,
    cylinder_mesh,
    field_parts,
)
from tafel.platforms.mujoco_sim import MujocoDrawing
from tafel.platforms.robot_model import BALL_FRICTION, STANDING_HEIGHT, fsr_sites, joint_motor, sun_direction, urdf
from tafel.platforms.simulated import TIMESTEP, SimulatedRobotPlatform
from tafel.representations.field import BALL_RADIUS
from tafel.representations.motion import JOINT_NAMES
from tafel.representations.nao import ACCELEROMETER_POSITION, CAMERAS, COUPLED_JOINTS, SOLE_BACK, SOLE_FRONT, VERTICAL_FOV


def _import_quietly() -> Any:
    """``import pybullet`` without the ``pybullet build time: ...`` line its C code prints at import,
    which every command that loads the platform would otherwise show (it writes to the file
    descriptors themselves, so ``sys.stderr`` cannot catch it: both are pointed at /dev/null meanwhile)."""
    for stream in (sys.stdout, sys.stderr):
        stream.flush()
    saved = [os.dup(fd) for fd in (1, 2)]
    try:
        with open(os.devnull, "wb") as null:
            for fd in (1, 2):
                os.dup2(null.fileno(), fd)
            import pybullet as module

            ctypes.CDLL(None).fflush(None)  # whatever C buffered goes to /dev/null, not out after the restore
    finally:
        for fd, copy in zip((1, 2), saved):
            os.dup2(copy, fd)
            os.close(copy)
    return module


pybullet = _import_quietly()


POSITION_GAIN = 0.1  # PyBullet's position motors: share of the position error corrected per step
ROBOT_RGBA = (0.87, 0.87, 0.9, 1.0)
M = 0.001
#: m of carpet one copy of its texture covers (``field_world.carpet_texture`` paints one metre)
CARPET_TILE = 1.0
#: how much darker the carpet's darker strips are, as a share of ``SceneLook.texture`` (mild 2.5 %, full 6 %)
STRIPE_SHADE = 0.5


def _quaternion_yaw(yaw: float) -> tuple[float, float, float, float]:
    return (0.0, 0.0, math.sin(yaw / 2), math.cos(yaw / 2))


def _matrix(quaternion: tuple[float, ...]) -> np.ndarray:
    return np.array(pybullet.getMatrixFromQuaternion(quaternion)).reshape(3, 3)


def carpet_mesh(half_x: float, half_y: float, strips: int | None = None, tile: float = CARPET_TILE) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The carpet's top (half extents in m, at z = 0) as squares of ``tile`` m, each with the whole texture
    on it (one metre of ``carpet_texture``): vertices, texture coordinates and triangles (counter-clockwise
    from above). ``strips`` 0 or 1: only every other strip across the field (those whose index along x
    has that parity), for the mowing stripes; None: all. Small squares, not two triangles: the CPU
    renderer's texture follows them without wrapping coordinates, and none reaches far behind the camera."""
    xs = np.append(np.arange(-half_x, half_x, tile), half_x)
    ys = np.append(np.arange(-half_y, half_y, tile), half_y)
    vertices: list[tuple[float, float, float]] = []
    uvs: list[tuple[float, float]] = []
    triangles: list[tuple[int, int, int]] = []
    for strip, (x0, x1) in enumerate(zip(xs[:-1], xs[1:])):
        if strips is not None and strip % 2 != strips:
            continue
        for y0, y1 in zip(ys[:-1], ys[1:]):
            if x1 - x0 < 1e-9 or y1 - y0 < 1e-9:
                continue
            k = len(vertices)
            u, v = (x1 - x0) / tile, (y1 - y0) / tile
            vertices += [(x0, y0, 0.0), (x1, y0, 0.0), (x1, y1, 0.0), (x0, y1, 0.0)]
            uvs += [(0.0, 0.0), (u, 0.0), (u, v), (0.0, v)]
            triangles += [(k, k + 1, k + 2), (k, k + 2, k + 3)]
    return np.array(vertices), np.array(uvs), np.array(triangles, dtype=np.int64)


def stripe_shade(look: SceneLook) -> tuple[int, float]:
    """Which strips of the carpet (parity along x) look darker, and by what factor: a seeded phase, and
    half the texture's strength (a pile laid or brushed the other way)."""
    return int(np.random.default_rng([look.seed, 67]).integers(2)), 1.0 - STRIPE_SHADE * look.texture


#: s a render worker may take to build its world, and to answer one image, before this process renders alone
WORKER_START_S = 60.0
WORKER_IMAGE_S = 10.0


def _serve_renders(connection: Connection, options: dict[str, Any]) -> None:
    """A render worker's life: build the world as the platform does, then for each (state, camera) pose
    what moves and send the camera's image back as raw bytes, until None or the pipe closes."""
    platform = PybulletPlatform({**options, "render_worker": "off", "renderer": "pybullet", "viewer": False})
    platform.build(frozenset(), viewer=False)
    connection.send("ready")
    try:
        while True:
            message = connection.recv()
            if message is None:
                break
            state, camera = message
            platform.set_moving_state(state)
            connection.send_bytes(memoryview(np.ascontiguousarray(platform.render(camera))).cast("B"))
    except (EOFError, OSError, KeyboardInterrupt):
        pass
    finally:
        platform.stop()


class RenderWorker:
    """A process with a copy of the world that renders one camera while the simulation renders the other.

    ``request`` hands it the poses of what moves and the camera; ``image`` waits for the picture. Any
    failure (it died, it is slow to answer) raises ``PlatformError``; the platform then renders alone."""

    def __init__(self, options: dict[str, Any], size: tuple[int, int]) -> None:
        """``size``: (width, height) px of the camera it draws."""
        width, height = size
        context = multiprocessing.get_context("spawn")  # a fork would share this process's PyBullet client
        self.connection, child = context.Pipe()
        self.process = context.Process(target=_serve_renders, args=(child, options), name="pybullet-render", daemon=True)
        self.process.start()
        child.close()
        self.shape = (height, width, 3)
        self.buffer = bytearray(height * width * 3)
        if not self.connection.poll(WORKER_START_S) or self.connection.recv() != "ready":
            self.close()
            raise PlatformError("the PyBullet render worker did not start")

    def request(self, state: tuple[Any, ...], camera: str) -> None:
        try:
            self.connection.send((state, camera))
        except (OSError, ValueError) as exc:
            raise PlatformError(f"the PyBullet render worker is gone ({exc})") from None

    def image(self) -> np.ndarray:
        try:
            if not self.connection.poll(WORKER_IMAGE_S):
                raise PlatformError(f"the PyBullet render worker gave no image within {WORKER_IMAGE_S:g} s")
            size = self.connection.recv_bytes_into(self.buffer)
        except (EOFError, OSError) as exc:
            raise PlatformError(f"the PyBullet render worker is gone ({exc})") from None
        if size != len(self.buffer):
            raise PlatformError(f"the PyBullet render worker sent {size} bytes for a {self.shape} image")
        return np.frombuffer(self.buffer, np.uint8).reshape(self.shape).copy()

    def close(self) -> None:
        try:
            self.connection.send(None)
        except (OSError, ValueError):
            pass
        self.process.join(timeout=5.0)
        if self.process.is_alive():
            self.process.kill()
            self.process.join()
        self.connection.close()


def spare_core() -> bool:
    """Whether a core is free for a render worker: there is more than one, and the last minute's load
    leaves one idle (on a machine already busy, a second process only adds switching)."""
    cores = os.cpu_count() or 1
    return cores > 1 and os.getloadavg()[0] <= cores - 1


RENDERERS = ("auto", "mujoco", "pybullet")


def parse_renderer(value: Any) -> str:
    """``--renderer``: auto, mujoco or pybullet (what draws the cameras' images)."""
    text = str(value if value is not None else "auto").lower()
    if text not in RENDERERS:
        raise PlatformOptionError(f"--renderer takes auto, mujoco or pybullet, got {value!r}")
    return text


def parse_render_worker(value: Any) -> bool | None:
    """``--render-worker``: on, off, or auto (None: on where cameras render headless and a core is spare)."""
    text = str(value if value is not None else "auto").lower()
    if text not in ("on", "off", "auto"):
        raise PlatformOptionError(f"--render-worker takes on, off or auto, got {value!r}")
    return None if text == "auto" else text == "on"


class PybulletPlatform(SimulatedRobotPlatform):
    name = "pybullet"
    engine = "PyBullet"
    description = "PyBullet physics: the same robot, field and ball, cameras drawn by MuJoCo's renderer (or PyBullet's)"

    def __init__(self, options: dict[str, Any] | None = None) -> None:
        super().__init__(options)
        self.client: int | None = None
        self.viewer = False
        self.render_worker = parse_render_worker(self.options.get("render_worker"))
        self.renderer = parse_renderer(self.options.get("renderer"))
        self.worker: RenderWorker | None = None
        self.drawing: MujocoDrawing | None = None  # MuJoCo drawing this world's images (--renderer)

    @classmethod
    def add_arguments(cls, parser: Any) -> None:
        super().add_arguments(parser)
        parser.add_argument("--renderer", choices=RENDERERS, default="auto",
                            help="pybullet: what draws the cameras: mujoco (MuJoCo's renderer, EGL or OSMesa, about ten times "
                                 "faster), pybullet (its CPU renderer, no OpenGL) or auto (mujoco where it can render headless)")
        parser.add_argument("--render-worker", choices=["on", "off", "auto"], default="auto",
                            help="pybullet: with --renderer pybullet, render the top camera in a process of its own, in parallel with the bottom one "
                                 "(auto: with cameras on, no viewer and a core to spare: more than one, not all busy)")

    # ------------------------------------------------------------------------------- the world
    def build(self, contexts: frozenset[str], viewer: bool) -> None:
        self.viewer = viewer
        self.client = pybullet.connect(pybullet.GUI if viewer else pybullet.DIRECT)
        if self.client < 0:
            raise PlatformError("PyBullet could not start its physics server")
        c = self.client
        pybullet.resetSimulation(physicsClientId=c)
        pybullet.setGravity(0, 0, -9.81, physicsClientId=c)
        pybullet.setTimeStep(TIMESTEP, physicsClientId=c)
        pybullet.setPhysicsEngineParameter(numSolverIterations=50, deterministicOverlappingPairs=1, physicsClientId=c)
        self.bodies: dict[str, int] = {}
        ball = (self.initial_ball[0] * M, self.initial_ball[1] * M)
        for part in field_parts(ball, self.ball_color, self.scene_look):
            self.bodies[part.name] = self._field_body(part)
        self._load_robot()
        self.previous_velocity = np.zeros(3)
        if self.cameras and "cognition" in contexts and self.renderer != "pybullet":
            try:
                self.drawing = MujocoDrawing(self.sizes, self.ball_color, self.scene_look, self.shadows)
                names = [pybullet.getJointInfo(self.robot, j, physicsClientId=c)[1].decode() for j in self.all_joints]
                pairs = [(joint, self.drawing.joint_address(name)) for joint, name in zip(self.all_joints, names)]
                #: (PyBullet joint, MuJoCo qpos address) of every joint both worlds have
                self.drawn_joints = [(joint, address) for joint, address in pairs if address is not None]
            except PlatformError as exc:
                if self.renderer == "mujoco":
                    self.stop()
                    raise
                print(f"pybullet: {exc}; the cameras render with PyBullet's CPU renderer", file=sys.stderr)
        wanted = self.render_worker if self.render_worker is not None else spare_core()
        if wanted and self.cameras and self.drawing is None and not viewer and "cognition" in contexts:
            try:
                self.worker = RenderWorker(dict(self.options), self.sizes["top"])
            except PlatformError as exc:
                print(f"pybullet: {exc}; rendering both cameras in this process", file=sys.stderr)

    def _field_body(self, part: FieldPart) -> int:
        c = self.client
        kind = {"plane": pybullet.GEOM_PLANE, "box": pybullet.GEOM_BOX, "cylinder": pybullet.GEOM_CYLINDER,
                "capsule": pybullet.GEOM_CAPSULE, "sphere": pybullet.GEOM_SPHERE}[part.kind]
        position, orientation = part.position, _quaternion_yaw(part.yaw)
        shape: dict[str, Any] = {}
        if part.kind == "box":
            shape = {"halfExtents": part.size}
        elif part.kind == "cylinder":
            shape = {"radius": part.size[0], "length": 2 * part.size[1]}
        elif part.kind == "sphere":
            shape = {"radius": part.size[0]}
        elif part.kind == "capsule":
            start, end = np.array(part.position), np.array(part.end)
            direction = end - start
            shape = {"radius": part.size[0], "length": float(np.linalg.norm(direction))}
            position = tuple((start + end) / 2)
            # PyBullet capsules lie along z: tip z over onto the direction
            orientation = pybullet.getQuaternionFromEuler([0.0, math.atan2(math.hypot(direction[0], direction[1]), direction[2]),
                                                           math.atan2(direction[1], direction[0])])
        if not part.in_cameras:
            # the cameras render every body, its collision shape where it has no visual shape; fully
            # transparent shapes they leave out. The viewer gets lines instead.
            visual = pybullet.createVisualShape(kind, rgbaColor=(*part.rgba[:3], 0.0), physicsClientId=c, **shape)
            if self.viewer:
                self._draw_net(part)
        elif part.texture:
            vertices, normals, uvs, triangles = ball_mesh(part.size[0])
            visual = pybullet.createVisualShape(pybullet.GEOM_MESH, vertices=vertices.tolist(), normals=normals.tolist(),
                                                uvs=uvs.tolist(), indices=triangles.ravel().tolist(), rgbaColor=part.rgba,
                                                physicsClientId=c)
        elif part.kind == "cylinder":
            vertices, normals, triangles = cylinder_mesh(part.size[0], part.size[1])
            visual = pybullet.createVisualShape(pybullet.GEOM_MESH, vertices=vertices.tolist(), normals=normals.tolist(),
                                                indices=triangles.ravel().tolist(), rgbaColor=part.rgba, physicsClientId=c)
        elif part.kind == "plane" and part.material == "carpet" and self.scene_look is not None:
            dark, _ = stripe_shade(self.scene_look)
            visual = self._carpet_visual(part, 1 - dark, 1.0)  # the lighter strips; the body "carpet_stripes" has the others
        elif part.kind == "plane":
            visual = pybullet.createVisualShape(pybullet.GEOM_BOX, halfExtents=[part.size[0], part.size[1], 0.0005],
                                                rgbaColor=part.rgba, visualFramePosition=[0, 0, -0.0005], physicsClientId=c)
        else:
            visual = pybullet.createVisualShape(kind, rgbaColor=part.rgba, physicsClientId=c, **shape)
        if part.collides:  # collision shapes call the length of cylinders and capsules "height"
            collision_shape = {("height" if k == "length" else k): v for k, v in shape.items()}
            collision = pybullet.createCollisionShape(kind, physicsClientId=c, **collision_shape)
        else:
            collision = -1
        body = pybullet.createMultiBody(baseMass=part.mass, baseCollisionShapeIndex=collision, baseVisualShapeIndex=visual,
                                        basePosition=position, baseOrientation=orientation, physicsClientId=c)
        if part.texture:
            pybullet.changeVisualShape(body, -1, textureUniqueId=self._ball_texture(), physicsClientId=c)
        elif part.kind == "plane" and part.material == "carpet" and self.scene_look is not None:
            texture = self._carpet_texture(self.scene_look)
            pybullet.changeVisualShape(body, -1, textureUniqueId=texture, physicsClientId=c)
            dark, shade = stripe_shade(self.scene_look)
            stripes = pybullet.createMultiBody(baseMass=0.0, baseCollisionShapeIndex=-1, baseVisualShapeIndex=self._carpet_visual(part, dark, shade),
                                               basePosition=position, physicsClientId=c)
            pybullet.changeVisualShape(stripes, -1, textureUniqueId=texture, physicsClientId=c)
            self.bodies[f"{part.name}_stripes"] = stripes
        if part.name == "ball":
            sliding, spinning, rolling = (float(v) for v in BALL_FRICTION.split())
            pybullet.changeDynamics(body, -1, lateralFriction=sliding, spinningFriction=spinning, rollingFriction=rolling,
                                    physicsClientId=c)
        elif part.kind == "plane":
            pybullet.changeDynamics(body, -1, lateralFriction=1.0, physicsClientId=c)
        elif part.absorbs:
            pybullet.changeDynamics(body, -1, lateralFriction=NET_FRICTION, restitution=0.0, physicsClientId=c)
        return body

    def _carpet_visual(self, part: FieldPart, strips: int, shade: float) -> int:
        """Every other strip of the realistic carpet as a textured mesh, its texture darkened by ``shade``
        (the CPU renderer multiplies a texture by the shape's colour)."""
        vertices, uvs, triangles = carpet_mesh(part.size[0], part.size[1], strips)
        return pybullet.createVisualShape(pybullet.GEOM_MESH, vertices=vertices.tolist(), normals=[[0.0, 0.0, 1.0]] * len(vertices),
                                          uvs=uvs.tolist(), indices=triangles.ravel().tolist(), rgbaColor=(shade, shade, shade, 1.0),
                                          physicsClientId=self.client)

    def _draw_net(self, part: FieldPart, mesh: float = 0.1) -> None:
        """A box the cameras must not see (a goal net) as a grid of debug lines, which only the GUI draws."""
        centre, half = np.array(part.position), np.array(part.size)
        thin = int(np.argmin(half))  # the net's plane is across its thinnest axis
        u, v = (axis for axis in range(3) if axis != thin)
        colour = part.rgba[:3]
        for along, across in ((u, v), (v, u)):
            for offset in np.arange(-half[across], half[across] + 1e-9, mesh):
                start, end = centre.copy(), centre.copy()
                start[across] = end[across] = centre[across] + offset
                start[along], end[along] = centre[along] - half[along], centre[along] + half[along]
                pybullet.addUserDebugLine(start.tolist(), end.tolist(), colour, physicsClientId=self.client)

    def _ball_texture(self) -> int:
        """The SPL ball's pattern, through a temporary PNG (PyBullet loads textures only from files)."""
        return self._load_texture(ball_texture_png())

    def _carpet_texture(self, look: SceneLook) -> int:
        """One seeded metre of the realistic carpet, MuJoCo's (``field_world.carpet_texture``)."""
        return self._load_texture(carpet_texture_png(look))

    def _load_texture(self, png: bytes) -> int:
        """A texture from PNG bytes, through a temporary file (PyBullet loads textures only from files)."""
        with tempfile.NamedTemporaryFile(suffix=".png", delete=False) as handle:
            handle.write(png)
        try:
            return pybullet.loadTexture(handle.name, physicsClientId=self.client)
        finally:
            os.unlink(handle.name)

    def _load_robot(self) -> None:
        c = self.client
        with tempfile.NamedTemporaryFile("w", suffix=".urdf", delete=False) as handle:
            handle.write(urdf())
        try:
            self.robot = pybullet.loadURDF(handle.name, basePosition=[0, 0, STANDING_HEIGHT + 0.002],
                                           flags=pybullet.URDF_USE_INERTIA_FROM_FILE, physicsClientId=c)
        finally:
            os.unlink(handle.name)
        names = {pybullet.getJointInfo(self.robot, i, physicsClientId=c)[1].decode(): i
                 for i in range(pybullet.getNumJoints(self.robot, physicsClientId=c))}
        self.joint_ids = [names[name] for name in JOINT_NAMES]
        self.follower_ids = [(names[follower], JOINT_NAMES.index(leader)) for follower, leader in COUPLED_JOINTS.items()]
        self.torques, self.speeds = zip(*(joint_motor(name) for name in (*JOINT_NAMES, *COUPLED_JOINTS)))
        self.head_link = names["HeadPitch"]
        self.foot_links = {"L": names["LAnkleRoll"], "R": names["RAnkleRoll"]}
        self.base_inertial = np.array(pybullet.getDynamicsInfo(self.robot, -1, physicsClientId=c)[3])
        all_joints = list(names.values())
        self.all_joints = all_joints
        pybullet.setJointMotorControlArray(self.robot, all_joints, pybullet.VELOCITY_CONTROL, forces=[0.0] * len(all_joints),
                                           physicsClientId=c)
        for link in [-1, *all_joints]:
            pybullet.changeVisualShape(self.robot, link, rgbaColor=ROBOT_RGBA, physicsClientId=c)
        for joint in all_joints:
            # PyBullet applies the URDF's joint damping explicitly: on the small links (neck, shoulders)
            # one step of it overshoots, and a limp robot blows up. The servos damp instead.
            pybullet.changeDynamics(self.robot, joint, jointDamping=0.0, physicsClientId=c)
        for link in [-1, *all_joints]:
            # every part grips like MuJoCo's (the robot's geoms and the carpet: 1.0); PyBullet's default
            # of 0.5 lets hands and seat slide away in a get-up
            spinning = 0.02 if link in self.foot_links.values() else 0.0
            pybullet.changeDynamics(self.robot, link, lateralFriction=1.0, spinningFriction=spinning, physicsClientId=c)
        self.move_ball(*self.initial_ball, self.initial_ball_velocity)

    def stop(self) -> None:
        super().stop()
        if self.drawing is not None:
            self.drawing.close()
            self.drawing = None
        if self.worker is not None:
            self.worker.close()
            self.worker = None
        if self.client is not None:
            try:
                pybullet.disconnect(physicsClientId=self.client)
            except pybullet.error:
                pass
            self.client = None

    # ---------------------------------------------------------------------------------- engine
    def step_physics(self, steps: int) -> None:
        before = self._base_velocity()
        for _ in range(steps):
            pybullet.stepSimulation(physicsClientId=self.client)
        after = self._base_velocity()
        self.acceleration = (after - before) / (steps * TIMESTEP)

    def _base_velocity(self) -> np.ndarray:
        """Velocity (m/s) of the accelerometer's point: the base's centre of mass plus the turn's share."""
        linear, angular = pybullet.getBaseVelocity(self.robot, physicsClientId=self.client)
        _, rotation = self.torso_pose()
        lever = rotation @ (np.array(ACCELEROMETER_POSITION) * M - self.base_inertial)
        return np.array(linear) + np.cross(np.array(angular), lever)

    def joint_angles(self) -> np.ndarray:
        states = pybullet.getJointStates(self.robot, self.joint_ids, physicsClientId=self.client)
        return np.array([state[0] for state in states])

    def joint_torques(self) -> np.ndarray:
        states = pybullet.getJointStates(self.robot, self.joint_ids, physicsClientId=self.client)
        return np.array([state[3] for state in states])

    def imu(self) -> tuple[np.ndarray, np.ndarray]:
        """Proper acceleration (what an accelerometer measures) and angular velocity, in the torso frame."""
        _, rotation = self.torso_pose()
        angular = np.array(pybullet.getBaseVelocity(self.robot, physicsClientId=self.client)[1])
        acceleration = getattr(self, "acceleration", np.zeros(3))
        return rotation.T @ (acceleration + np.array([0.0, 0.0, 9.81])), rotation.T @ angular

    def foot_forces(self) -> np.ndarray:
        """Each contact's normal force shared between the sole's four corners by where it is."""
        forces = np.zeros(8)
        for index, side in enumerate("LR"):
            link = self.foot_links[side]
            state = pybullet.getLinkState(self.robot, link, computeForwardKinematics=True, physicsClientId=self.client)
            origin, rotation = np.array(state[4]), _matrix(state[5])
            corners = [np.array(p) for _, p in fsr_sites(side)]
            left, right = corners[0][1], corners[1][1]
            for contact in pybullet.getContactPoints(bodyA=self.robot, linkIndexA=link, physicsClientId=self.client):
                local = rotation.T @ (np.array(contact[5]) - origin)
                u = min(1.0, max(0.0, (local[0] + SOLE_BACK * M) / ((SOLE_FRONT + SOLE_BACK) * M)))  # 1 at the front
                v = min(1.0, max(0.0, (local[1] - right) / (left - right)))  # 1 at the left edge
                force = contact[9]
                forces[index * 4 : index * 4 + 4] += force * np.array([u * v, u * (1 - v), (1 - u) * v, (1 - u) * (1 - v)])
        return forces

    def images(self, time_ns: int) -> tuple[int, dict[str, np.ndarray]]:
        """Both cameras' images: the top one from the render worker while this process renders the bottom
        one (images shown late, ``--camera-latency-ms``, are rendered here from the saved world)."""
        if self.worker is None or (self.camera_latency_ns and self.history):
            return super().images(time_ns)
        try:
            self.worker.request(self.moving_state(), "top")
            bottom = self.render("bottom")
            return time_ns, {"top": self.worker.image(), "bottom": bottom}
        except PlatformError as exc:
            print(f"pybullet: {exc}; rendering both cameras in this process from now on", file=sys.stderr)
            self.worker.close()
            self.worker = None
            return super().images(time_ns)

    def moving_state(self) -> tuple[Any, ...]:
        """The poses of what moves, all a copy of the world needs to render as this one looks: the robot's
        base, every joint's angle, the ball."""
        c = self.client
        base = pybullet.getBasePositionAndOrientation(self.robot, physicsClientId=c)
        joints = tuple(state[0] for state in pybullet.getJointStates(self.robot, self.all_joints, physicsClientId=c))
        ball = pybullet.getBasePositionAndOrientation(self.bodies["ball"], physicsClientId=c)
        return base, joints, ball

    def set_moving_state(self, state: tuple[Any, ...]) -> None:
        """Put what moves where ``moving_state`` found it (in a render worker's copy of the world)."""
        c = self.client
        (position, orientation), joints, (ball_position, ball_orientation) = state
        pybullet.resetBasePositionAndOrientation(self.robot, position, orientation, physicsClientId=c)
        for joint, angle in zip(self.all_joints, joints):
            pybullet.resetJointState(self.robot, joint, angle, 0.0, physicsClientId=c)
        pybullet.resetBasePositionAndOrientation(self.bodies["ball"], ball_position, ball_orientation, physicsClientId=c)

    def render(self, camera: str) -> np.ndarray:
        if self.drawing is not None:
            self._pose_drawing(self.drawing)
            return self.drawing.render(camera)
        rgba, _ = self._camera_image(camera, segmentation=False)
        width, height = self.sizes[camera]
        return np.asarray(rgba, dtype=np.uint8).reshape(height, width, 4)[:, :, :3].copy()

    def _camera_pose(self, camera: str) -> tuple[np.ndarray, np.ndarray]:
        """(position m, axes 3x3: columns forward, left, up) of the ``top`` or ``bottom`` camera in the world."""
        mount = next(m for m in CAMERAS if m.name == camera)
        state = pybullet.getLinkState(self.robot, self.head_link, computeForwardKinematics=True, physicsClientId=self.client)
        head_position, head_rotation = np.array(state[4]), _matrix(state[5])
        c, s = math.cos(mount.tilt), math.sin(mount.tilt)
        tilt = np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])  # pitched down by the mount's tilt
        return head_position + head_rotation @ (np.array(mount.position) * M), head_rotation @ tilt

    def camera_rotation(self, camera: str) -> np.ndarray:
        return self._camera_pose(camera)[1]

    def _camera_image(self, camera: str, segmentation: bool) -> tuple[Any, Any]:
        eye, axes = self._camera_pose(camera)
        view = pybullet.computeViewMatrix(eye.tolist(), (eye + axes[:, 0]).tolist(), axes[:, 2].tolist())
        width, height = self.sizes[camera]
        projection = pybullet.computeProjectionMatrixFOV(math.degrees(VERTICAL_FOV), width / height, 0.01, 30.0)
        # lit from behind the camera and from above, like MuJoCo's headlight and sun: posts look alike
        light = -axes[:, 0] + np.array([0.0, 0.0, 1.0])
        if self.shadows and self.scene_look:  # --realism: the hall's sun, where shadows fall the same way from every view
            light = -np.array(sun_direction(self.scene_look.seed))
        flags = pybullet.ER_SEGMENTATION_MASK_OBJECT_AND_LINKINDEX if segmentation else pybullet.ER_NO_SEGMENTATION_MASK
        _, _, rgba, _, segments = pybullet.getCameraImage(width, height, view, projection, renderer=pybullet.ER_TINY_RENDERER,
                                                          flags=flags, shadow=int(self.shadows), lightDirection=light.tolist(),
                                                          lightAmbientCoeff=0.55, lightDiffuseCoeff=0.5, lightSpecularCoeff=0.0,
                                                          physicsClientId=self.client)
        return rgba, segments

    def pose_joints(self, angles: np.ndarray) -> None:
        for joint, angle in zip(self.joint_ids, angles):
            pybullet.resetJointState(self.robot, joint, float(angle), 0.0, physicsClientId=self.client)
        for follower, leader in self.follower_ids:
            pybullet.resetJointState(self.robot, follower, float(angles[leader]), 0.0, physicsClientId=self.client)

    def _pose_drawing(self, drawing: MujocoDrawing) -> None:
        """Pose MuJoCo's copy of the world as this one is now: the torso's frame, every joint, the ball."""
        c = self.client
        states = pybullet.getJointStates(self.robot, [j for j, _ in self.drawn_joints], physicsClientId=c)
        angles = {address: state[0] for (_, address), state in zip(self.drawn_joints, states)}
        position, _ = self.torso_pose()
        _, (x, y, z, w) = pybullet.getBasePositionAndOrientation(self.robot, physicsClientId=c)
        ball, (bx, by, bz, bw) = pybullet.getBasePositionAndOrientation(self.bodies["ball"], physicsClientId=c)
        drawing.pose(position, np.array([w, x, y, z]), angles, np.array(ball), np.array([bw, bx, by, bz]))

    def ball_mask(self, camera: str) -> np.ndarray:
        if self.drawing is not None:
            self._pose_drawing(self.drawing)
            return self.drawing.ball_mask(camera)
        _, segments = self._camera_image(camera, segmentation=True)
        width, height = self.sizes[camera]
        return (np.asarray(segments).reshape(height, width) & ((1 << 24) - 1)) == self.bodies["ball"]

    def world_state(self) -> int:
        return pybullet.saveState(physicsClientId=self.client)

    def forget_state(self, state: int) -> None:
        pybullet.removeState(state, physicsClientId=self.client)

    def render_state(self, state: int, cameras: tuple[str, ...]) -> dict[str, np.ndarray]:
        now = pybullet.saveState(physicsClientId=self.client)
        try:
            pybullet.restoreState(stateId=state, physicsClientId=self.client)
            return {camera: self.render(camera) for camera in cameras}
        finally:
            pybullet.restoreState(stateId=now, physicsClientId=self.client)
            pybullet.removeState(now, physicsClientId=self.client)

    def drive(self, targets: np.ndarray, stiffness: np.ndarray) -> None:
        joints = list(self.joint_ids) + [follower for follower, _ in self.follower_ids]
        goals = list(targets) + [targets[leader] for _, leader in self.follower_ids]
        strength = list(stiffness) + [stiffness[leader] for _, leader in self.follower_ids]
        # one call per joint: only this form takes a speed limit (PyBullet's motors cannot follow the
        # motors' torque-speed line as MuJoCo's do; the no-load speed as a hard limit comes closest)
        for joint, goal, torque, speed, share in zip(joints, goals, self.torques, self.speeds, strength):
            pybullet.setJointMotorControl2(self.robot, joint, pybullet.POSITION_CONTROL, targetPosition=goal, force=torque * share,
                                           positionGain=POSITION_GAIN, velocityGain=1.0, maxVelocity=speed,
                                           physicsClientId=self.client)

    def torso_pose(self) -> tuple[np.ndarray, np.ndarray]:
        position, orientation = pybullet.getBasePositionAndOrientation(self.robot, physicsClientId=self.client)
        rotation = _matrix(orientation)
        return np.array(position) - rotation @ self.base_inertial, rotation  # the link frame, not the centre of mass

    def ball_position(self) -> tuple[float, float]:
        position, _ = pybullet.getBasePositionAndOrientation(self.bodies["ball"], physicsClientId=self.client)
        return position[0] * 1000.0, position[1] * 1000.0

    def move_ball(self, x_mm: float, y_mm: float, velocity_mm_s: tuple[float, float] = (0.0, 0.0)) -> None:
        ball = self.bodies["ball"]
        vx, vy = velocity_mm_s[0] * M, velocity_mm_s[1] * M
        pybullet.resetBasePositionAndOrientation(ball, [x_mm * M, y_mm * M, 0.05], [0, 0, 0, 1], physicsClientId=self.client)
        pybullet.resetBaseVelocity(ball, [vx, vy, 0], [-vy / (BALL_RADIUS * M), vx / (BALL_RADIUS * M), 0], physicsClientId=self.client)

    def place_robot(self, position_m: np.ndarray, quaternion_wxyz: np.ndarray) -> None:
        w, x, y, z = (float(v) for v in quaternion_wxyz)
        orientation = (x, y, z, w)
        base = np.asarray(position_m) + _matrix(orientation) @ self.base_inertial
        pybullet.resetBasePositionAndOrientation(self.robot, base.tolist(), orientation, physicsClientId=self.client)
        pybullet.resetBaseVelocity(self.robot, [0, 0, 0], [0, 0, 0], physicsClientId=self.client)

    def apply_push(self, force_n: np.ndarray) -> None:
        position, _ = pybullet.getBasePositionAndOrientation(self.robot, physicsClientId=self.client)
        pybullet.applyExternalForce(self.robot, -1, [float(v) for v in force_n], position, pybullet.WORLD_FRAME,
                                    physicsClientId=self.client)
