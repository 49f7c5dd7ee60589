"""RobotDetector against ground truth: MuJoCo renders of a match's world with other robots, and real NAO images.

    MUJOCO_GL=egl python benchmarks/robots.py [--seeds 1 2 3] [--scenes 40] [--real FOLDER]

Scenes: one robot (the viewer) stands anywhere on the field with its head turned anywhere it looks
in a game; up to ``others`` robots (none in some scenes) stand at random places, most of them within
3 m in front of it, all in the stand pose, facing anywhere; the ball lies within 2 m in front of the
viewer, where a player looks. Both cameras are rendered (top 640x480, bottom 320x240, as on the
NAO) and the program's perception runs on them (``tools.simulation.scene_frames.Perception`` plus
``RobotDetector``). A robot counts as visible when its torso lies within ``--max-distance`` (mm) of
the viewer and its feet are in one camera's view; a robot found matches a visible robot within
``--tolerance`` mm (and a robot found near an invisible one is not counted as wrong).

Figures: ``precision`` (found robots that are real) and ``recall`` (visible robots found) over all
seeds and per seed, ``mean_error_mm`` of the matches, and ``real_empty_false``: robots reported on
the real images whose labels list no robot (``--real``, default ``../shared/real-images``; robots
are not labelled there, so only images that show none are judged: see ``EMPTY_SOURCE``), with the number of
robots reported on the others for a look. ``ms_per_pair``: the detector's mean time per frame pair
(renders). Prints one JSON line.
"""

from __future__ import annotations

import argparse
import csv
import json
import math
import os
import statistics
import sys
from pathlib import Path
from typing import Any

import cv2
import mujoco
import numpy as np

REPO = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(REPO))

from tafel.core.framework.manager import ModuleManager  # noqa: E402
from tafel.modules.motion.kinematics import CAMERA_LINKS, angles_by_name, camera_pose_in_torso, link_poses, robot_frame_from_torso  # noqa: E402
from tafel.modules.motion.stand_motion import stand_pose  # noqa: E402
from tafel.modules.perception.field_boundary_detector import FieldBoundaryDetector  # noqa: E402
from tafel.modules.perception.field_color_provider import FieldColorProvider  # noqa: E402
from tafel.modules.perception.goal_post_detector import GoalPostDetector  # noqa: E402
from tafel.modules.perception.robot_detector import RobotDetector  # noqa: E402
from tafel.platforms.match_world import MatchWorld  # noqa: E402
from tafel.platforms.mujoco_sim import MujocoRobot  # noqa: E402
from tafel.representations.geometry import Pose2D  # noqa: E402
from tafel.representations.infrastructure import FrameInfo  # noqa: E402
from tafel.representations.motion import HEAD_PITCH, HEAD_YAW, CameraMatrix, CameraMatrixBottom, CameraMatrixBuffer, CameraMatrixTop  # noqa: E402
from tafel.representations.nao import BOTTOM_CAMERA, TOP_CAMERA, VERTICAL_FOV  # noqa: E402
from tafel.representations.obstacles import RobotsPercept  # noqa: E402
from tafel.representations.perception import CameraImageBottom, CameraImageTop  # noqa: E402

DEFAULT_REAL = REPO.parent / "shared" / "real-images"
SIZES = {"top": (640, 480), "bottom": (320, 240)}
MOUNTS = {"top": TOP_CAMERA, "bottom": BOTTOM_CAMERA}
FRAME_NS = 33_333_333


def horizontal_fov(width: int, height: int) -> float:
    return 2 * math.atan(math.tan(VERTICAL_FOV / 2) * width / height)


class RobotScenes:
    """A match's world of ``count`` robots, posed kinematically (no physics), rendered from robot 0's cameras."""

    def __init__(self, count: int) -> None:
        self.world = MatchWorld([(-3000.0 + 400.0 * k, -3200.0) for k in range(count)])
        self.model, self.data = self.world.model, self.world.data
        self.robots: list[MujocoRobot] = self.world.robots
        self.renderers = {camera: mujoco.Renderer(self.model, h, w) for camera, (w, h) in SIZES.items()}
        self.angles = stand_pose()

    def close(self) -> None:
        for renderer in self.renderers.values():
            renderer.close()

    def place(self, index: int, pose: tuple[float, float, float], head: tuple[float, float] = (0.0, 0.0)) -> np.ndarray:
        """Stand robot ``index`` at ``pose`` (field mm, rad) looking (yaw, pitch rad); the torso in its robot frame (4x4)."""
        angles = self.angles.copy()
        angles[HEAD_YAW], angles[HEAD_PITCH] = head
        poses = link_poses(angles_by_name(angles), CAMERA_LINKS)
        torso_in_robot = robot_frame_from_torso(poses, 0.0, 0.0)
        offset = torso_in_robot[:3, 3]
        robot = Pose2D(*pose)
        torso_x, torso_y = robot.to_global(offset[0], offset[1])
        body = self.robots[index]
        self.data.qpos[body.joint_qpos] = angles
        self.data.qvel[body.joint_dof] = 0.0
        body.place(self.data, np.array([torso_x, torso_y, offset[2]]) * 0.001, np.array([math.cos(pose[2] / 2), 0.0, 0.0, math.sin(pose[2] / 2)]))
        self.poses = poses
        return torso_in_robot

    def render(self, viewer: tuple[float, float, float], head: tuple[float, float], others: list[tuple[float, float, float]],
               ball: tuple[float, float] = (0.0, 8000.0)) -> tuple[dict[str, tuple[np.ndarray, CameraMatrix]], list[tuple[float, float]]]:
        """Both cameras' images and matrices of robot 0 at ``viewer``, the others at ``others``, the ball at
        ``ball`` (field mm); and where the others' centres (torsos) are in the viewer's robot frame (mm)."""
        for k, pose in enumerate(others, start=1):
            self.place(k, pose)
        for k in range(len(others) + 1, len(self.robots)):
            self.place(k, (-4000.0 + 300.0 * k, 4500.0, 0.0))  # beside the field, out of the way
        torso_in_robot = self.place(0, viewer, head)
        self.world.ball.place(self.data, *ball)
        mujoco.mj_forward(self.model, self.data)
        shots = {}
        for camera, mount in MOUNTS.items():
            pose = torso_in_robot @ camera_pose_in_torso(self.poses, mount)
            renderer = self.renderers[camera]
            renderer.update_scene(self.data, camera=self.robots[0].camera(camera))
            shots[camera] = (renderer.render().copy(), CameraMatrix(pose[:3, :3].copy(), pose[:3, 3].copy(), True))
        here = Pose2D(*viewer)
        truth = []
        for k in range(1, len(others) + 1):
            x, y, _ = self.world.robot_pose(k)
            truth.append(here.to_local(x, y))
        return shots, truth


class Detection:
    """The perception modules RobotDetector needs and RobotDetector, one manager stepped frame by frame."""

    def __init__(self) -> None:
        self.manager = ModuleManager([FieldColorProvider, FieldBoundaryDetector, GoalPostDetector, RobotDetector],
                                     external=[CameraImageTop, CameraImageBottom, CameraMatrixBuffer, FrameInfo])
        self.frame = 0
        self.detector_ms: list[float] = []

    def __call__(self, shots: dict[str, tuple[np.ndarray, CameraMatrix, float, float]]) -> list[tuple[float, float]]:
        self.frame += 1
        time_ns = self.frame * FRAME_NS
        board = self.manager.blackboard
        board.set(FrameInfo(frame_number=self.frame, time_ns=time_ns))
        for camera, rep in (("top", CameraImageTop), ("bottom", CameraImageBottom)):
            image, _, hfov, vfov = shots[camera]
            board.set(rep(image=image, horizontal_fov=hfov, vertical_fov=vfov, time_ns=time_ns))
        top, bottom = shots["top"][1], shots["bottom"][1]
        board.set(CameraMatrixBuffer.of(CameraMatrixTop(top.rotation, top.translation, True),
                                        CameraMatrixBottom(bottom.rotation, bottom.translation, True), time_ns))
        self.manager.execute()
        for name, ms in zip(*self.manager.last_times_ms()):
            if name == "RobotDetector":
                self.detector_ms.append(float(ms))
        return [(r.x, r.y) for r in board[RobotsPercept].robots]


def visible(point: tuple[float, float], shots: dict[str, tuple[np.ndarray, CameraMatrix]], max_distance: float) -> bool:
    """Whether a robot centred at ``point`` (robot frame mm) has its feet in a camera's view within ``max_distance``."""
    if math.hypot(*point) > max_distance:
        return False
    for image, matrix in shots.values():
        height, width = image.shape[:2]
        fx = (width / 2) / math.tan(horizontal_fov(width, height) / 2)
        fy = (height / 2) / math.tan(VERTICAL_FOV / 2)
        local = matrix.rotation.T @ (np.array([point[0], point[1], 0.0]) - matrix.translation)
        if local[0] <= 1.0:
            continue
        u, v = width / 2 - fx * local[1] / local[0], height / 2 - fy * local[2] / local[0]
        if 0 <= u < width and 0 <= v < height:
            return True
    return False


Scene = tuple[tuple[float, float, float], tuple[float, float], list[tuple[float, float, float]], tuple[float, float]]


def scene(rng: np.random.Generator, others: int) -> Scene:
    """The viewer's pose and head, the others' poses (field mm, rad): most of them in front of the
    viewer within 3 m, none nearer than 300 mm to another; and the ball, in front of the viewer (where
    a player looks) within 2 m, on the field."""
    viewer = (rng.uniform(-3500, 3500), rng.uniform(-2500, 2500), rng.uniform(-math.pi, math.pi))
    head = (rng.uniform(-0.8, 0.8), rng.uniform(-0.1, 0.45))
    places: list[tuple[float, float, float]] = []
    while len(places) < others:
        if rng.random() < 0.8:
            distance, bearing = rng.uniform(350, 3000), viewer[2] + head[0] + rng.uniform(-0.6, 0.6)
            x, y = viewer[0] + distance * math.cos(bearing), viewer[1] + distance * math.sin(bearing)
        else:
            x, y = rng.uniform(-4500, 4500), rng.uniform(-3000, 3000)
        if abs(x) > 4500 or abs(y) > 3000:
            continue
        if all(math.hypot(x - px, y - py) > 400 for px, py, _ in [*places, viewer]):
            places.append((x, y, rng.uniform(-math.pi, math.pi)))
    while True:
        distance, bearing = rng.uniform(250, 2000), viewer[2] + head[0] + rng.uniform(-0.4, 0.4)
        ball = (viewer[0] + distance * math.cos(bearing), viewer[1] + distance * math.sin(bearing))
        if abs(ball[0]) < 4500 and abs(ball[1]) < 3000 and all(math.hypot(ball[0] - px, ball[1] - py) > 250 for px, py, _ in places):
            return viewer, head, places, ball


def judge(found: list[tuple[float, float]], truth: list[tuple[float, float]], seen: list[bool], tolerance: float
          ) -> tuple[int, int, int, list[float]]:
    """(true positives, false positives, visible robots, errors mm): found robots matched greedily to the nearest real one."""
    free = set(range(len(truth)))
    hits, wrong, errors = 0, 0, []
    for fx, fy in found:
        near = sorted(free, key=lambda k: math.hypot(fx - truth[k][0], fy - truth[k][1]))
        if near and math.hypot(fx - truth[near[0]][0], fy - truth[near[0]][1]) <= tolerance:
            k = near[0]
            free.discard(k)
            if seen[k]:
                hits += 1
                errors.append(math.hypot(fx - truth[k][0], fy - truth[k][1]))
            continue
        wrong += 1
    return hits, wrong, sum(seen), errors


def rendered(seeds: list[int], scenes: int, others: int, tolerance: float, max_distance: float) -> dict[str, Any]:
    """Precision and recall over rendered scenes of every seed."""
    world = RobotScenes(others + 1)
    per_seed, errors, detection = {}, [], Detection()
    total = [0, 0, 0]
    try:
        for seed in seeds:
            rng = np.random.default_rng(seed)
            counts = [0, 0, 0]
            for _ in range(scenes):
                viewer, head, places, ball = scene(rng, int(rng.integers(0, others + 1)))
                shots, truth = world.render(viewer, head, places, ball)
                inputs = {c: (img, m, horizontal_fov(*SIZES[c]), VERTICAL_FOV) for c, (img, m) in shots.items()}
                found = detection(inputs)
                seen = [visible(t, shots, max_distance) for t in truth]
                hits, wrong, real, errs = judge(found, truth, seen, tolerance)
                for i, v in enumerate((hits, wrong, real)):
                    counts[i] += v
                    total[i] += v
                errors += errs
            per_seed[str(seed)] = {"precision": round(counts[0] / max(1, counts[0] + counts[1]), 3),
                                   "recall": round(counts[0] / max(1, counts[2]), 3), "visible": counts[2]}
    finally:
        world.close()
    return {"precision": round(total[0] / max(1, total[0] + total[1]), 3), "recall": round(total[0] / max(1, total[2]), 3),
            "visible_robots": total[2], "found_right": total[0], "found_wrong": total[1],
            "mean_error_mm": round(statistics.fmean(errors), 1) if errors else None, "per_seed": per_seed,
            "ms_per_pair": round(statistics.fmean(detection.detector_ms), 3) if detection.detector_ms else None}


#: the real images whose view holds no robot on the field (looked at by eye; the labels do not list robots):
#: all of HULKs' (their lab's field, goal and hall; robots only sit off the field behind the goal)
EMPTY_SOURCE = "HULKs/hulk"


def real_images(folder: Path) -> dict[str, Any]:
    """Robots reported on the real images: per image, for the ones that show none and the rest."""
    from tafel.platforms.images import posed_image

    labels = folder / "labels.csv"
    if not labels.exists():
        return {"real_images": "missing"}
    detection = Detection()
    reported: dict[str, int] = {}
    with labels.open() as handle:
        rows = list(csv.DictReader(handle))
    for row in rows:
        path = folder / row["image"]
        shot = posed_image(path)
        bottom_image = cv2.resize(shot.image, (320, 240), interpolation=cv2.INTER_AREA)
        inputs = {"top": (shot.image, shot.matrix, shot.horizontal_fov, shot.vertical_fov),
                  "bottom": (bottom_image, shot.matrix, shot.horizontal_fov, shot.vertical_fov)}
        if row["camera"] == "bottom":
            inputs = {"top": (np.zeros((480, 640, 3), np.uint8), shot.matrix, shot.horizontal_fov, shot.vertical_fov),
                      "bottom": (bottom_image, shot.matrix, shot.horizontal_fov, shot.vertical_fov)}
        reported[row["image"]] = len(detection(inputs))
    empty = [row["image"] for row in rows if row["source"] == EMPTY_SOURCE]
    return {"real_images": len(reported), "real_empty_images": len(empty), "real_empty_false": sum(reported[n] for n in empty),
            "real_reported": {name: count for name, count in reported.items() if count}}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, nargs="+", default=[1, 2, 3])
    parser.add_argument("--scenes", type=int, default=40, help="rendered scenes per seed")
    parser.add_argument("--others", type=int, default=4, help="the most other robots in a scene")
    parser.add_argument("--tolerance", type=float, default=300.0, help="mm between a robot found and a real one")
    parser.add_argument("--max-distance", type=float, default=3500.0, help="mm: farther robots need not be found")
    parser.add_argument("--real", type=Path, default=DEFAULT_REAL)
    args = parser.parse_args()
    os.environ.setdefault("MUJOCO_GL", "egl")
    result: dict[str, Any] = {"benchmark": "robots", "load": os.getloadavg()[0]}
    result.update(rendered(args.seeds, args.scenes, args.others, args.tolerance, args.max_distance))
    result.update(real_images(args.real))
    print(json.dumps(result))


if __name__ == "__main__":
    main()
