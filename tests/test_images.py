"""Recorded images with the camera's pose (``tafel.platforms.images``): pose files, PNG text chunks, given
poses, NAO raw frames, and the video platform playing a folder of real NAO images through the cognition."""

from __future__ import annotations

import json
import math
import struct
import zlib
from pathlib import Path

import cv2
import numpy as np
import pytest

from tafel.core.logs import read_log
from tafel.core.logs.serialization import deserialize
from tafel.modules.motion.kinematics import CAMERA_LINKS, angles_by_name, camera_pose_in_torso, link_poses, robot_frame_from_torso
from tafel.modules.motion.stand_motion import stand_pose
from tafel.platforms.images import (
    CameraPose,
    ImageSourceError,
    pose_json,
    posed_image,
    read_image,
    rotation_y,
    rotation_z,
    standing_camera,
)
from tafel.representations.motion import HEAD_PITCH, HEAD_YAW, CameraMatrix
from tafel.representations.nao import BOTTOM_CAMERA, TOP_CAMERA
from tafel.representations.perception import BallImagePercept
from tests.test_cli_runtime import tafel

REAL = Path(__file__).parent / "data" / "real_images"
HTWK = REAL / "images" / "htwk"


def write_png(path: Path, texts: dict[str, str] | None = None) -> None:
    """A small grey PNG with ``texts`` as tEXt chunks after the header (as HTWK's saver writes them)."""
    ok, encoded = cv2.imencode(".png", np.full((48, 64, 3), 120, np.uint8))
    assert ok
    data = encoded.tobytes()
    header_end = 8 + 12 + struct.unpack(">I", data[8:12])[0]
    chunks = b""
    for key, value in (texts or {}).items():
        body = key.encode() + b"\0" + value.encode()
        chunks += struct.pack(">I", len(body)) + b"tEXt" + body + struct.pack(">I", zlib.crc32(b"tEXt" + body))
    path.write_bytes(data[:header_end] + chunks + data[header_end:])


def kinematic_camera(camera: str, head_yaw: float, head_pitch: float) -> np.ndarray:
    """The camera's pose in the robot frame (4x4) by the program's own kinematics, standing."""
    angles = stand_pose()
    angles[HEAD_YAW], angles[HEAD_PITCH] = head_yaw, head_pitch
    poses = link_poses(angles_by_name(angles), CAMERA_LINKS)
    return robot_frame_from_torso(poses, 0.0, 0.0) @ camera_pose_in_torso(poses, TOP_CAMERA if camera == "top" else BOTTOM_CAMERA)


@pytest.mark.parametrize(("camera", "yaw", "pitch"), [("top", 0.0, 0.0), ("top", 0.5, 0.3), ("bottom", -0.4, -0.2)])
def test_a_standing_cameras_pose_matches_the_kinematics(camera: str, yaw: float, pitch: float) -> None:
    pose = kinematic_camera(camera, yaw, pitch)
    matrix = standing_camera(camera, yaw, pitch)
    assert np.allclose(matrix.rotation, pose[:3, :3], atol=2e-3)
    assert np.allclose(matrix.translation, pose[:3, 3], atol=3.0)


def test_hulks_pose_file_gives_the_recorded_matrix(tmp_path: Path) -> None:
    image = tmp_path / "1687000000.jpg"
    cv2.imwrite(str(image), np.full((480, 640, 3), 90, np.uint8))
    half = 0.3 / 2  # a camera pitched down by 0.3 rad and turned left by 0.2 rad: q = qz(0.2) * qy(0.3)
    qz, qy = (0.0, 0.0, math.sin(0.1), math.cos(0.1)), (0.0, math.sin(half), 0.0, math.cos(half))
    x = qz[3] * qy[0] - qz[2] * qy[1]
    y = qz[3] * qy[1] + qz[2] * qy[0]
    z = qz[2] * qy[3]
    w = qz[3] * qy[3]
    (tmp_path / "1687000000.json").write_text(json.dumps({
        "camera_matrix": {"camera_to_ground": {"rotation": [x, y, z, w], "translation": [0.05, -0.01, 0.48]},
                          "field_of_view": [0.97, 0.75]},
        "position": "Bottom"}))
    posed = posed_image(image)
    assert posed.pose_source == "json (HULKs)" and posed.camera == "bottom"
    assert np.allclose(posed.matrix.rotation, rotation_z(0.2) @ rotation_y(0.3), atol=1e-9)
    assert np.allclose(posed.matrix.translation, [50.0, -10.0, 480.0])
    assert (posed.horizontal_fov, posed.vertical_fov) == (0.97, 0.75)


def test_tafel_pose_file_round_trips(tmp_path: Path) -> None:
    image = tmp_path / "frame_0001.png"
    write_png(image)
    matrix = CameraMatrix(rotation_y(0.4), np.array([10.0, 0.0, 450.0]), True)
    (tmp_path / "frame_0001.json").write_text(json.dumps(pose_json("top", matrix, 1.0, 0.8)))
    posed = posed_image(image)
    assert posed.pose_source == "json (Tafel)"
    assert np.allclose(posed.matrix.rotation, matrix.rotation) and np.allclose(posed.matrix.translation, matrix.translation)
    assert (posed.horizontal_fov, posed.vertical_fov) == (1.0, 0.8)


def test_png_text_chunks_place_the_camera_as_htwk_store_them(tmp_path: Path) -> None:
    image = tmp_path / "match_00012_U.png"
    write_png(image, {"pitch": "0.0", "roll": "0.0", "headPitch": "0.35", "headYaw": "-0.25"})
    posed = posed_image(image)
    assert posed.pose_source == "png text" and posed.camera == "top"
    expected = kinematic_camera("top", -0.25, 0.35)
    assert np.allclose(posed.matrix.rotation, expected[:3, :3], atol=2e-3)
    assert np.allclose(posed.matrix.translation, expected[:3, 3], atol=3.0)


def test_a_given_pose_is_used_where_the_image_has_none_and_a_standing_robot_otherwise(tmp_path: Path) -> None:
    image = tmp_path / "plain.png"
    write_png(image)
    given = posed_image(image, CameraPose.parse("480,0.3,0,0.1"))
    assert given.pose_source.startswith("given")
    assert np.allclose(given.matrix.rotation, rotation_z(0.1) @ rotation_y(0.3)) and given.matrix.translation[2] == 480.0
    nominal = posed_image(image)
    assert nominal.pose_source.startswith("nominal")
    assert np.allclose(nominal.matrix.translation, kinematic_camera("top", 0.0, 0.0)[:3, 3], atol=3.0)


def test_nao_raw_yuv422_frames_are_read(tmp_path: Path) -> None:
    frame = np.zeros((480, 640, 2), np.uint8)
    frame[..., 0] = 180  # Y: bright
    frame[:, 0::2, 1], frame[:, 1::2, 1] = 128, 128  # U, V: no colour
    raw = tmp_path / "top_0001.yuv"
    frame.tofile(raw)
    rgb = read_image(raw)
    assert rgb.shape == (480, 640, 3)
    assert np.abs(rgb.astype(int) - 180).max() <= 2
    assert posed_image(raw).camera == "top"


@pytest.mark.parametrize(("content", "message"), [
    (b"\x00" * 1000, "1000 bytes is no NAO raw YUV422 frame"),
])
def test_a_raw_frame_of_the_wrong_size_is_a_clear_error(tmp_path: Path, content: bytes, message: str) -> None:
    raw = tmp_path / "broken.yuv"
    raw.write_bytes(content)
    with pytest.raises(ImageSourceError, match=message):
        read_image(raw)


@pytest.mark.parametrize(("pose_file", "message"), [
    ("{not json", "cannot read the camera pose"),
    ('{"camera_matrix": {"camera_to_ground": {"rotation": [0, 0, 0]}}}', "no camera pose in it"),
    ('{"tafel_camera": {"rotation": [[1, 0, 0], [0, 1, 0], [0, 0, 1]], "translation": [0, 0, "high"]}}', "no camera pose in it"),
])
def test_bad_pose_files_are_clear_errors(tmp_path: Path, pose_file: str, message: str) -> None:
    image = tmp_path / "a.png"
    write_png(image)
    (tmp_path / "a.json").write_text(pose_file)
    with pytest.raises(ImageSourceError, match=message):
        posed_image(image)


@pytest.mark.parametrize("text", ["", "high", "0,0.3", "500,nan", "1,2,3,4,5"])
def test_bad_given_poses_say_what_is_expected(text: str) -> None:
    with pytest.raises(ImageSourceError, match="HEIGHT,PITCH,ROLL,YAW"):
        CameraPose.parse(text)


@pytest.mark.slow
def test_real_nao_images_run_through_the_whole_cognition(tmp_path: Path) -> None:
    log = tmp_path / "real.mcap"
    # HTWK's images carry no pose: the head pitch their ball's size implies is given on the command line
    result = tafel("run", "--platform", "video", "--source", str(HTWK), "--fps", "20", "--no-debug", "--camera-pose", "503,0.27",
                   "--record", str(log), "--record-reps", "BallImagePercept,BallPercept")
    assert result.returncode == 0, result.stderr
    assert "cognition: 3 frames" in result.stdout
    assert "camera pose of the first: given (503 mm high, pitch 0.270" in result.stderr
    assert "nothing provides CameraMatrixBuffer" not in result.stderr
    assert "SelfLocator disabled" not in result.stderr and "BallLocator disabled" not in result.stderr
    percepts = [deserialize(BallImagePercept, m.data) for m in read_log(log).messages if m.topic == "cognition/BallImagePercept"]
    assert len(percepts) == 3  # in file order: ..._00049806_U.png, ..._00051659_U.png, ..._00070111_U.png
    assert any(c.camera == "top" and math.hypot(c.x - 282, c.y - 251) < 19 for c in percepts[1].candidates)  # the SPL ball detector ran


@pytest.mark.slow
@pytest.mark.parametrize(("args", "message"), [
    (["--camera-pose", "tall"], "HEIGHT,PITCH,ROLL,YAW"),
    (["--camera", "left"], "invalid choice"),
])
def test_bad_image_options_are_clear_errors(args: list[str], message: str) -> None:
    result = tafel("run", "--platform", "video", "--source", str(HTWK), "--no-debug", *args)
    assert result.returncode != 0 and message in result.stderr
    assert "Traceback" not in result.stderr


@pytest.mark.slow
def test_a_folder_without_images_is_a_clear_error(tmp_path: Path) -> None:
    (tmp_path / "notes.txt").write_text("no images here")
    result = tafel("run", "--platform", "video", "--source", str(tmp_path), "--no-debug")
    assert result.returncode == 1 and "holds no images" in result.stderr
    assert "Traceback" not in result.stderr
