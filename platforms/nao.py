"""The real NAO V6: LoLA for joints, IMU, foot pressure, touch, battery, sonars and LEDs; V4L2 for the cameras.

LoLA (the robot's low-level daemon) sends one msgpack map every 12 ms over the Unix socket
``/tmp/robocup``; every packet is answered with exactly one actuator map. The packets drive the motion
loop (83.3 Hz). Sensor values are mapped into the representations the simulators provide, in the
project's frames and units. Both cameras are read through V4L2 in the cognition process; the top camera
is mounted upside down, so its image is turned by 180 degrees.

Safety: the runtime tells motion when cognition is gone (motion modules move safely then); when the
program ends or fails, this platform answers LoLA for one more second with a crouch that ends limp,
before it lets go of the socket.
"""

from __future__ import annotations

import argparse
import errno
import logging
import math
import os
import socket
import time
from collections.abc import Mapping, Sequence
from typing import Any, ClassVar

import cv2
import msgpack
import numpy as np

from tafel.core.framework.manager import Blackboard
from tafel.core.runtime import clock
from tafel.core.runtime.platform import Platform, PlatformError
from tafel.platforms.actuators import ActuatorGuard
from tafel.platforms.network import NETWORK_INPUTS, NETWORK_OUTPUTS, NetworkedPlatform
from tafel.platforms.v4l2 import newest_image
from tafel.representations.motion import (
    JOINT_COUNT,
    JOINT_INDEX,
    BatteryData,
    FsrData,
    InertialSensorData,
    JointCommand,
    JointSensorData,
    LedRequest,
    TouchSensorData,
)
from tafel.representations.nao import HORIZONTAL_FOV, VERTICAL_FOV
from tafel.representations.perception import CameraImageBottom, CameraImageTop
from tafel.representations.sonar import SonarData

log = logging.getLogger("tafel.platform.nao")

LOLA_SOCKET = "/tmp/robocup"
LOLA_RATE = 1000.0 / 12.0  # Hz
PACKET_SIZE = 896
SENSOR_LENGTHS = {"Position": 25, "Stiffness": 25, "Current": 25, "Temperature": 25, "Accelerometer": 3,
                  "Gyroscope": 3, "Angles": 2, "FSR": 8, "Touch": 14, "Battery": 4}
#: where to go and how long, when the program ends: a crouch, then limp
CROUCH = {"HeadPitch": 0.0, "LShoulderPitch": 1.6, "RShoulderPitch": 1.6, "LShoulderRoll": 0.1, "RShoulderRoll": -0.1,
          "LElbowRoll": -0.3, "RElbowRoll": 0.3, "LHipPitch": -0.85, "RHipPitch": -0.85, "LKneePitch": 2.1,
          "RKneePitch": 2.1, "LAnklePitch": -1.2, "RAnklePitch": -1.2}
CROUCH_SECONDS, LIMP_SECONDS = 1.0, 0.4


class LolaProtocolError(PlatformError):
    """LoLA sent something that is not a sensor packet."""


def crouch_pose() -> np.ndarray:
    pose = np.zeros(JOINT_COUNT)
    for name, angle in CROUCH.items():
        pose[JOINT_INDEX[name]] = angle
    return pose


#: the bit of LoLA's battery status that is set while the robot charges (B-Human's NaoProvider)
BATTERY_CHARGING_BIT = 0x80


def battery_data(battery: Sequence[float]) -> BatteryData:
    """LoLA's ``Battery`` array (charge, status, current, temperature) as ``BatteryData``."""
    status = int(battery[1])
    return BatteryData(charge=float(battery[0]), status=status, charging=bool(status & BATTERY_CHARGING_BIT),
                       current=float(battery[2]), temperature=float(battery[3]))


def convert_inertial(accelerometer: np.ndarray, gyroscope: np.ndarray, angles: np.ndarray) -> InertialSensorData:
    """LoLA's IMU values in the project's frame (x forward, y left, z up).

    LoLA's axes are the robot's, but its accelerometer reports the opposite of what an accelerometer
    measures (gravity itself, -9.81 on z when upright), so all three axes are negated, as B-Human and
    HULKs do. Two real packets settle it: only with all three negated does the roll computed from the
    accelerometer have the sign of LoLA's own ``Angles[0]`` (tests/test_nao.py). The gyroscope shares
    those axes and measures angular velocity with the right-hand rule, so it is taken as it is: a robot
    turning left (counter-clockwise seen from above) has a positive rate about z, and LoLA's roll and
    pitch rates match the derivatives of its own ``Angles``. NaoTH negates z for an older convention.
    """
    return InertialSensorData(accelerometer=-np.asarray(accelerometer, dtype=float),
                              gyroscope=np.asarray(gyroscope, dtype=float).copy(), angles=np.asarray(angles, dtype=float).copy())


def sonar_data(values: Mapping[str, np.ndarray]) -> SonarData:
    """LoLA's ``Sonar`` array (left, right: m to the nearest echo) as ``SonarData``; not valid where the
    packet held none (it is not checked like the rest: a robot without sonars still walks)."""
    sonar = values.get("Sonar")
    if sonar is None:
        return SonarData(valid=False)
    return SonarData(left=float(sonar[0]), right=float(sonar[1]), valid=True)


def parse_sensors(packet: Any) -> dict[str, np.ndarray]:
    """The sensor arrays of one LoLA packet, checked: a clear error for anything malformed."""
    if not isinstance(packet, dict):
        raise LolaProtocolError(f"malformed LoLA packet: expected a map, got {type(packet).__name__}")
    values = {}
    for key, length in SENSOR_LENGTHS.items():
        raw = packet.get(key)
        if not isinstance(raw, (list, tuple)) or len(raw) != length:
            found = f"{len(raw)} values" if isinstance(raw, (list, tuple)) else repr(type(raw).__name__)
            raise LolaProtocolError(f"malformed LoLA packet: {key} should hold {length} numbers, found {found}")
        try:
            values[key] = np.asarray(raw, dtype=float)
        except (TypeError, ValueError):
            raise LolaProtocolError(f"malformed LoLA packet: {key} holds something that is not a number") from None
    sonar = packet.get("Sonar")  # left, right (m): kept where it is two finite numbers
    if isinstance(sonar, (list, tuple)) and len(sonar) == 2 and all(isinstance(v, (int, float)) and math.isfinite(v) for v in sonar):
        values["Sonar"] = np.asarray(sonar, dtype=float)
    return values


class NaoPlatform(NetworkedPlatform, Platform):
    name = "nao"
    description = "the real NAO V6: LoLA (msgpack over /tmp/robocup) and both cameras through V4L2"
    clock = "own"
    provides: ClassVar[Mapping[str, tuple[type, ...]]] = {
        "motion": (JointSensorData, InertialSensorData, FsrData, TouchSensorData, BatteryData, SonarData),
        "cognition": (CameraImageTop, CameraImageBottom, *NETWORK_INPUTS),
    }
    consumes: ClassVar[Mapping[str, tuple[type, ...]]] = {"motion": (JointCommand, LedRequest), "cognition": NETWORK_OUTPUTS}

    def __init__(self, options: Mapping[str, Any] | None = None) -> None:
        super().__init__(options)
        self.socket_path = str(self.options.get("lola") or LOLA_SOCKET)
        self.cameras = str(self.options.get("cameras", "on")).lower() not in ("off", "false", "0", "no")
        self.camera_devices = {"top": self.options.get("camera_top") or self._default_device("top"),
                               "bottom": self.options.get("camera_bottom") or self._default_device("bottom")}
        self.connection: socket.socket | None = None
        self.unpacker = msgpack.Unpacker(raw=False)
        self.packer = msgpack.Packer(use_single_float=True)
        self.captures: dict[str, Any] = {}
        #: stale camera images dropped per camera, and when that was last said (monotonic s)
        self.dropped_images: dict[str, int] = {}
        self.dropped_said = 0.0
        self.measured = np.zeros(JOINT_COUNT)
        self.commanded_stiffness = np.zeros(JOINT_COUNT)
        self.guard = ActuatorGuard("nao")  # joint limits, 0..1, no NaN reaches LoLA
        self.time_ns = 0
        self.packets = 0
        self.pending_answer = False
        self.check()

    @classmethod
    def add_arguments(cls, parser: argparse.ArgumentParser) -> None:
        parser.add_argument("--lola", default=LOLA_SOCKET, help=f"nao: LoLA's Unix socket (default {LOLA_SOCKET})")
        parser.add_argument("--cameras", choices=["on", "off"], default="on", help="nao: read the cameras")
        parser.add_argument("--camera-top", help="nao: V4L2 device of the top camera (default /dev/video-top, else /dev/video0)")
        parser.add_argument("--camera-bottom", help="nao: V4L2 device of the bottom camera (default /dev/video-bottom, else /dev/video1)")

    @staticmethod
    def _default_device(camera: str) -> str:
        named = f"/dev/video-{camera}"
        return named if os.path.exists(named) else ("/dev/video0" if camera == "top" else "/dev/video1")

    def rates(self) -> Mapping[str, float] | None:
        return {"motion": LOLA_RATE}

    def check(self) -> None:
        """Fail before anything starts when LoLA or a camera is not there, saying what to do."""
        if not os.path.exists(self.socket_path):
            raise PlatformError(
                f"LoLA's socket {self.socket_path} does not exist: is lola running on this robot "
                "(systemctl --user status lola)? Use --lola PATH for another socket."
            )
        if self.cameras:
            for camera, device in self.camera_devices.items():
                if not os.path.exists(device):
                    raise PlatformError(f"the {camera} camera {device} does not exist; pass --camera-{camera} DEVICE, or --cameras off")

    # ------------------------------------------------------------------------------ lifecycle
    def start(self, contexts: frozenset[str]) -> None:
        if "motion" in contexts:
            self.connection = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
            try:
                self.connection.connect(self.socket_path)
            except OSError as exc:
                self.connection.close()
                self.connection = None
                raise PlatformError(f"cannot connect to LoLA at {self.socket_path}: {exc.strerror or exc}") from None
        if "cognition" in contexts:
            self.network.open()
        if "cognition" in contexts and self.cameras:
            for camera, device in self.camera_devices.items():
                capture = cv2.VideoCapture(device, cv2.CAP_V4L2)
                if not capture.isOpened():
                    raise PlatformError(f"cannot open the {camera} camera {device} (in use by another program?)")
                self.captures[camera] = capture

    def stop(self) -> None:
        self.network.close()
        for capture in self.captures.values():
            capture.release()
        self.captures = {}
        if self.connection is not None:
            try:
                self.safe_stop()
            finally:
                self.connection.close()
                self.connection = None

    def safe_stop(self) -> None:
        """Answer LoLA for a second more: into a crouch, then limp; then let go of the socket."""
        start = self.measured.copy()
        goal = crouch_pose()
        stiffness = np.maximum(self.commanded_stiffness, 0.6)
        total = int((CROUCH_SECONDS + LIMP_SECONDS) * LOLA_RATE)
        crouch_packets = int(CROUCH_SECONDS * LOLA_RATE)
        self.connection.settimeout(0.1)
        for i in range(total):
            try:
                if not self.pending_answer:
                    self.receive()
            except LolaProtocolError:  # LoLA speaks nonsense: we cannot follow its beat, so go limp at once
                try:
                    self.send({"Position": self.measured.tolist(), "Stiffness": [0.0] * JOINT_COUNT, "Chest": [1.0, 0.0, 0.0]})
                except OSError:
                    pass
                return
            except (PlatformError, OSError):
                return  # LoLA is gone: nothing more to say to it
            if i < crouch_packets:
                blend = 0.5 - 0.5 * math.cos(math.pi * (i + 1) / crouch_packets)
                position, now = start + (goal - start) * blend, stiffness
            else:
                position, now = goal, stiffness * max(0.0, 1.0 - (i + 1 - crouch_packets) / (total - crouch_packets))
            try:
                self.send({"Position": position.tolist(), "Stiffness": now.tolist(), "Chest": [1.0, 0.0, 0.0]})
            except OSError:
                return

    # ---------------------------------------------------------------------------------- LoLA
    def receive(self) -> dict[str, np.ndarray]:
        """The next sensor packet (blocks until LoLA sends one)."""
        while True:
            try:
                packet = next(self.unpacker, None)
            except (msgpack.ExtraData, msgpack.FormatError, msgpack.StackError, ValueError) as exc:
                raise LolaProtocolError(
                    f"malformed LoLA packet after {self.packets} good ones: the bytes are not msgpack ({type(exc).__name__})"
                ) from None
            if packet is not None:
                self.pending_answer = True
                self.packets += 1
                return parse_sensors(packet)
            try:
                data = self.connection.recv(4096)
            except TimeoutError:
                raise PlatformError(f"LoLA sent nothing for {self.connection.gettimeout()} s") from None
            except OSError as exc:
                raise PlatformError(f"lost LoLA at {self.socket_path}: {exc.strerror or exc}") from None
            if not data:
                raise PlatformError(f"LoLA closed the connection at {self.socket_path}")
            try:
                self.unpacker.feed(data)
            except msgpack.BufferFull:
                raise LolaProtocolError("malformed LoLA packet: more data than any sensor packet holds") from None

    def send(self, answer: Mapping[str, Any]) -> None:
        self.connection.sendall(self.packer.pack(dict(answer)))
        self.pending_answer = False

    def sense(self, context: str, blackboard: Blackboard, frame_number: int, time_ns: int) -> None:
        if context == "motion":
            values = self.receive()
            self.time_ns = clock.now_ns()
            self.measured = values["Position"]
            self.guard.hold(self.measured)
            blackboard.set(JointSensorData(position=values["Position"], stiffness=values["Stiffness"],
                                           current=values["Current"], temperature=values["Temperature"]))
            inertial = convert_inertial(values["Accelerometer"], values["Gyroscope"], values["Angles"])
            blackboard.set(inertial)
            blackboard.set(FsrData(pressure=values["FSR"]))
            blackboard.set(TouchSensorData(pressed=values["Touch"]))
            blackboard.set(battery_data(values["Battery"]))
            blackboard.set(sonar_data(values))
        elif context == "cognition":
            self.time_ns = clock.now_ns()
            self.network.receive(blackboard, self.time_ns)
            if not self.captures:
                time.sleep(1.0 / 30.0)  # no cameras: keep cognition at its usual pace
                return
            for camera, rep in (("top", CameraImageTop), ("bottom", CameraImageBottom)):
                ok, frame, taken_ns, dropped = newest_image(self.captures[camera], self.camera_devices[camera])
                if not ok:
                    raise PlatformError(f"the {camera} camera {self.camera_devices[camera]} stopped delivering images")
                self.report_dropped(camera, dropped)
                if camera == "top":
                    frame = cv2.rotate(frame, cv2.ROTATE_180)  # mounted upside down
                image = blackboard[rep]
                image.time_ns = taken_ns
                image.image = cv2.cvtColor(frame, cv2.COLOR_BGR2RGB)
                image.horizontal_fov, image.vertical_fov = HORIZONTAL_FOV, VERTICAL_FOV

    def report_dropped(self, camera: str, dropped: int) -> None:
        """Stale images dropped (cognition was slower than the camera): counted, said at most once a second."""
        if not dropped:
            return
        self.dropped_images[camera] = self.dropped_images.get(camera, 0) + dropped
        now = time.monotonic()
        if now - self.dropped_said >= 1.0:
            self.dropped_said = now
            log.warning("cognition is slower than the cameras: dropped stale images (%s so far) to work on the newest",
                        ", ".join(f"{c} {n}" for c, n in sorted(self.dropped_images.items())))

    def frame_time_ns(self, context: str) -> int | None:
        return self.time_ns

    def commands(self) -> Mapping[str, tuple[str, Any]]:
        return self.network.commands()

    def act(self, context: str, blackboard: Blackboard) -> None:
        if context == "cognition":
            self.network.send(blackboard)
        if context != "motion" or not self.pending_answer:
            return
        command, leds = blackboard[JointCommand], blackboard[LedRequest]
        position, self.commanded_stiffness = self.guard(command.position, command.stiffness)
        try:
            self.send({
                "Position": position.tolist(),
                "Stiffness": self.commanded_stiffness.tolist(),
                "Chest": leds.chest.tolist(), "LFoot": leds.left_foot.tolist(), "RFoot": leds.right_foot.tolist(),
                "LEye": leds.left_eye.tolist(), "REye": leds.right_eye.tolist(),
                "LEar": leds.left_ear.tolist(), "REar": leds.right_ear.tolist(), "Skull": leds.skull.tolist(),
                "Sonar": [True, True],  # as most teams send: keeps the sonars measuring
            })
        except OSError as exc:
            if exc.errno in (errno.EPIPE, errno.ECONNRESET):
                raise PlatformError(f"LoLA closed the connection at {self.socket_path}") from None
            raise
