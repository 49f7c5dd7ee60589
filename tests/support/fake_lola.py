"""A stand-in for the NAO's LoLA daemon: a Unix socket that sends 896-byte sensor packets at 83 Hz
and records every answer, for testing the nao platform without a robot."""

from __future__ import annotations

import socket
import threading
import time
from pathlib import Path
from typing import Any

import msgpack

PERIOD = 0.012
PACKET_SIZE = 896


#: the keys of a real read packet, in LoLA's order (NaoTH's LolaData.h)
KEY_ORDER = ("RobotConfig", "Accelerometer", "Angles", "Battery", "Current", "FSR", "Gyroscope", "Position", "Sonar",
             "Stiffness", "Temperature", "Touch", "Status")
BODY_ID, HEAD_ID = "P0000073A07S94700014", "P0000074A05S93J00024"  # 20 characters each, as on a robot


def sensor_packet(positions: list[float], stiffness: list[float], index: int, *,
                  accelerometer: tuple[float, float, float] = (0.1, 0.0, -9.81),
                  gyroscope: tuple[float, float, float] = (0.0, 0.0, 0.01),
                  angles: tuple[float, float] = (0.0, 0.01), sonar: tuple[float, float] = (2.0, 2.0)) -> bytes:
    """One packet as LoLA sends it: its key order, 20-character IDs, float32 values, exactly 896 bytes.

    The accelerometer is in LoLA's convention (-9.81 on z when upright).
    """
    values: dict[str, Any] = {
        "RobotConfig": [BODY_ID, "6.0.0", HEAD_ID, "6.0.0"],
        "Accelerometer": list(accelerometer), "Angles": list(angles), "Battery": [0.99, -32552.0, 0.016, 3.6],  # NaoTH's real packet (charging)
        "Current": [0.1] * 25, "FSR": [0.6] * 8, "Gyroscope": list(gyroscope), "Position": list(positions),
        "Sonar": list(sonar), "Stiffness": list(stiffness), "Temperature": [35.0] * 25, "Touch": [0.0] * 14,
        "Status": [index % 2] * 25,
    }
    data = msgpack.Packer(use_single_float=True).pack({key: values[key] for key in KEY_ORDER})
    assert len(data) == PACKET_SIZE, f"a LoLA packet is {PACKET_SIZE} bytes, this one {len(data)}"
    return data


class FakeLola:
    """Serve one client; ``garbage_after`` sends bytes that are no msgpack after that many packets."""

    def __init__(self, path: Path, *, garbage_after: int | None = None) -> None:
        self.path = path
        self.garbage_after = garbage_after
        self.sent = 0
        self.answers: list[dict[str, Any]] = []
        self.sizes: set[int] = set()
        self.positions = [0.0] * 25
        self.stiffness = [0.0] * 25
        self.sonar = (2.0, 2.0)  # m: what the left and right sonars hear
        self.stop = threading.Event()
        self.server = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
        self.server.bind(str(path))
        self.server.listen(1)
        self.thread = threading.Thread(target=self.serve, daemon=True)
        self.thread.start()

    def serve(self) -> None:
        self.server.settimeout(30)
        try:
            client, _ = self.server.accept()
        except OSError:
            return
        client.setblocking(False)
        unpacker = msgpack.Unpacker(raw=False)
        deadline = time.monotonic()
        try:
            while not self.stop.is_set():
                deadline += PERIOD
                if self.garbage_after is not None and self.sent >= self.garbage_after:
                    data = b"\xc1" * PACKET_SIZE  # 0xc1 is never used by msgpack
                else:
                    data = sensor_packet(self.positions, self.stiffness, self.sent, sonar=self.sonar)
                self.sizes.add(len(data))
                try:
                    client.sendall(data)
                except (BlockingIOError, BrokenPipeError, ConnectionResetError):
                    break
                self.sent += 1
                while time.monotonic() < deadline:
                    try:
                        chunk = client.recv(65536)
                    except BlockingIOError:
                        time.sleep(0.001)
                        continue
                    except OSError:
                        return
                    if not chunk:
                        return
                    self._take(unpacker, chunk)
        finally:
            self._drain(client, unpacker)
            client.close()

    def _take(self, unpacker: msgpack.Unpacker, chunk: bytes) -> None:
        unpacker.feed(chunk)
        for answer in unpacker:
            self.answers.append(answer)
            if isinstance(answer, dict) and "Position" in answer:
                self.positions = list(answer["Position"])  # ideal servos
                self.stiffness = list(answer["Stiffness"])

    def _drain(self, client: socket.socket, unpacker: msgpack.Unpacker) -> None:
        """Read the answers still on their way when the client let go."""
        client.settimeout(0.5)
        try:
            while chunk := client.recv(65536):
                self._take(unpacker, chunk)
        except OSError:
            pass

    def close(self) -> None:
        self.stop.set()
        try:  # wakes an accept() still waiting for a program that never came (closing alone does not)
            self.server.shutdown(socket.SHUT_RDWR)
        except OSError:
            pass
        self.server.close()
        self.thread.join(timeout=5)
