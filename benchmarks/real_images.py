"""Perception on real NAO camera images: the default cognition's perception modules over every labelled image.

    python benchmarks/real_images.py [FOLDER]     # default ../shared/real-images (from the repository)

FOLDER holds ``labels.csv`` and the images, laid out as ``../shared/real-images/README.md`` describes
(``image, camera, ball_visible, ball_x, ball_y, ball_r, matrix``; HULKs' ``.json`` beside an image gives
the recorded camera matrix and three labelled goal-area lines). Each image runs at 640x480 and, shrunk,
at 320x240, through a fresh module manager (FieldColorProvider, FieldBoundaryDetector, SPLBallDetector,
BallLocator, LineDetector, GoalPostDetector; twice, so that the smoothed field colour has settled).

The camera's pose: the recorded one where there is one; for ``label`` a camera at standing height, level,
pitched so that a 100 mm ball at the labelled pixel has the labelled radius; for ``nominal`` a standing
robot looking ahead (``tafel.platforms.images``).

Figures, for each of "640x480" and "320x240":
- ``ball_recall``: share of the images with a ball in which a candidate's centre lies within the labelled
  radius of the labelled centre;
- ``ball_false_positive_rate``: share of the images without a ball in which any candidate was reported;
- ``ball_precision``: share of all reported candidates that are the labelled ball;
- ``ball_center_error_px``: mean distance (px at that resolution) of the found balls' centres from the labels;
- ``line_points_within_100mm``: share of ``LinePercept`` points within 100 mm of a painted line, the robot
  placed on the field by the labelled goal-area lines (HULKs' images);
- ``posts_within_300mm``: share of reported goal posts within 300 mm of a real post (HULKs' images), with
  ``posts_reported`` beside it;
- ``ms_per_frame``: mean milliseconds per frame of each module.
Prints one JSON line. Targets (issue 31): recall >= 0.9, false positives <= 0.02, posts >= 0.8.
"""

from __future__ import annotations

import argparse
import csv
import json
import math
import sys
import time
from collections import defaultdict
from pathlib import Path
from types import SimpleNamespace
from typing import Any

import cv2
import numpy as np

REPO = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(REPO))

from tafel.modules.modeling.field_model import FIELD_MODEL  # noqa: E402
from tafel.modules.perception.image_geometry import ImageProjection  # noqa: E402
from tafel.platforms.images import CameraPose, PosedImage, posed_image, standing_camera  # noqa: E402
from tafel.representations import field  # noqa: E402
from tafel.representations.field import BALL_RADIUS  # noqa: E402
from tafel.representations.motion import CameraMatrix  # noqa: E402
from tafel.representations.perception import BallImagePercept, GoalPostPercept, LinePercept  # noqa: E402
from tafel.tools.simulation.scene_frames import Perception  # noqa: E402

DEFAULT_FOLDER = REPO.parent / "shared" / "real-images"
RESOLUTIONS = {"640x480": 1.0, "320x240": 0.5}


def label_pose(camera: str, x: float, y: float, radius: float, width: int, height: int, fov: tuple[float, float]) -> CameraPose:
    """A level camera at the standing height of ``camera``, pitched so that a ball at pixel (x, y) has ``radius`` px."""
    camera_height = float(standing_camera(camera).translation[2])

    def radius_at(pitch: float) -> float:
        projection = ImageProjection(CameraPose(camera_height, pitch).matrix(), width, height, *fov)
        centre, hit = projection.to_ground(np.array([x]), np.array([y]), BALL_RADIUS)
        if not hit[0]:
            return 0.0
        return projection.fx * BALL_RADIUS / float(np.linalg.norm(np.append(centre[0], BALL_RADIUS) - projection.translation))

    low, high = -0.6, 1.5  # a larger pitch brings the ground nearer: the radius grows with it
    for _ in range(60):
        middle = (low + high) / 2
        low, high = (middle, high) if radius_at(middle) < radius else (low, middle)
    return CameraPose(camera_height, (low + high) / 2)


def field_pose(crossings: dict[str, list[float]], projection: ImageProjection) -> tuple[float, float, float] | None:
    """The robot's pose on the field (mm, rad) from HULKs' three labelled goal-area lines, taken as the
    opponent's goal area: the goal line, the goal area's front line and its side line (the labels call
    either of the last two ``goal_box_line``: the front line is the one along the goal line)."""
    try:
        names = ("border_line_0", "border_line_1", "goal_box_line_0", "goal_box_line_1", "connecting_line_0", "connecting_line_1")
        xs = np.array([crossings[n][0] for n in names], float)
        ys = np.array([crossings[n][1] for n in names], float)
    except (KeyError, IndexError, TypeError):
        return None
    ground, hits = projection.to_ground(xs, ys)
    if not hits.all():
        return None
    g0, g1, b0, b1, c0, c1 = ground

    def parallel(p: np.ndarray, q: np.ndarray) -> float:
        """|cos| of the angle between the goal line and the line p -> q."""
        return abs(float(np.dot(g1 - g0, q - p))) / max(float(np.linalg.norm(g1 - g0) * np.linalg.norm(q - p)), 1e-9)

    if parallel(c0, c1) > parallel(b0, b1):  # the labels name the front and side lines either way: the front one runs along the goal line
        b0, b1, c0, c1 = c0, c1, b0, b1
    def meet(p: np.ndarray, q: np.ndarray, r: np.ndarray, s: np.ndarray) -> np.ndarray:
        d1, d2 = q - p, s - r
        t = np.linalg.solve(np.column_stack([d1, -d2]), r - p)[0]
        return p + t * d1

    along = (g1 - g0) / np.linalg.norm(g1 - g0) + np.sign(np.dot(b1 - b0, g1 - g0)) * (b1 - b0) / np.linalg.norm(b1 - b0)
    along /= np.linalg.norm(along)
    corner = meet(b0, b1, c0, c1)  # the goal area's front corner
    forward = np.array([-along[1], along[0]])  # the field's x axis points from the front line to the goal line
    if np.dot(meet(g0, g1, c0, c1) - corner, forward) < 0:
        forward = -forward
    left = np.array([-forward[1], forward[0]])
    middle = b1 if np.linalg.norm(b1 - corner) > np.linalg.norm(b0 - corner) else b0  # the front line's end away from the corner
    side = -1.0 if np.dot(middle - corner, left) > 0 else 1.0  # the front line runs from the corner towards the middle
    corner_field = np.array([field.LENGTH / 2 - field.GOAL_AREA_LENGTH, side * field.GOAL_AREA_WIDTH / 2])
    heading = -math.atan2(forward[1], forward[0])
    c, s = math.cos(heading), math.sin(heading)
    position = corner_field - np.array([[c, -s], [s, c]]) @ corner
    return float(position[0]), float(position[1]), heading


def to_field(points: np.ndarray, pose: tuple[float, float, float]) -> np.ndarray:
    c, s = math.cos(pose[2]), math.sin(pose[2])
    return np.asarray(points, float).reshape(-1, 2) @ np.array([[c, s], [-s, c]]) + np.array(pose[:2])


def load(folder: Path, row: dict[str, str]) -> PosedImage:
    path = folder / row["image"]
    camera = row.get("camera") or "top"
    if row.get("matrix") == "label" and row.get("ball_visible") == "y":
        image = cv2.imread(str(path))
        height, width = image.shape[:2]
        posed = posed_image(path, camera=camera)
        pose = label_pose(camera, float(row["ball_x"]), float(row["ball_y"]), float(row["ball_r"]), width, height,
                          (posed.horizontal_fov, posed.vertical_fov))
        labelled = posed_image(path, pose, camera)
        labelled.pose_source = "label"
        return labelled
    return posed_image(path, camera=camera)


def run(folder: Path) -> dict[str, Any]:
    rows = list(csv.DictReader((folder / "labels.csv").open()))
    results: dict[str, Any] = {}
    for name, scale in RESOLUTIONS.items():
        balls = found = negatives = false_alarms = candidates = correct = 0
        errors: list[float] = []
        line_hits = line_points = posts_near = posts = 0
        times: dict[str, list[float]] = defaultdict(list)
        for row in rows:
            posed = load(folder, row)
            image = posed.image
            if scale != 1.0:
                image = cv2.resize(image, (round(image.shape[1] * scale), round(image.shape[0] * scale)), interpolation=cv2.INTER_AREA)
            view = SimpleNamespace(image=image, horizontal_fov=posed.horizontal_fov, vertical_fov=posed.vertical_fov, matrix=posed.matrix)
            empty = SimpleNamespace(image=np.zeros((0, 0, 3), np.uint8), horizontal_fov=0.0, vertical_fov=0.0, matrix=CameraMatrix())
            frames = {"top": view, "bottom": empty} if posed.camera == "top" else {"top": empty, "bottom": view}
            perception = Perception()
            for _ in range(2):  # the second frame: the field colour settled, and no first-call costs in the times
                board = perception(frames)  # type: ignore[arg-type]
            for module, ms in zip(*perception.manager.last_times_ms()):
                times[module].append(ms)
            reported = [c for c in board[BallImagePercept].candidates if c.camera == posed.camera]
            candidates += len(reported)
            if row.get("ball_visible") == "y":
                balls += 1
                x, y, r = (float(row[k]) * scale for k in ("ball_x", "ball_y", "ball_r"))
                distances = [math.hypot(c.x - x, c.y - y) for c in reported]
                hits = [d for d in distances if d <= r]
                correct += len(hits)
                if hits:
                    found += 1
                    errors.append(min(hits))
            else:
                negatives += 1
                false_alarms += bool(reported)
            crossings_file = (folder / row["image"]).with_suffix(".json")
            if row.get("matrix") == "recorded" and crossings_file.is_file():
                crossings = json.loads(crossings_file.read_text()).get("crossings", {})
                full = ImageProjection(posed.matrix, posed.image.shape[1], posed.image.shape[0], posed.horizontal_fov, posed.vertical_fov)
                pose = field_pose(crossings, full)
                if pose is not None:
                    points = board[LinePercept].points
                    if len(points):
                        line_points += len(points)
                        line_hits += int((FIELD_MODEL.line_distance(to_field(points, pose)) <= 100.0).sum())
                    feet = [(p.x, p.y) for p in board[GoalPostPercept].posts]
                    if feet:
                        posts += len(feet)
                        posts_near += int((FIELD_MODEL.post_distance(to_field(np.array(feet), pose)) <= 300.0).sum())
        results[name] = {
            "ball_recall": round(found / balls, 3) if balls else None,
            "ball_false_positive_rate": round(false_alarms / negatives, 3) if negatives else None,
            "ball_precision": round(correct / candidates, 3) if candidates else None,
            "ball_center_error_px": round(float(np.mean(errors)), 2) if errors else None,
            "line_points_within_100mm": round(line_hits / line_points, 3) if line_points else None,
            "posts_within_300mm": round(posts_near / posts, 3) if posts else None,
            "posts_reported": posts,
            "ms_per_frame": {module: round(float(np.mean(ms)), 2) for module, ms in times.items()},
            "images": len(rows), "images_with_ball": balls,
        }
    return results


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("folder", nargs="?", default=str(DEFAULT_FOLDER), help="labelled images (labels.csv and the images)")
    args = parser.parse_args()
    folder = Path(args.folder)
    if not (folder / "labels.csv").is_file():
        parser.error(f"{folder} has no labels.csv: give a folder laid out as ../shared/real-images (see its README.md)")
    started = time.perf_counter()
    figures: dict[str, Any] = {"benchmark": "real_images", "folder": str(folder)}
    figures |= run(folder)
    figures["targets"] = {"ball_recall": 0.9, "ball_false_positive_rate": 0.02, "posts_within_300mm": 0.8}
    figures["benchmark_wall_s"] = round(time.perf_counter() - started, 1)
    print(json.dumps(figures))


if __name__ == "__main__":
    main()
