"""The video platform: a generated video of a moving orange ball, played as a user would."""

from __future__ import annotations

from pathlib import Path

import cv2
import numpy as np
import pytest

from tafel.core.logs import read_log
from tafel.core.logs.serialization import deserialize
from tafel.representations.infrastructure import FrameInfo
from tafel.representations.perception import BallImagePercept
from tests.test_cli_runtime import tafel

FRAMES = 60


def ball_center(i: int) -> tuple[int, int]:
    """Where the generated video draws the ball in frame i (from 0): left to right, slightly down."""
    return 40 + 4 * i, 100 + i


@pytest.fixture(scope="module")
def video(tmp_path_factory) -> Path:
    path = tmp_path_factory.mktemp("video") / "ball.avi"
    writer = cv2.VideoWriter(str(path), cv2.VideoWriter_fourcc(*"MJPG"), 25, (320, 240))
    assert writer.isOpened()
    for i in range(FRAMES):
        frame = np.zeros((240, 320, 3), np.uint8)
        frame[:] = (50, 140, 40)  # green carpet (BGR)
        cv2.circle(frame, ball_center(i), 15, (0, 110, 255), -1)  # orange ball (BGR)
        writer.write(frame)
    writer.release()
    return path


@pytest.mark.slow
def test_the_detector_reports_the_ball_frame_by_frame(video: Path, tmp_path: Path) -> None:
    log = tmp_path / "video.mcap"
    result = tafel("run", "--platform", "video", "--source", str(video), "--fps", "200", "--no-debug",
                   "--record", str(log), "--record-reps", "BallImagePercept,FrameInfo")
    assert result.returncode == 0, result.stderr
    assert "cognition: 60 frames" in result.stdout
    contents = read_log(log)
    percepts = {m.sequence: deserialize(BallImagePercept, m.data) for m in contents.messages if m.topic == "cognition/BallImagePercept"}
    times = {m.sequence: deserialize(FrameInfo, m.data).time_ns for m in contents.messages if m.topic == "cognition/FrameInfo"}
    assert sorted(percepts) == list(range(1, FRAMES + 1))
    for frame, percept in percepts.items():
        expected = ball_center(frame - 1)
        best = percept.candidates[0]
        assert best.camera == "top"
        assert abs(best.x - expected[0]) < 1.5 and abs(best.y - expected[1]) < 1.5, (frame, best)
        assert best.radius == pytest.approx(15.0, abs=1.5)
        assert times[frame] == (frame - 1) * 5_000_000  # frame time from the playback rate (--fps 200)


@pytest.mark.slow
def test_modules_that_need_more_than_an_image_are_pruned_with_a_report(video: Path) -> None:
    result = tafel("run", "--platform", "video", "--source", str(video), "--fps", "200", "--no-debug")
    assert result.returncode == 0, result.stderr
    assert "motion: not running: the platform provides nothing to it" in result.stderr
    assert "cognition: BallLocator disabled: nothing provides CameraMatrixBuffer" in result.stderr
    assert "cognition: KalmanBallModeler disabled: nothing provides BallPercept" in result.stderr
    assert "Traceback" not in result.stderr
    strict = tafel("run", "--platform", "video", "--source", str(video), "--strict", "--no-debug")
    assert strict.returncode == 2 and "cannot feed these modules (--strict)" in strict.stderr


@pytest.mark.slow
def test_the_file_plays_at_its_own_rate_and_loops(video: Path) -> None:
    modules = tafel("modules", "--platform", "video", "--source", str(video))
    assert "cognition (25 Hz)" in modules.stdout  # the file's frame rate
    looped = tafel("run", "--platform", "video", "--source", str(video), "--fps", "400", "--loop", "--seconds", "0.4", "--no-debug")
    assert looped.returncode == 0, looped.stderr
    frames = int(__import__("re").search(r"cognition: (\d+) frames", looped.stdout).group(1))
    assert frames > FRAMES


@pytest.mark.slow
@pytest.mark.parametrize(
    ("source", "message"),
    [
        ("missing.avi", "video file missing.avi does not exist"),
        ("NOT_A_VIDEO", "cannot read video file"),
        ("7", "no camera at index 7"),
    ],
)
def test_bad_sources_get_clear_errors(tmp_path: Path, source: str, message: str) -> None:
    if source == "NOT_A_VIDEO":
        bogus = tmp_path / "notes.avi"
        bogus.write_text("this is not a video")
        source = str(bogus)
    result = tafel("run", "--platform", "video", "--source", source, "--no-debug")
    assert result.returncode == 1 and message in result.stderr
    assert "Traceback" not in result.stderr
    missing = tafel("run", "--platform", "video", "--no-debug")
    assert missing.returncode == 2 and "needs --source FILE" in missing.stderr


@pytest.mark.parametrize(("options", "message"), [
    ({"camera": "Top"}, "--camera takes one of top, bottom, got 'Top'"),  # as the Camera enum: names as written
    ({"ball_color": "red"}, "--ball-color takes one of spl, orange, got 'red'"),
    ({"fps": 0.0}, "--fps takes a finite number of frames per second above 0, got 0"),  # 0 was taken as "the file's rate"
    ({"fps": -5.0}, "--fps takes a finite number of frames per second above 0, got -5"),
    ({"fov": 180.0}, "--fov takes a finite number of degrees above 0 and below 180 (the horizontal field of view), got 180"),
    ({"fov": float("nan")}, "--fov takes a finite number of degrees above 0 and below 180 (the horizontal field of view), got nan"),
])
def test_bad_video_options_are_refused_in_the_one_wording(options: dict, message: str) -> None:
    from tafel.core.runtime.platform import PlatformOptionError
    from tafel.platforms.video import VideoPlatform

    with pytest.raises(PlatformOptionError) as error:
        VideoPlatform({"source": "missing.avi", **options})
    assert str(error.value) == message
