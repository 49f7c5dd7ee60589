"""Train the ball classifier (``modules/perception/ball_classifier.py``) reproducibly.

    python -m tafel.tools.simulation.train_ball_classifier [--scenes 250] [--seed 0] [--real FOLDER] [--out PATH]

Data:
- simulator renders with ground truth (``tools.simulation.scene_frames.SceneRenderer``, MuJoCo): the robot anywhere
  on the field, the head anywhere, the ball 0.3 to 5 m away, at 640x480 and 320x240, through the platform's own
  ``--realism`` (``platforms/realism.py``, ``config/realism.toml``): blocks of ``HALL_SCENES`` scenes in one seeded hall
  (clutter, nets, carpet green, shadows at full), the levels ``LEVELS`` in turn, each scene with a camera of its own
  (exposure, white balance, cast, vignetting, noise, motion blur, YUV422, JPEG). Most renders first get things painted
  in that real fields hold and the simulator does not (``distractors``: robots' black joints in white plastic, dark
  feet of goal frames and tables, legs and shoes), before the camera sees them; all seeded;
- every candidate ``SPLBallDetector`` examines in them (its checks' verdict aside) is a row: a ball when
  its centre lies within 0.75 of the true radius of the rendered ball's, none when farther than 1.5 radii
  (between: left out); the true ball itself, its centre (by a quarter radius) and radius (-20 to +35 %) jittered as the
  detector's estimates are, adds positives;
- real labelled images only where given (``--real``: a folder laid out as ``../shared/real-images``), each in a
  few variants through a mild ``--realism`` camera. None by default: the only ones the project may train on
  (``tests/data/real_images``) are images of ``benchmarks/real_images.py``, and a model trained on them is judged on
  what it learned. Give only images whose licence allows training on them, and none the benchmark uses.

Everything is seeded: the same arguments give the same model. Prints one JSON line (rows, balls,
training and held-out accuracy, the model's size) and writes the model (default: the shipped one). Needs nothing beyond the project's dependencies and a simulator.
"""

from __future__ import annotations

import argparse
import csv
import json
import math
import os
import time
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import cv2
import numpy as np

from tafel.modules.perception.ball_classifier import FEATURES, MODEL_PATH, features, train
from tafel.modules.perception.ball_spots import carpet
from tafel.modules.perception.spl_ball_detector import SPLBallDetector
from tafel.platforms.images import posed_image
from tafel.platforms.realism import CameraRealism, realism_level
from tafel.representations.motion import CameraMatrix
from tafel.tools.simulation.scene_frames import LabelledFrame, Perception, random_ball_scene

REPO = Path(__file__).resolve().parents[2]  # tools/simulation/: the checkout, for its test images
#: the real images in the checkout whose licence allows training: all are images of benchmarks/real_images.py, so
#: ``--real`` leaves them out unless asked (the pipeline's test uses them as its tiny real data set)
DEFAULT_REAL = REPO / "tests" / "data" / "real_images"
RESOLUTIONS = ("640x480", "320x240")
#: the ``--realism`` levels the renders cycle through, a block of scenes (one hall) each: mostly real cameras, some plain
LEVELS = ("full", "mild", "full", "off")
#: scenes rendered in one hall (a world built for each seed) before the next; every scene gets cameras of its own
HALL_SCENES = 10
#: focal length of the NAO's cameras in image widths (56.3 degrees across)
NAO_FOCAL = 0.5 / math.tan(math.radians(56.3) / 2)


def camera_like(image: np.ndarray, rng: np.random.Generator, level: str = "full") -> np.ndarray:
    """``image`` (RGB, uint8) as a camera of the platforms' ``--realism`` ``level`` delivers it (``platforms/realism.py``:
    exposure, white balance, cast, vignetting, noise, motion blur, YUV422, JPEG), the camera drawn from ``rng``:
    the one image-degradation code, for images that did not come through a simulated camera (real ones, painted tests)."""
    settings = realism_level(level)
    if settings is None:
        return image
    pipeline = CameraRealism(settings, int(rng.integers(2**31)), "top")
    return pipeline(image, pipeline.posed_shift(NAO_FOCAL * image.shape[1]))


def distractors(image: np.ndarray, rng: np.random.Generator, ball: tuple[float, float, float] | None,
                painted: list[tuple[float, float, float]] | None = None) -> np.ndarray:
    """``image`` with one to three things painted in that real fields hold and the simulator does not: a
    robot's white plastic with a black joint, the dark foot of a goal frame or a table, a leg with a shoe,
    white plastic with dark spots that is not round. They are painted away from ``ball`` (x, y, radius px);
    ``painted`` gets the centre and size (px) of each."""
    out = image.copy()
    height, width = out.shape[:2]
    for _ in range(int(rng.integers(1, 4))):
        size = rng.uniform(0.015, 0.1) * width
        for _ in range(10):
            x, y = rng.uniform(0, width), rng.uniform(0.2 * height, height)
            if ball is None or math.hypot(x - ball[0], y - ball[1]) > 1.5 * ball[2] + 2.5 * size:
                break
        else:
            continue
        kind = int(rng.integers(0, 4))
        if painted is not None:
            painted.append((x, y, size))
        white = tuple(int(v) for v in np.clip(rng.normal(215, 25) + rng.normal(0, 12, 3), 120, 255))
        dark = tuple(int(v) for v in np.clip(rng.normal(40, 20) + rng.normal(0, 10, 3), 0, 110))
        centre = (int(x), int(y))
        if kind == 0:  # white plastic with a black joint in it
            axes = (int(size), int(size * rng.uniform(0.6, 1.5)))
            cv2.ellipse(out, centre, axes, rng.uniform(0, 180), 0, 360, white, -1)
            cv2.circle(out, (int(x + rng.normal(0, 0.2) * size), int(y + rng.normal(0, 0.2) * size)), int(size * rng.uniform(0.25, 0.6)), dark, -1)
        elif kind == 1:  # a goal frame's or table's dark foot, a bar rising from it
            cv2.ellipse(out, centre, (int(size), int(size * rng.uniform(0.2, 0.5))), 0, 0, 360, dark, -1)
            bar = max(1, int(size * rng.uniform(0.15, 0.4)))
            cv2.rectangle(out, (int(x) - bar, 0 if rng.random() < 0.5 else int(y - 4 * size)), (int(x) + bar, int(y)), dark, -1)
        elif kind == 2:  # a leg with a shoe
            leg = tuple(int(v) for v in rng.integers(20, 200, 3))
            cv2.rectangle(out, (int(x - 0.4 * size), 0), (int(x + 0.4 * size), int(y)), leg, -1)
            cv2.ellipse(out, centre, (int(size), int(size * 0.45)), 0, 0, 360, dark, -1)
        else:  # white plastic, not round, with dark spots
            points = np.array([[x + rng.uniform(-1.5, 1.5) * size, y + rng.uniform(-1.5, 1.5) * size] for _ in range(5)], np.int32)
            cv2.fillConvexPoly(out, cv2.convexHull(points), white)
            for _ in range(int(rng.integers(1, 4))):
                cv2.circle(out, (int(x + rng.normal(0, 0.5) * size), int(y + rng.normal(0, 0.5) * size)),
                           max(1, int(size * rng.uniform(0.1, 0.35))), dark, -1)
    return cv2.GaussianBlur(out, (3, 3), 0) if rng.random() < 0.5 else out


class Collector:
    """Rows of features with labels from frames run through the perception modules."""

    def __init__(self, rng: np.random.Generator) -> None:
        self.rows: list[np.ndarray] = []
        self.labels: list[int] = []
        self.groups: list[int] = []
        self.rng = rng

    def add(self, perception: Perception, camera: str, truth: tuple[float, float, float] | None, group: int,
            others: Sequence[tuple[float, float, float]] = ()) -> None:
        """The candidates the detector examined in ``camera``'s image of the last frame, jittered true balls
        and the painted things (``others``: centre and size, px) as if proposed; ``truth``: the ball's centre
        and radius (px), None without a visible ball."""
        detector: SPLBallDetector = perception.manager.module("SPLBallDetector")
        segmented = perception.manager.blackboard.get("SegmentedImage")
        hsv, green = segmented.hsv(camera), segmented.green(camera)
        if hsv.size == 0:
            return
        light = carpet(hsv, green)
        for seen, spot, _ in detector.examined:
            if seen != camera:
                continue
            if truth is None:
                label = 0
            else:
                distance = math.hypot(spot.x - truth[0], spot.y - truth[1])
                label = 1 if distance <= 0.75 * truth[2] else 0 if distance > 1.5 * truth[2] else -1
            if label >= 0:
                self.append(features(hsv, green, spot.x, spot.y, spot.radius, *light), label, group)
        for x, y, size in others:  # the detector proposes only those whose size fits a ball there: these are rarer
            self.append(features(hsv, green, x + self.rng.normal(0.0, 0.2) * size, y + self.rng.normal(0.0, 0.2) * size,
                                 size * self.rng.uniform(0.6, 1.3), *light), 0, group)
        if truth is not None and truth[2] >= 2.0:
            # the detector's centre and size are estimates (a ball cut by the image's edge, merged with a shadow)
            for _ in range(3):
                x, y = truth[0] + self.rng.normal(0.0, 0.25) * truth[2], truth[1] + self.rng.normal(0.0, 0.25) * truth[2]
                self.append(features(hsv, green, x, y, truth[2] * self.rng.uniform(0.8, 1.35), *light), 1, group)

    def append(self, row: np.ndarray, label: int, group: int) -> None:
        self.rows.append(row)
        self.labels.append(label)
        self.groups.append(group)


def perception_without_classifier() -> Perception:
    """The perception modules with the detector's classifier off: training sees every candidate."""
    perception = Perception()
    perception.manager.module("SPLBallDetector").parameters.classifier = False
    return perception


def simulated(collector: Collector, engine: str, scenes: int, seed: int, painted_negatives: bool = False) -> None:
    """Rows from ``scenes`` random rendered scenes at each resolution, through the platform's own camera
    pipeline and hall (``--realism``, ``LEVELS`` in turn, a hall of its own every ``HALL_SCENES`` scenes and a camera
    of its own every scene); ``painted_negatives``: every painted distractor is a row too, not only those the
    detector proposes (tried: it made the model timid, recall on real balls fell)."""
    from tafel.tools.simulation.scene_frames import SceneRenderer

    rng = np.random.default_rng(seed)
    for resolution in RESOLUTIONS:
        made = 0
        while made < scenes:
            level = LEVELS[(made // HALL_SCENES) % len(LEVELS)]
            with SceneRenderer(engine, resolution, realism=level, seed=int(rng.integers(2**31))) as renderer:
                perception = perception_without_classifier()
                for _ in range(min(HALL_SCENES, scenes - made)):
                    scene = random_ball_scene(rng)
                    while scene is None:
                        scene = random_ball_scene(rng)
                    pose, head, ball = scene
                    made += 1
                    renderer.new_cameras(int(rng.integers(2**31)))
                    painted: dict[str, list[tuple[float, float, float]]] = {"top": [], "bottom": []}

                    def paint(camera: str, image: np.ndarray, circle: tuple[float, float, float] | None,
                              marks: dict[str, list[tuple[float, float, float]]] = painted) -> np.ndarray:
                        return distractors(image, rng, circle, marks[camera]) if rng.random() < 0.7 else image

                    views = renderer.frames(pose, head, ball, paint)
                    for _ in range(2):  # the field colour settles on this frame's light
                        perception(views)
                    for camera, view in views.items():
                        truth = view.ball_image if view.ball_image is not None and view.ball_visible >= 0.5 else None
                        collector.add(perception, camera, truth, group=made, others=painted[camera] if painted_negatives else ())


def real(collector: Collector, folder: Path, variants: int) -> None:
    """Rows from the labelled real images of ``folder`` (labels.csv), each in ``variants`` realistic versions at both resolutions."""
    labels = folder / "labels.csv"
    if not labels.is_file():
        raise SystemExit(f"{folder} has no labels.csv: give a folder laid out as ../shared/real-images, or --real '' for none")
    empty = LabelledFrame("", np.zeros((0, 0, 3), np.uint8), CameraMatrix(), 0.0, 0.0, (0.0, 0.0, 0.0), (0.0, 0.0), 0.0, None, 0.0)
    with labels.open() as handle:
        rows = list(csv.DictReader(handle))
    for index, row in enumerate(rows):
        posed = posed_image(folder / row["image"], camera=row.get("camera") or None)
        for variant in range(variants):
            for resolution in RESOLUTIONS:
                scale = int(resolution.split("x")[0]) / posed.image.shape[1]
                image = posed.image if scale == 1.0 else cv2.resize(posed.image, None, fx=scale, fy=scale, interpolation=cv2.INTER_AREA)
                if variant:  # a real image through another camera still: the mild level, on top of its own
                    image = camera_like(image, collector.rng, "mild")
                view = LabelledFrame(posed.camera, image, posed.matrix, posed.horizontal_fov, posed.vertical_fov, (0.0, 0.0, 0.0),
                                     (0.0, 0.0), 0.0, None, 0.0)
                perception = perception_without_classifier()
                frames = {"top": view, "bottom": empty} if posed.camera == "top" else {"top": empty, "bottom": view}
                for _ in range(2):
                    perception(frames)
                truth = None
                if row.get("ball_visible") == "y":
                    truth = (float(row["ball_x"]) * scale, float(row["ball_y"]) * scale, float(row["ball_r"]) * scale)
                collector.add(perception, posed.camera, truth, group=-1 - index)


def labelled_images(folder: Path) -> list[str]:
    """The images (paths below ``folder``) that ``folder``'s labels.csv lists: what ``real`` trains on."""
    with (folder / "labels.csv").open() as labels:
        return [row["image"] for row in csv.DictReader(labels)]


def arguments() -> argparse.ArgumentParser:
    """The command line: what the data and the network are."""
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--scenes", type=int, default=250, help="random rendered scenes per resolution (both cameras each)")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--engine", default="mujoco", help="the simulator that renders (mujoco or pybullet)")
    parser.add_argument("--real", default="", help="labelled real images (labels.csv), none by default: the only ones the "
                        "project may train on (tests/data/real_images) are benchmark images, and training on them is training on the test")
    parser.add_argument("--real-variants", type=int, default=6, help="realistic versions of each real image")
    parser.add_argument("--painted-negatives", action="store_true", help="every painted distractor as a row, not only those proposed")
    parser.add_argument("--hidden", type=int, default=24, help="hidden units of the network")
    parser.add_argument("--epochs", type=int, default=600, help="full-batch training steps")
    parser.add_argument("--out", default=str(MODEL_PATH), help="where the model is written (.npz)")
    return parser


def main(argv: list[str] | None = None) -> None:
    parser = arguments()
    args = parser.parse_args(argv)
    if args.scenes < 0 or args.real_variants < 1:
        parser.error("--scenes must be 0 or more and --real-variants 1 or more")
    os.environ.setdefault("MUJOCO_GL", "egl")
    started = time.perf_counter()
    collector = Collector(np.random.default_rng(args.seed))
    if args.scenes:
        simulated(collector, args.engine, args.scenes, args.seed, args.painted_negatives)
    if args.real:
        real(collector, Path(args.real), args.real_variants)
    rows, labels, groups = np.array(collector.rows, np.float32).reshape(-1, FEATURES), np.array(collector.labels), np.array(collector.groups)
    # held out: every fifth scene (whole scenes, so that no scene is on both sides)
    held = groups % 5 == 4
    figures: dict[str, Any] = {"rows": len(rows), "balls": int(labels.sum())}
    if held.any() and len(np.unique(labels[held])) == 2 and len(np.unique(labels[~held])) == 2:
        check = train(rows[~held], labels[~held], args.hidden, args.epochs, args.seed)
        said = check.scores(rows[held]) >= 0.0
        truth = labels[held] == 1
        figures |= {"held_out_ball_recall": round(float((said & truth).sum() / max(1, truth.sum())), 4),
                    "held_out_false_positive_rate": round(float((said & ~truth).sum() / max(1, (~truth).sum())), 4)}
    model = train(rows, labels, args.hidden, args.epochs, args.seed)
    out = Path(args.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    model.save(out)
    figures |= {"model": str(out), "model_bytes": out.stat().st_size, "wall_s": round(time.perf_counter() - started, 1)}
    print(json.dumps(figures))


if __name__ == "__main__":
    main()
