"""What Tafel shows in Foxglove and Lichtblick: representations turned into Foxglove's well-known messages.

The same topics in recordings and live (metres and seconds, as Foxglove wants them):

| topic | schema | from |
|---|---|---|
| ``/camera/top``, ``/camera/bottom`` | ``foxglove.CompressedImage`` (JPEG) | ``CameraImageTop/Bottom`` |
| ``/camera/top/calibration``, ... | ``foxglove.CameraCalibration`` | the image size and field of view |
| ``/camera/top/annotations``, ... | ``foxglove.ImageAnnotations`` | ``DebugDrawings`` on ``image:top/bottom``, at the image's time |
| ``/scene`` | ``foxglove.SceneUpdate`` | the field (once), robot, ``BallModel``, ``BallPercept``, ``field`` and ``robot`` drawings |
| ``/tf`` | ``foxglove.FrameTransforms`` | field -> robot (``RobotPose`` while valid, else ``Odometry``), robot -> torso (``TorsoPose``), torso -> cameras |
| ``/joints``, ``/imu``, ``/fsr``, ``/timing``, ``/rates`` | JSON by name, for the Plot panel | joints, IMU, foot pressure, ``ModuleTimes``, frame times |
| ``/behavior`` | JSON, for the Raw Messages panel | ``ActivationGraph``: the active options, root first, and the path on one line |
| ``/log`` | ``foxglove.Log`` | the program's log lines |

A ``FoxgloveTranslator`` is fed every representation as it is recorded (in the writer thread, or in the
live bridge's thread: never in a loop) and answers with the messages to send. Message timestamps are
the frame times moved onto the wall clock by one fixed offset, so that an image and its annotations
share one timestamp and transforms line up with everything else.
"""

from __future__ import annotations

import json
import logging
import time
from collections import deque
from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass
from typing import Any

import cv2
import numpy as np
from foxglove import messages as fm

from tafel.core.logs import ExtraMessage
from tafel.core.logs.serialization import deserialize
from tafel.debug.concepts import DebugDrawings, ModuleTimes
from tafel.modules.motion.kinematics import angles_by_name, link_poses
from tafel.representations.behavior import ActivationGraph
from tafel.representations.infrastructure import FrameInfo
from tafel.representations.modeling import BallModel, RobotPose
from tafel.representations.motion import (
    JOINT_NAMES,
    CameraMatrixBottom,
    CameraMatrixTop,
    FsrData,
    InertialSensorData,
    JointCommand,
    JointSensorData,
    TorsoPose,
)
from tafel.representations.motion_control import Odometry
from tafel.representations.perception import BallPercept, CameraImageBottom, CameraImageTop
from tafel.tools.viewers.foxglove_scene import (
    OPTICAL,
    M,
    ball_entity,
    calibration,
    color,
    drawings_entity,
    field_entity,
    image_annotations,
    quaternion,
    robot_entity,
    timestamp,
    yaw_quaternion,
)
from tafel.tools.viewers.robot_links import PARENTS

CAMERAS = {CameraImageTop: "top", CameraImageBottom: "bottom"}
#: the eight foot pressure sensors in ``FsrData`` order
FSR_NAMES = tuple(f"{foot}_{where}" for foot in ("left", "right") for where in ("front_left", "front_right", "rear_left", "rear_right"))
CAMERA_MATRICES = {CameraMatrixTop: "top", CameraMatrixBottom: "bottom"}
#: every topic, for a client that subscribes to everything and for the layouts
TOPICS = ("/camera/top", "/camera/bottom", "/camera/top/calibration", "/camera/bottom/calibration", "/camera/top/annotations",
          "/camera/bottom/annotations", "/scene", "/tf", "/joints", "/imu", "/fsr", "/timing", "/rates", "/behavior", "/log")
#: which representations each topic is made of: what the live bridge asks the loops for
NEEDS: dict[str, tuple[type, ...]] = {
    "/camera/top": (CameraImageTop,), "/camera/bottom": (CameraImageBottom,),
    "/camera/top/calibration": (CameraImageTop,), "/camera/bottom/calibration": (CameraImageBottom,),
    "/camera/top/annotations": (CameraImageTop, DebugDrawings), "/camera/bottom/annotations": (CameraImageBottom, DebugDrawings),
    "/scene": (BallModel, BallPercept, DebugDrawings, FrameInfo),
    "/tf": (Odometry, TorsoPose, CameraMatrixTop, CameraMatrixBottom, JointSensorData),
    "/joints": (JointSensorData, JointCommand), "/imu": (InertialSensorData,), "/fsr": (FsrData,), "/timing": (ModuleTimes,),
    "/rates": (FrameInfo,), "/behavior": (ActivationGraph,), "/log": (),
}
#: every representation some topic is made of; the others are not even decoded
USED = frozenset(rep for reps in NEEDS.values() for rep in reps) | frozenset(CAMERA_MATRICES) | {RobotPose}


def _numbers(names: Iterable[str]) -> dict[str, Any]:
    """An object of these named numbers (any of them may be missing, no others)."""
    return {"type": "object", "properties": {name: {"type": "number"} for name in names}, "additionalProperties": False}


def _per_context(values: dict[str, Any]) -> dict[str, Any]:
    """An object by context name (one context a message); the two of the program's plan are named."""
    return {"type": "object", "properties": {context: values for context in ("cognition", "motion")}, "additionalProperties": values}


#: the JSON Schema of each JSON topic: what Foxglove's panels (Plot, Raw Messages) offer as fields
JSON_SCHEMAS: dict[str, bytes] = {topic: json.dumps({"title": title, **schema}).encode() for topic, title, schema in (
    ("/joints", "Joint values by name: measured (position, temperature) and commanded (command, stiffness)",
     {"type": "object", "properties": {key: _numbers(JOINT_NAMES) for key in ("position", "temperature", "command", "stiffness")},
      "required": ["command", "stiffness"], "additionalProperties": False}),
    ("/imu", "Inertial sensors: accelerometer (m/s^2), gyroscope (rad/s), torso angles (rad)",
     {"type": "object", "properties": {"accelerometer": _numbers("xyz"), "gyroscope": _numbers("xyz"), "angles": _numbers(("roll", "pitch"))},
      "required": ["accelerometer", "gyroscope", "angles"], "additionalProperties": False}),
    ("/fsr", "Foot pressure sensors by name (kg)", {**_numbers(FSR_NAMES), "required": list(FSR_NAMES)}),
    ("/timing", "Module times (ms) by context and module", _per_context({"type": "object", "additionalProperties": {"type": "number"}})),
    ("/rates", "Frames per second by context", _per_context({"type": "number"})),
    ("/behavior", "The behaviour's active options, root first: name, state, s in option and in state, depth, parameters",
     {"type": "object", "properties": {
         "path": {"type": "string"},
         "options": {"type": "array", "items": {"type": "object", "properties": {
             "name": {"type": "string"}, "state": {"type": "string"}, "time_in_option": {"type": "number"},
             "time_in_state": {"type": "number"}, "depth": {"type": "integer"}, "parameters": {"type": "string"}},
             "required": ["name", "state", "time_in_option", "time_in_state", "depth", "parameters"], "additionalProperties": False}}},
      "required": ["path", "options"], "additionalProperties": False}),
)}


@dataclass
class Outgoing:
    """One message for Foxglove: ``message`` is a ``foxglove.messages`` object or, on JSON topics, a dict."""

    topic: str
    message: Any
    time_ns: int  # frame time
    wall_ns: int  # when Foxglove shows it

    def encoded(self) -> ExtraMessage:
        """The message as bytes with its schema, for an MCAP file."""
        if isinstance(self.message, dict):
            return ExtraMessage(self.topic, json_schema_name(self.topic), "jsonschema", JSON_SCHEMAS[self.topic],
                                "json", json.dumps(self.message, separators=(",", ":")).encode(), self.time_ns, self.wall_ns)
        schema = self.message.get_schema()
        return ExtraMessage(self.topic, schema.name, schema.encoding, schema.data, "protobuf", self.message.encode(),
                            self.time_ns, self.wall_ns)


def json_schema_name(topic: str) -> str:
    """The schema name of a JSON topic: ``/joints`` is ``tafel.foxglove.joints``."""
    return f"tafel.foxglove{topic.replace('/', '.')}"


def named(values: Iterable[float]) -> dict[str, float]:
    """Per-joint values by joint name (``JOINT_NAMES`` order)."""
    return {name: float(v) for name, v in zip(JOINT_NAMES, values)}


class FoxgloveTranslator:
    """Turns representations, one at a time as they are recorded, into Foxglove messages.

    ``wanted`` says which topics to make (all when None; the live bridge passes those with
    subscribers), so that nothing is encoded for a topic nobody looks at.
    """

    def __init__(self, jpeg_quality: int = 80, wanted: Callable[[str], bool] | None = None) -> None:
        self.jpeg_quality = jpeg_quality
        self.wanted = wanted or (lambda _topic: True)
        self.offset_ns: int | None = None  # wall clock - frame time, fixed at the first message
        self.field_sent = False
        self.images: dict[str, tuple[int, int, int]] = {}  # camera -> (time ns, width, height) of its last image
        self.image_context = ""  # the context the images come to: its drawings annotate them
        self.torso = (np.eye(3), np.array([0.0, 0.0, 300.0]))
        self.cameras: dict[str, tuple[np.ndarray, np.ndarray]] = {}
        self.frame_times: dict[str, deque[int]] = {}
        self.joints: dict[str, dict[str, float]] = {}
        self.positions: np.ndarray | None = None  # the last measured joint angles: the links' frames on /tf
        self.pose: Any = None  # the last valid RobotPose

    def resend_field(self) -> None:
        """Send the field again with the next scene (a client subscribed to the scene anew)."""
        self.field_sent = False

    # ------------------------------------------------------------------------------- entry points
    def translate(self, topic: str, cls: type, time_ns: int, wall_ns: int, data: bytes) -> list[ExtraMessage]:
        """``LogWriter``'s hook: one recorded representation (protobuf bytes) to encoded messages."""
        if cls not in USED:
            return []
        return [out.encoded() for out in self.feed(topic.split("/", 1)[0], deserialize(cls, data), time_ns, wall_ns)]

    def feed(self, context: str, value: Any, time_ns: int, wall_ns: int | None = None) -> list[Outgoing]:
        """One representation of ``context`` at frame time ``time_ns``: the messages it makes."""
        wall = wall_ns if wall_ns is not None else time.time_ns()
        if self.offset_ns is None:
            self.offset_ns = wall - time_ns
        return list(self._messages(context, value, time_ns, wall))

    def log_record(self, record: logging.LogRecord, time_ns: int) -> Outgoing | None:
        """A log line as ``foxglove.Log`` (at the wall-clock time it was logged)."""
        if not self.wanted("/log"):
            return None
        level = {logging.DEBUG: fm.LogLevel.Debug, logging.INFO: fm.LogLevel.Info, logging.WARNING: fm.LogLevel.Warning,
                 logging.ERROR: fm.LogLevel.Error, logging.CRITICAL: fm.LogLevel.Fatal}.get(record.levelno, fm.LogLevel.Info)
        wall = int(record.created * 1e9)
        message = fm.Log(timestamp=timestamp(wall), level=level, message=record.getMessage(), name=record.name,
                         file=record.pathname, line=record.lineno)
        return Outgoing("/log", message, time_ns, wall)

    # ----------------------------------------------------------------------------- translation
    def _stamp(self, time_ns: int) -> fm.Timestamp:
        """A frame time as a message timestamp: on the wall clock, by the offset of the first message."""
        return timestamp(time_ns + (self.offset_ns or 0))

    def _messages(self, context: str, value: Any, time_ns: int, wall: int) -> Iterator[Outgoing]:
        stamp = self._stamp(time_ns)
        kind = type(value)
        if kind in CAMERAS:
            self.image_context = context
            yield from self._image(CAMERAS[kind], value, time_ns, wall)
        elif kind is DebugDrawings:
            yield from self._drawings(context, value, time_ns, wall, stamp)
        elif kind in CAMERA_MATRICES:
            self.cameras[CAMERA_MATRICES[kind]] = (np.asarray(value.rotation, float), np.asarray(value.translation, float))
        elif kind is TorsoPose:
            self.torso = (np.asarray(value.rotation, float), np.asarray(value.translation, float))
        elif kind is RobotPose:
            self.pose = value if value.valid else None
        elif kind is Odometry and self.wanted("/tf"):
            yield Outgoing("/tf", self._transforms(value, stamp), time_ns, wall)
        elif kind is BallModel and self.wanted("/scene"):
            yield Outgoing("/scene", self._scene(value, stamp), time_ns, wall)
        elif kind is BallPercept and self.wanted("/scene"):
            seen = [(value.x, value.y)] if value.seen else []
            yield Outgoing("/scene", fm.SceneUpdate(entities=[ball_entity(stamp, "ball/percept", seen, color("yellow", 0.6))]), time_ns, wall)
        elif kind is JointSensorData:
            self.positions = np.asarray(value.position, float)
            self.joints = {"position": named(value.position), "temperature": named(value.temperature)}
        elif kind is JointCommand and self.wanted("/joints"):  # once per motion frame, with the last measurement
            yield Outgoing("/joints", {**self.joints, "command": named(value.position), "stiffness": named(value.stiffness)}, time_ns, wall)
        elif kind is InertialSensorData and self.wanted("/imu"):
            yield Outgoing("/imu", {"accelerometer": dict(zip("xyz", map(float, value.accelerometer))),
                                    "gyroscope": dict(zip("xyz", map(float, value.gyroscope))),
                                    "angles": {"roll": float(value.angles[0]), "pitch": float(value.angles[1])}}, time_ns, wall)
        elif kind is FsrData and self.wanted("/fsr"):
            yield Outgoing("/fsr", dict(zip(FSR_NAMES, map(float, value.pressure))), time_ns, wall)
        elif kind is ModuleTimes and self.wanted("/timing"):
            yield Outgoing("/timing", {context: dict(zip(value.names, value.milliseconds))}, time_ns, wall)
        elif kind is FrameInfo:
            yield from self._rates(context, time_ns, wall)
        elif kind is ActivationGraph and self.wanted("/behavior"):
            yield Outgoing("/behavior", {"path": value.status_text(), "options": [
                {"name": o.name, "state": o.state, "time_in_option": float(o.time_in_option), "time_in_state": float(o.time_in_state),
                 "depth": int(o.depth), "parameters": o.parameters} for o in value.options]}, time_ns, wall)

    def _image(self, camera: str, value: Any, time_ns: int, wall: int) -> Iterator[Outgoing]:
        image = np.asarray(value.image)
        if image.ndim != 3 or not image.size:
            return
        height, width = image.shape[:2]
        taken = value.time_ns or time_ns
        self.images[camera] = (taken, width, height)
        stamp = self._stamp(taken)
        frame_id = f"camera_{camera}_optical"
        if self.wanted(f"/camera/{camera}"):
            ok, jpeg = cv2.imencode(".jpg", cv2.cvtColor(image, cv2.COLOR_RGB2BGR), [cv2.IMWRITE_JPEG_QUALITY, self.jpeg_quality])
            if ok:
                yield Outgoing(f"/camera/{camera}", fm.CompressedImage(timestamp=stamp, frame_id=frame_id, data=jpeg.tobytes(), format="jpeg"),
                               time_ns, wall)
        if self.wanted(f"/camera/{camera}/calibration"):
            yield Outgoing(f"/camera/{camera}/calibration",
                           calibration(stamp, camera, width, height, value.horizontal_fov, value.vertical_fov), time_ns, wall)

    def _drawings(self, context: str, value: Any, time_ns: int, wall: int, stamp: fm.Timestamp) -> Iterator[Outgoing]:
        by_canvas: dict[str, list[Any]] = {}
        for primitive in value.primitives:
            by_canvas.setdefault(primitive.canvas, []).append(primitive)
        for camera in ("top", "bottom"):
            topic = f"/camera/{camera}/annotations"
            if camera in self.images and context == self.image_context and self.wanted(topic):
                image_stamp = self._stamp(self.images[camera][0])  # the image's timestamp: the panel pairs them
                yield Outgoing(topic, image_annotations(image_stamp, by_canvas.get(f"image:{camera}", [])), time_ns, wall)
        if self.wanted("/scene"):  # every frame, also when empty: yesterday's drawings disappear
            entities = [drawings_entity(stamp, context, canvas, by_canvas.get(canvas, [])) for canvas in ("field", "robot")]
            yield Outgoing("/scene", fm.SceneUpdate(entities=entities), time_ns, wall)

    def _scene(self, ball: Any, stamp: fm.Timestamp) -> fm.SceneUpdate:
        entities = robot_entity(stamp)
        if not self.field_sent:
            entities.append(field_entity(stamp))
            self.field_sent = True
        entities.append(ball_entity(stamp, "ball/model", [(ball.x, ball.y)] if ball.valid else [], color("orange")))
        return fm.SceneUpdate(entities=entities)

    def _transforms(self, odometry: Any, stamp: fm.Timestamp) -> fm.FrameTransforms:
        rotation, translation = self.torso
        where = self.pose or odometry  # the localization's pose while it is valid, else odometry from the start
        transforms = [
            fm.FrameTransform(timestamp=stamp, parent_frame_id="field", child_frame_id="robot",
                              translation=fm.Vector3(x=where.x * M, y=where.y * M, z=0.0), rotation=yaw_quaternion(where.rotation)),
            fm.FrameTransform(timestamp=stamp, parent_frame_id="robot", child_frame_id="torso",
                              translation=fm.Vector3(x=translation[0] * M, y=translation[1] * M, z=translation[2] * M),
                              rotation=quaternion(rotation)),
        ]
        for camera, (cam_rotation, cam_translation) in self.cameras.items():
            # the camera matrices are in the robot frame: relative to the torso they are torso^-1 * camera
            relative_rotation = rotation.T @ cam_rotation
            relative_translation = rotation.T @ (cam_translation - translation)
            transforms.append(fm.FrameTransform(timestamp=stamp, parent_frame_id="torso", child_frame_id=f"camera_{camera}",
                                                translation=fm.Vector3(x=relative_translation[0] * M, y=relative_translation[1] * M,
                                                                       z=relative_translation[2] * M),
                                                rotation=quaternion(relative_rotation)))
            transforms.append(fm.FrameTransform(timestamp=stamp, parent_frame_id=f"camera_{camera}", child_frame_id=f"camera_{camera}_optical",
                                                translation=fm.Vector3(x=0, y=0, z=0), rotation=quaternion(OPTICAL)))
        transforms += self._link_transforms(stamp)
        return fm.FrameTransforms(transforms=transforms)

    def _link_transforms(self, stamp: fm.Timestamp) -> list[fm.FrameTransform]:
        """Each link's frame in its parent's (``torso`` the root), from the measured joint angles and the
        program's kinematic model: the robot in Foxglove's 3D panel."""
        if self.positions is None:
            return []
        poses = link_poses(angles_by_name(self.positions))
        transforms = []
        for link, parent in PARENTS.items():
            local = np.linalg.inv(poses[parent]) @ poses[link]
            transforms.append(fm.FrameTransform(timestamp=stamp, parent_frame_id=parent, child_frame_id=link,
                                                translation=fm.Vector3(x=local[0, 3] * M, y=local[1, 3] * M, z=local[2, 3] * M),
                                                rotation=quaternion(local[:3, :3])))
        return transforms

    def _rates(self, context: str, time_ns: int, wall: int) -> Iterator[Outgoing]:
        """Frames per second of each context over the last second of frame time."""
        times = self.frame_times.setdefault(context, deque())
        times.append(time_ns)
        while times[0] < time_ns - 1_000_000_000:
            times.popleft()
        if len(times) > 1 and time_ns > times[0] and self.wanted("/rates"):
            yield Outgoing("/rates", {context: (len(times) - 1) * 1e9 / (time_ns - times[0])}, time_ns, wall)


class RecordingChannels(logging.Handler):
    """Foxglove's channels in every file a ``Recorder`` writes: the translation hook for the
    representations, and the program's log lines (``tafel`` loggers) while a recording runs."""

    def __init__(self, recorder: Any, jpeg_quality: int = 80) -> None:
        super().__init__(logging.INFO)
        self.recorder = recorder
        self.jpeg_quality = jpeg_quality
        self.translator = FoxgloveTranslator(jpeg_quality)
        recorder.listeners.append(self.switch)

    def new_file(self) -> Callable[[str, type, int, int, bytes], list[ExtraMessage]]:
        self.translator = FoxgloveTranslator(self.jpeg_quality)  # the field again, a new time offset
        return self.translator.translate

    def switch(self, recording: bool) -> None:
        logger = logging.getLogger("tafel")
        if recording:
            logger.addHandler(self)
        else:
            logger.removeHandler(self)

    def emit(self, record: logging.LogRecord) -> None:
        writer = self.recorder.writer
        message = self.translator.log_record(record, int(record.created * 1e9) - (self.translator.offset_ns or 0))
        if writer is not None and message is not None:
            writer.write_extra(message.encoded())
