"""Each camera at its own resolution (``--resolution TOP,BOTTOM``), as the NAO's are usually set: the top one
at 640x480 to see far, the bottom one at 320x240. Images, fields of view and what cognition makes of them."""

from __future__ import annotations

import math

import numpy as np
import pytest

from tafel.core.runtime.platform import PlatformOptionError
from tafel.platforms.simulated import parse_resolutions
from tafel.representations.perception import BallPercept, CameraImageBottom, CameraImageTop
from tests.support.simulation import Simulation

NAO = "640x480,320x240"


def test_one_size_is_both_cameras_and_two_are_top_then_bottom() -> None:
    assert parse_resolutions("320x240") == {"top": (320, 240), "bottom": (320, 240)}
    assert parse_resolutions(" 640X480 , 320x240") == {"top": (640, 480), "bottom": (320, 240)}


@pytest.mark.parametrize(("text", "message"), [
    ("640x480,320x240,160x120", "WIDTHxHEIGHT or TOP,BOTTOM (e.g. 640x480,320x240), got '640x480,320x240,160x120'"),
    ("640x480,", "WIDTHxHEIGHT with 16 to 4096 pixels a side"),
    ("640x480,8x8", "16 to 4096 pixels a side"),
])
def test_bad_resolutions_say_what_would_be_right(text: str, message: str) -> None:
    with pytest.raises(PlatformOptionError, match=message.replace("(", r"\(").replace(")", r"\)")):
        parse_resolutions(text)


@pytest.mark.slow
@pytest.mark.parametrize("engine", ["mujoco", "pybullet"])
def test_top_at_640x480_and_bottom_at_320x240_are_seen_where_they_are(engine: str) -> None:
    """Each camera's image at its size with the NAO's field of view, and the ball found where it lies by the
    default cognition in either camera: the camera matrices and intrinsics hold at both sizes."""
    sim = Simulation(engine, resolution=NAO, ball="1500,300")
    try:
        sim.run(1.5)  # stands, the head finds the ball far away: the top camera
        cognition = sim.blackboard("cognition")
        top, bottom = cognition[CameraImageTop], cognition[CameraImageBottom]
        assert top.image.shape == (480, 640, 3) and bottom.image.shape == (240, 320, 3)
        for image in (top, bottom):
            assert math.degrees(image.vertical_fov) == pytest.approx(43.7)
            assert math.degrees(image.horizontal_fov) == pytest.approx(56.3, abs=0.2)
        seen = {}
        for ball, camera in (((1500.0, 300.0), "top"), ((220.0, 40.0), "bottom")):
            sim.platform.move_ball(*ball)
            sim.run(0.6)
            percept = sim.blackboard("cognition")[BallPercept]
            truth = sim.platform.ball_in_robot_frame()
            seen[camera] = (percept.seen, percept.camera, round(math.hypot(percept.x - truth[0], percept.y - truth[1])))
            assert percept.seen and percept.camera == camera, seen
            assert seen[camera][2] < max(60.0, 0.06 * math.hypot(*truth)), seen
        assert np.asarray(sim.blackboard("cognition")[CameraImageTop].image).std() > 5
    finally:
        sim.close()
