"""The 3D view in headless Chromium: the program sends the links' poses from its kinematic model
(RobotLinks), and the page's scene holds every link where the kinematics put it for the angles sent."""

from __future__ import annotations

import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from tafel.modules.motion.kinematics import link_poses
from tests.support.browser import WebProgram, launch, missing_browser, open_page, wait_for
from tests.test_web_view import screenshot_dir

pytestmark = [pytest.mark.slow, pytest.mark.skipif(missing_browser() is not None, reason=str(missing_browser()))]


@pytest.fixture(scope="module")
def playwright() -> Iterator[Any]:
    from playwright.sync_api import sync_playwright

    with sync_playwright() as driver:
        yield driver


def column_major(elements: list[float]) -> np.ndarray:
    """A three.js Matrix4's elements (column-major) as a 4x4 array."""
    return np.array(elements, dtype=float).reshape(4, 4).T


def test_the_3d_view_draws_the_links_at_the_angles_the_program_sent(playwright: Any, tmp_path: Path, tmp_path_factory: Any) -> None:
    program = WebProgram("run", "--platform", "dummy", "--debug-port", "0", "--web-port", "0", "--config", str(tmp_path), cwd=tmp_path)
    browser = launch(playwright)
    try:
        page = open_page(browser, program.url)
        page.locator("[data-view=view3d]").scroll_into_view_if_needed()
        wait_for(page, "tafel.state.view3d.frames > 3 && tafel.state.view3d.links.LFoot && tafel.state.view3d.links.RFingers")
        shown = page.evaluate("(() => { const v = tafel.state.view3d; const names = Object.keys(v.links);"
                              " return { angles: v.message.angles, links: Object.fromEntries(names.map((n) => [n, v.linkMatrix(n)])) }; })()")
        angles = shown["angles"]
        assert {"HeadYaw", "LKneePitch", "RHipYawPitch"} <= set(angles)
        expected = link_poses(angles)
        base = column_major(shown["links"]["torso"])  # the torso in the robot frame (TorsoPose), in metres
        base[:3, 3] *= 1000.0
        assert set(shown["links"]) == set(expected)
        for name, pose in expected.items():
            drawn = column_major(shown["links"][name])
            want = base @ pose
            np.testing.assert_allclose(drawn[:3, :3], want[:3, :3], atol=1e-4, err_msg=name)
            np.testing.assert_allclose(drawn[:3, 3], want[:3, 3] * 0.001, atol=1e-5, err_msg=name)  # metres in the scene
        # the feet are below the torso and the head above it, as a standing robot has them
        assert shown["links"]["Head"][14] > shown["links"]["torso"][14] > shown["links"]["LFoot"][14]
        if page.evaluate("tafel.state.view3d.webgl"):
            wait_for(page, "tafel.state.view3d.drawn > 0")
        time.sleep(0.5)
        page.locator("[data-view=view3d]").screenshot(path=str(screenshot_dir(tmp_path_factory) / "view3d.png"))
        assert page.problems == []
    finally:
        browser.close()
        program.stop()
