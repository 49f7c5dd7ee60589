"""Rendered camera frames with ground truth: data for detector tests, the perception benchmark and training.

``SceneRenderer`` poses the simulated robot kinematically (stand pose, any head angles, anywhere on
the field), puts the ball where asked and renders both cameras, without stepping the physics. Each
``LabelledFrame`` carries what a detector should find: the ball in the robot frame, its circle in the
image, the share of it that is visible (from the engine's segmentation, so occlusion counts), and
the camera matrix computed by the same kinematics the program uses.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field

import numpy as np

from tafel.core.framework.manager import Blackboard, ModuleManager
from tafel.core.runtime.platform import load_platform
from tafel.modules.motion.kinematics import CAMERA_LINKS, angles_by_name, camera_pose_in_torso, link_poses, robot_frame_from_torso
from tafel.modules.motion.stand_motion import stand_pose
from tafel.modules.perception.ball_detector import BallDetector
from tafel.modules.perception.ball_locator import BallLocator
from tafel.modules.perception.field_boundary_detector import FieldBoundaryDetector
from tafel.modules.perception.field_color_provider import FieldColorProvider
from tafel.modules.perception.goal_post_detector import GoalPostDetector
from tafel.modules.perception.line_detector import LineDetector
from tafel.modules.perception.spl_ball_detector import SPLBallDetector
from tafel.platforms.realism import CameraRealism
from tafel.platforms.simulated import SimulatedRobotPlatform
from tafel.representations import field as spl
from tafel.representations.geometry import Pose2D
from tafel.representations.infrastructure import FrameInfo
from tafel.representations.motion import HEAD_PITCH, HEAD_YAW, CameraMatrix, CameraMatrixBottom, CameraMatrixBuffer, CameraMatrixTop
from tafel.representations.nao import BOTTOM_CAMERA, TOP_CAMERA
from tafel.representations.perception import CameraImageBottom, CameraImageTop

CAMERAS = {"top": TOP_CAMERA, "bottom": BOTTOM_CAMERA}
#: how far from the centre spot random balls lie (mm): on the field, or just over its lines
BALL_X = spl.LENGTH / 2 + 300.0
BALL_Y = spl.WIDTH / 2 + 300.0


@dataclass
class LabelledFrame:
    """One camera's image with what is really there. Positions in the robot frame are mm."""

    camera: str
    image: np.ndarray
    matrix: CameraMatrix
    horizontal_fov: float
    vertical_fov: float
    robot_pose: tuple[float, float, float]  # field mm, mm, rad
    ball: tuple[float, float]  # robot frame, mm
    ball_distance: float  # mm from the camera's ground point
    ball_image: tuple[float, float, float] | None  # centre x, y and radius (px) of the ball's projection; None behind
    ball_visible: float  # share of the ball's projected disc that the image shows (0..1)
    ball_pixels: int = 0
    notes: dict[str, float] = field(default_factory=dict)


class SceneRenderer:
    """A simulated platform used as a camera: pose, place, render, with the truth alongside."""

    def __init__(self, engine: str = "mujoco", resolution: str = "320x240", ball_color: str = "spl", realism: str = "off",
                 seed: int = 0) -> None:
        """``realism``: the platform's ``--realism`` level (the hall and the camera pipeline, seeded by ``seed``);
        posed frames have no motion of their own, so each gets a seeded head turn for its blur. Each engine
        draws with its own renderer (PyBullet's CPU one, not MuJoCo's it uses by default): perception is
        judged on two renderers' looks."""
        options = {"resolution": resolution, "ball_color": ball_color, "realism": realism, "seed": seed, "renderer": engine}
        self.platform: SimulatedRobotPlatform = load_platform(engine)(options)
        self.platform.start(frozenset({"motion", "cognition"}))
        self.angles = stand_pose()

    def close(self) -> None:
        self.platform.stop()

    def __enter__(self) -> SceneRenderer:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def new_cameras(self, seed: int) -> None:
        """Cameras of their own for the next frames (exposure, white balance, cast, noise, JPEG drawn from
        ``seed``; the hall stays): training sees many cameras without building a world for each."""
        level = self.platform.realism_level
        if level is not None:
            self.platform.camera_realism = {name: CameraRealism(level, seed, name) for name in CAMERAS}

    def frames(self, robot_pose: tuple[float, float, float], head: tuple[float, float], ball: tuple[float, float],
               paint: Callable[[str, np.ndarray, tuple[float, float, float] | None], np.ndarray] | None = None) -> dict[str, LabelledFrame]:
        """Both cameras' frames with the robot at ``robot_pose`` (field mm, rad), head (yaw, pitch) in
        rad and the ball at ``ball`` (field mm). ``paint(camera, image, ball circle px)``: changes the render
        before the camera's pipeline (``--realism``) sees it, as things really in the scene would be."""
        angles = self.angles.copy()
        angles[HEAD_YAW], angles[HEAD_PITCH] = head
        poses = link_poses(angles_by_name(angles), CAMERA_LINKS)
        torso_in_robot = robot_frame_from_torso(poses, 0.0, 0.0)
        robot = Pose2D(*robot_pose)
        heading = robot_pose[2]
        offset = torso_in_robot[:3, 3]  # the torso above the robot frame's origin, turned with the robot
        torso_x, torso_y = robot.to_global(offset[0], offset[1])
        p = self.platform
        p.pose_joints(angles)
        p.place_robot(np.array([torso_x, torso_y, offset[2]]) * 0.001,
                      np.array([math.cos(heading / 2), 0.0, 0.0, math.sin(heading / 2)]))
        p.move_ball(*ball)
        ball_robot = robot.to_local(*ball)
        result = {}
        for name, mount in CAMERAS.items():
            horizontal_fov, vertical_fov = p.fov(name)
            camera = torso_in_robot @ camera_pose_in_torso(poses, mount)
            matrix = CameraMatrix(camera[:3, :3].copy(), camera[:3, 3].copy(), True)
            image = p.render(name)
            projected = project_ball(matrix, ball_robot, *p.sizes[name], horizontal_fov, vertical_fov)
            if paint is not None:
                image = paint(name, image, projected)
            pipeline = p.camera_realism.get(name)
            if pipeline is not None:
                image = pipeline(image, pipeline.posed_shift(p.focal_px(name)[0]))
            mask = p.ball_mask(name)
            visible = 0.0
            if projected is not None:
                area = math.pi * projected[2] ** 2
                visible = min(1.0, float(mask.sum()) / area) if area > 0 else 0.0
            distance = math.hypot(ball_robot[0] - matrix.translation[0], ball_robot[1] - matrix.translation[1])
            result[name] = LabelledFrame(name, image, matrix, horizontal_fov, vertical_fov, robot_pose, ball_robot, distance,
                                         projected, visible, int(mask.sum()))
        return result

    def random_frames(self, count: int, seed: int = 0, ball_range: tuple[float, float] = (300.0, 5000.0)) -> Iterator[LabelledFrame]:
        """``count`` frames of random scenes: the robot anywhere on the field, the head anywhere it can
        look, the ball mostly in front of it within ``ball_range`` mm (sometimes behind, so that frames
        without a ball occur), both cameras."""
        rng = np.random.default_rng(seed)
        made = 0
        while made < count:
            pose = (rng.uniform(-4300, 4300), rng.uniform(-2800, 2800), rng.uniform(-math.pi, math.pi))
            head = (rng.uniform(-0.8, 0.8), rng.uniform(-0.3, 0.45))
            distance = rng.uniform(*ball_range)
            bearing = pose[2] + head[0] + rng.normal(0.0, 0.5)
            ball = (pose[0] + distance * math.cos(bearing), pose[1] + distance * math.sin(bearing))
            if abs(ball[0]) > BALL_X or abs(ball[1]) > BALL_Y:
                continue  # a ball off the field is put back by the referee; no detector needs to find it there
            for frame in self.frames(pose, head, ball).values():
                if made < count:
                    made += 1
                    yield frame


class Perception:
    """The program's perception modules on labelled frames, as one module manager that keeps its state
    from frame to frame (the field colour is smoothed over frames, as in the program)."""

    MODULES = (FieldColorProvider, FieldBoundaryDetector, SPLBallDetector, BallDetector, BallLocator, LineDetector, GoalPostDetector)

    def __init__(self, ball_detector: str = "SPLBallDetector") -> None:
        self.manager = ModuleManager(list(self.MODULES), external=[CameraImageTop, CameraImageBottom, CameraMatrixBuffer, FrameInfo],
                                     providers={"BallImagePercept": ball_detector})
        self.frame = 0

    def __call__(self, frames: dict[str, LabelledFrame]) -> Blackboard:
        """Run one cognition frame on both cameras' frames; the blackboard holds every percept."""
        self.frame += 1
        time_ns = self.frame * 33_333_333
        board = self.manager.blackboard
        board.set(FrameInfo(frame_number=self.frame, time_ns=time_ns))
        for camera, rep in (("top", CameraImageTop), ("bottom", CameraImageBottom)):
            frame = frames[camera]
            board.set(rep(image=frame.image, horizontal_fov=frame.horizontal_fov, vertical_fov=frame.vertical_fov, time_ns=time_ns))
        top, bottom = frames["top"].matrix, frames["bottom"].matrix
        board.set(CameraMatrixBuffer.of(CameraMatrixTop(top.rotation, top.translation, True),
                                        CameraMatrixBottom(bottom.rotation, bottom.translation, True), time_ns))
        self.manager.execute()
        return board


def project_ball(matrix: CameraMatrix, ball: tuple[float, float], width: int, height: int, horizontal_fov: float,
                 vertical_fov: float) -> tuple[float, float, float] | None:
    """The ball's centre and radius in the image (px) for a pinhole camera, None when behind it."""
    centre = np.array([ball[0], ball[1], spl.BALL_RADIUS])
    local = np.asarray(matrix.rotation).T @ (centre - np.asarray(matrix.translation))
    if local[0] <= spl.BALL_RADIUS:
        return None
    fx = (width / 2) / math.tan(horizontal_fov / 2)
    fy = (height / 2) / math.tan(vertical_fov / 2)
    x = width / 2 - fx * local[1] / local[0]
    y = height / 2 - fy * local[2] / local[0]
    return x, y, fx * spl.BALL_RADIUS / float(np.linalg.norm(local))


def random_ball_scene(rng: np.random.Generator) -> tuple[tuple[float, float, float], tuple[float, float], tuple[float, float]] | None:
    """A seeded random scene for perception figures: the robot's pose anywhere on the field (mm, rad), its head
    (yaw, pitch; rad), and the ball 0.3 to 5 m away, roughly where the head looks; None when the ball would be
    off the carpet (draw again)."""
    pose = (rng.uniform(-4300, 4300), rng.uniform(-2800, 2800), rng.uniform(-math.pi, math.pi))
    head = (rng.uniform(-0.8, 0.8), rng.uniform(-0.3, 0.45))
    distance, bearing = rng.uniform(300.0, 5000.0), pose[2] + head[0] + rng.normal(0.0, 0.5)
    ball = (pose[0] + distance * math.cos(bearing), pose[1] + distance * math.sin(bearing))
    if abs(ball[0]) > 4800 or abs(ball[1]) > 3300:
        return None
    return pose, head, ball


def random_far_ball_scene(rng: np.random.Generator, near: float = 4500.0, far: float = 9000.0
                          ) -> tuple[tuple[float, float, float], tuple[float, float], tuple[float, float]] | None:
    """A seeded random scene with the ball far away: the ball anywhere on the field, the robot anywhere ``near`` to ``far``
    mm from it, turned roughly towards it, its head looking about level (where the top camera sees far balls); pose
    (mm, rad), head (yaw, pitch; rad), ball (field mm), or None when the distance does not fit (draw again)."""
    ball = (rng.uniform(-spl.LENGTH / 2, spl.LENGTH / 2), rng.uniform(-spl.WIDTH / 2, spl.WIDTH / 2))
    x, y = rng.uniform(-4300, 4300), rng.uniform(-2800, 2800)
    distance = math.hypot(ball[0] - x, ball[1] - y)
    if not near <= distance <= far:
        return None
    head = (rng.uniform(-0.8, 0.8), rng.uniform(-0.3, 0.3))
    heading = math.atan2(ball[1] - y, ball[0] - x) - head[0] + rng.normal(0.0, 0.35)
    return (x, y, math.remainder(heading, math.tau)), head, ball
