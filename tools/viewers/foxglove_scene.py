"""Foxglove's drawing primitives for what Tafel shows: the field, the robot, balls, the debug drawings on
the field and robot canvases (scene entities) and on the images (annotations), camera calibrations,
and the colours, poses and quaternions they are made of (metres, as Foxglove wants them)."""

from __future__ import annotations

import math
from collections.abc import Iterable
from typing import Any

import numpy as np
from foxglove import messages as fm

from tafel.representations import field
from tafel.representations.geometry import Pose2D

M = 0.001  # mm -> m
COLORS = {"black": (0, 0, 0), "white": (1, 1, 1), "red": (1, 0, 0), "green": (0, 0.6, 0), "blue": (0, 0, 1), "yellow": (1, 1, 0),
          "orange": (1, 0.55, 0), "gray": (0.5, 0.5, 0.5), "grey": (0.5, 0.5, 0.5), "cyan": (0, 1, 1), "magenta": (1, 0, 1),
          "purple": (0.5, 0, 0.5), "pink": (1, 0.75, 0.8), "brown": (0.6, 0.3, 0.1)}


def color(name: str, alpha: float = 1.0) -> fm.Color:
    """A drawing colour (``orange``, ``#ff8800``) as Foxglove's; unknown names are black."""
    if name.startswith("#") and len(name) == 7:
        try:
            r, g, b = (int(name[i:i + 2], 16) / 255 for i in (1, 3, 5))
            return fm.Color(r=r, g=g, b=b, a=alpha)
        except ValueError:
            pass
    r, g, b = COLORS.get(name.lower(), (0, 0, 0))
    return fm.Color(r=r, g=g, b=b, a=alpha)


def timestamp(ns: int) -> fm.Timestamp:
    return fm.Timestamp(sec=ns // 1_000_000_000, nsec=ns % 1_000_000_000)


def quaternion(rotation: np.ndarray) -> fm.Quaternion:
    """A rotation matrix as a unit quaternion."""
    m = np.asarray(rotation, dtype=float)
    w = math.sqrt(max(0.0, 1.0 + m[0, 0] + m[1, 1] + m[2, 2])) / 2
    x = math.copysign(math.sqrt(max(0.0, 1.0 + m[0, 0] - m[1, 1] - m[2, 2])) / 2, m[2, 1] - m[1, 2])
    y = math.copysign(math.sqrt(max(0.0, 1.0 - m[0, 0] + m[1, 1] - m[2, 2])) / 2, m[0, 2] - m[2, 0])
    z = math.copysign(math.sqrt(max(0.0, 1.0 - m[0, 0] - m[1, 1] + m[2, 2])) / 2, m[1, 0] - m[0, 1])
    return fm.Quaternion(x=x, y=y, z=z, w=w)


def yaw_quaternion(angle: float) -> fm.Quaternion:
    return fm.Quaternion(x=0.0, y=0.0, z=math.sin(angle / 2), w=math.cos(angle / 2))


def pose(x: float = 0.0, y: float = 0.0, z: float = 0.0, orientation: fm.Quaternion | None = None) -> fm.Pose:
    """A pose from metres (and an orientation, none: unrotated)."""
    return fm.Pose(position=fm.Vector3(x=x, y=y, z=z), orientation=orientation or fm.Quaternion(x=0, y=0, z=0, w=1))


#: the optical frame (z along the view, x right, y down in the image) in Tafel's camera frame (x along
#: the view, y left, z up): what Foxglove expects of an image's frame
OPTICAL = np.array([[0.0, 0.0, 1.0], [-1.0, 0.0, 0.0], [0.0, -1.0, 0.0]])


def field_entity(now: fm.Timestamp) -> fm.SceneEntity:
    """The carpet, the lines and both goals (white posts and crossbar)."""
    points = [fm.Point3(x=v[0] * M, y=v[1] * M, z=0.001) for line in field.all_markings() for v in (line[:2], line[2:])]
    carpet = fm.CubePrimitive(pose=pose(z=-0.005), size=fm.Vector3(x=(field.LENGTH + 2 * field.BORDER_STRIP) * M,
                                                                       y=(field.WIDTH + 2 * field.BORDER_STRIP) * M, z=0.01),
                              color=fm.Color(r=0.1, g=0.5, b=0.15, a=1.0))
    posts = []
    post = field.GOAL_POST_DIAMETER * M
    for side in (-1, 1):
        x = side * (field.LENGTH / 2 + field.GOAL_POST_DIAMETER / 2) * M
        for y in (-1, 1):
            posts.append(fm.CylinderPrimitive(pose=pose(x, y * (field.GOAL_INNER_WIDTH + field.GOAL_POST_DIAMETER) / 2 * M,
                                                        field.GOAL_HEIGHT / 2 * M),
                                              size=fm.Vector3(x=post, y=post, z=field.GOAL_HEIGHT * M), color=color("white")))
        posts.append(fm.CubePrimitive(pose=pose(x, 0, field.GOAL_HEIGHT * M),
                                      size=fm.Vector3(x=post, y=(field.GOAL_INNER_WIDTH + 2 * field.GOAL_POST_DIAMETER) * M, z=post),
                                      color=color("white")))
    return fm.SceneEntity(timestamp=now, frame_id="field", id="field", frame_locked=True,
                          lines=[fm.LinePrimitive(type=fm.LinePrimitiveLineType.LineList, pose=pose(), thickness=0.05,
                                                  scale_invariant=False, points=points, color=color("white"))],
                          cubes=[carpet, *[p for p in posts if isinstance(p, fm.CubePrimitive)]],
                          cylinders=[p for p in posts if isinstance(p, fm.CylinderPrimitive)])


def robot_entity(now: fm.Timestamp) -> list[fm.SceneEntity]:
    """The robot: its torso and head (torso frame) and its feet (robot frame, on the ground)."""
    grey = fm.Color(r=0.85, g=0.85, b=0.88, a=1.0)
    torso = fm.SceneEntity(timestamp=now, frame_id="torso", id="robot/torso", frame_locked=True,
                           cubes=[fm.CubePrimitive(pose=pose(-0.01, 0, 0.06), size=fm.Vector3(x=0.1, y=0.15, z=0.16), color=grey)],
                           spheres=[fm.SpherePrimitive(pose=pose(0, 0, 0.2), size=fm.Vector3(x=0.12, y=0.12, z=0.12), color=grey)])
    feet = fm.SceneEntity(timestamp=now, frame_id="robot", id="robot/feet", frame_locked=True,
                          cubes=[fm.CubePrimitive(pose=pose(0.02, side * 0.05, 0.01), size=fm.Vector3(x=0.16, y=0.09, z=0.02), color=grey)
                                 for side in (-1, 1)])
    return [torso, feet]


def ball_entity(now: fm.Timestamp, entity_id: str, positions: Iterable[tuple[float, float]], rgba: fm.Color) -> fm.SceneEntity:
    """Balls (robot frame, mm) as spheres on the ground."""
    size = 2 * field.BALL_RADIUS * M
    return fm.SceneEntity(timestamp=now, frame_id="robot", id=entity_id, frame_locked=True,
                          spheres=[fm.SpherePrimitive(pose=pose(x * M, y * M, field.BALL_RADIUS * M), size=fm.Vector3(x=size, y=size, z=size),
                                                      color=rgba) for x, y in positions])


def drawings_entity(now: fm.Timestamp, context: str, canvas: str, primitives: Iterable[Any]) -> fm.SceneEntity:
    """The ``field`` canvas (field frame, mm) or the ``robot`` canvas (robot frame, mm): lines, rectangles,
    circles, robot poses as lines; texts as text."""
    lines, texts = [], []
    for p in primitives:
        points = _outline(p.kind, p.points)
        if points:
            lines.append(fm.LinePrimitive(type=fm.LinePrimitiveLineType.LineStrip, pose=pose(), thickness=max(0.01, p.width * 0.01),
                                          scale_invariant=False, points=[fm.Point3(x=x * M, y=y * M, z=0.02) for x, y in points],
                                          color=color(p.color)))
        elif p.kind == "text" and len(p.points) >= 2:
            texts.append(fm.TextPrimitive(pose=pose(p.points[0] * M, p.points[1] * M, 0.05), billboard=True, font_size=p.width or 12.0,
                                          scale_invariant=True, color=color(p.color), text=p.text))
    suffix = "" if canvas == "field" else f"/{canvas}"
    return fm.SceneEntity(timestamp=now, frame_id=canvas, id=f"drawings/{context}{suffix}", frame_locked=True, lines=lines, texts=texts)


def _outline(kind: str, points: list[float]) -> list[tuple[float, float]]:
    """The points of one drawing's outline; empty for texts and what cannot be drawn."""
    if kind == "line" and len(points) >= 4:
        return [(points[0], points[1]), (points[2], points[3])]
    if kind == "rectangle" and len(points) >= 4:
        x1, y1, x2, y2 = points[:4]
        return [(x1, y1), (x2, y1), (x2, y2), (x1, y2), (x1, y1)]
    if kind == "circle" and len(points) >= 3:
        x, y, r = points[:3]
        return [(x + r * math.cos(a), y + r * math.sin(a)) for a in np.linspace(0, math.tau, 25)]
    if kind == "robot_pose" and len(points) >= 3:
        pose = Pose2D(*points[:3])  # a triangle pointing where the robot faces
        return [pose.to_global(-100.0, -80.0), pose.to_global(150.0, 0.0), pose.to_global(-100.0, 80.0), pose.to_global(-100.0, -80.0)]
    return []


def image_annotations(stamp: fm.Timestamp, primitives: Iterable[Any]) -> fm.ImageAnnotations:
    """One image canvas (px) as Foxglove's image annotations."""
    circles, points, texts = [], [], []
    for p in primitives:
        if p.kind == "circle" and len(p.points) >= 3:
            circles.append(fm.CircleAnnotation(timestamp=stamp, position=fm.Point2(x=p.points[0], y=p.points[1]), diameter=2 * p.points[2],
                                               thickness=p.width, fill_color=color(p.color, 0.0), outline_color=color(p.color)))
        elif p.kind == "text" and len(p.points) >= 2:
            texts.append(fm.TextAnnotation(timestamp=stamp, position=fm.Point2(x=p.points[0], y=p.points[1]), text=p.text,
                                           font_size=p.width or 12.0, text_color=color(p.color), background_color=color("black", 0.0)))
        elif outline := _outline(p.kind, p.points):
            points.append(fm.PointsAnnotation(timestamp=stamp, type=fm.PointsAnnotationType.LineStrip, thickness=p.width,
                                              points=[fm.Point2(x=x, y=y) for x, y in outline], outline_color=color(p.color)))
    return fm.ImageAnnotations(circles=circles, points=points, texts=texts)


def calibration(stamp: fm.Timestamp, camera: str, width: int, height: int, horizontal_fov: float, vertical_fov: float) -> fm.CameraCalibration:
    """A pinhole model from the image size and the field of view (the simulators' cameras have no distortion)."""
    fx = width / 2 / math.tan(horizontal_fov / 2) if horizontal_fov > 0 else float(width)
    fy = height / 2 / math.tan(vertical_fov / 2) if vertical_fov > 0 else fx
    cx, cy = width / 2, height / 2
    return fm.CameraCalibration(timestamp=stamp, frame_id=f"camera_{camera}_optical", width=width, height=height,
                                distortion_model="plumb_bob", D=[0.0] * 5, K=[fx, 0, cx, 0, fy, cy, 0, 0, 1],
                                R=[1, 0, 0, 0, 1, 0, 0, 0, 1], P=[fx, 0, cx, 0, 0, fy, cy, 0, 0, 0, 1, 0])
