"""RobotControl in the browser, end to end: ``tafel run`` and ``tafel view`` driven in headless Chromium.

Every check goes through the page as a user would (clicks, typing, the page's own state) and is
confirmed through the debug server, or against the simulator's ground truth or the recorded log.
Screenshots of each view go to ``TAFEL_SCREENSHOT_DIR`` (the README's come from there), else to the
test's temporary folder.
"""

from __future__ import annotations

import math
import os
import re
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from tafel.core.logfile import read_log
from tafel.core.serialization import deserialize
from tafel.representations.modeling import RobotPose
from tests.support.browser import WebProgram, launch, missing_browser

pytestmark = [pytest.mark.slow, pytest.mark.skipif(missing_browser() is not None, reason=str(missing_browser()))]
VIEWS = ("field", "images", "status", "remote", "plots", "stopwatches", "modules", "representations", "requests", "modify",
         "parameters")


def wait_for(page: Any, expression: str, timeout: float = 20.0) -> Any:
    """Poll a JavaScript expression of the page until it is truthy; its value."""
    deadline = time.monotonic() + timeout
    while True:
        value = page.evaluate(expression)
        if value:
            return value
        assert time.monotonic() < deadline, f"the page never made {expression} true"
        time.sleep(0.1)


def screenshot_dir(tmp_path_factory: Any) -> Path:
    folder = os.environ.get("TAFEL_SCREENSHOT_DIR")
    return Path(folder) if folder else tmp_path_factory.mktemp("screenshots")


@pytest.fixture(scope="module")
def playwright() -> Iterator[Any]:
    from playwright.sync_api import sync_playwright

    with sync_playwright() as driver:
        yield driver


@pytest.fixture(scope="module")
def program(tmp_path_factory: Any) -> Iterator[WebProgram]:
    folder = tmp_path_factory.mktemp("run")
    (folder / "config").mkdir()
    running = WebProgram("run", "--platform", "mujoco", "--debug-port", "0", "--web-port", "0", "--status-interval", "1",
                         "--config", str(folder / "config"), cwd=folder)
    yield running
    running.stop()


@pytest.fixture(scope="module")
def page(playwright: Any, program: WebProgram) -> Iterator[Any]:
    browser = launch(playwright)
    context = browser.new_context(viewport={"width": 1600, "height": 1700})
    view = context.new_page()
    view.problems = []  # console errors and uncaught exceptions, for the whole session
    view.on("console", lambda m: view.problems.append(f"console {m.type}: {m.text}") if m.type == "error" else None)
    view.on("pageerror", lambda e: view.problems.append(f"page error: {e}"))
    view.goto(program.url)
    wait_for(view, "window.tafel && tafel.state.ready")
    yield view
    browser.close()


def test_the_page_loads_without_errors_and_shows_every_view(page: Any, program: WebProgram, tmp_path_factory: Any) -> None:
    wait_for(page, "tafel.state.robot && tafel.state.images.top.drawn > 5 && tafel.state.stopwatches && tafel.state.modules.graphs.cognition")
    page.evaluate("tafel.state.plots.add('rep:RobotPose', 'x')")
    page.select_option("[data-view=representations] select", "BallModel")
    wait_for(page, "tafel.state.inspected && tafel.state.inspected.topic === 'BallModel'")
    time.sleep(1.5)  # a second and a half of plot
    folder = screenshot_dir(tmp_path_factory)
    for view in VIEWS:
        page.locator(f"[data-view={view}]").screenshot(path=str(folder / f"{view}.png"))
        assert (folder / f"{view}.png").stat().st_size > 1000
    page.screenshot(path=str(folder / "page.png"))
    assert page.title() == "Tafel RobotControl"
    assert "mujoco" in page.inner_text("#identity")
    assert page.problems == []


def test_the_field_view_puts_the_robot_where_the_simulator_has_it(page: Any, program: WebProgram) -> None:
    for _ in range(3):  # three moments, as the robot walks
        truth = re.search(r"robot x=(-?\d+) y=(-?\d+) mm rotation (-?[\d.]+) rad", program.ask("sim:status"))
        shown = page.evaluate("tafel.state.robot")
        x, y, rotation = (float(v) for v in truth.groups())
        assert shown["valid"], shown
        assert math.hypot(shown["x"] - x, shown["y"] - y) < 300, (shown, truth.group(0))
        assert abs(math.remainder(shown["rotation"] - rotation, math.tau)) < math.radians(15), (shown, truth.group(0))
        time.sleep(1.0)
    # and the page drew it: the robot's pixel on the canvas is the pose's
    transform = page.evaluate("tafel.state.fieldTransform")
    assert transform["scale"] > 0.03


def test_switching_a_debug_request_in_the_page_switches_it_in_the_program(page: Any, program: WebProgram) -> None:
    box = page.locator("[data-request='FieldBoundaryDetector:draw']")
    box.wait_for()
    assert not box.is_checked()
    box.check()
    deadline = time.monotonic() + 10
    while "on  FieldBoundaryDetector:draw" not in program.ask("debug_request:list"):
        assert time.monotonic() < deadline, program.ask("debug_request:list")
        time.sleep(0.2)
    # its drawings reach the image view
    wait_for(page, "tafel.state.images.top.drawn > 0")
    box.uncheck()
    deadline = time.monotonic() + 10
    while "off FieldBoundaryDetector:draw" not in program.ask("debug_request:list"):
        assert time.monotonic() < deadline
        time.sleep(0.2)


def test_editing_a_parameter_in_the_page_changes_the_module(page: Any, program: WebProgram) -> None:
    field = page.locator("[data-parameter='FieldColorProvider.smoothing']")
    field.wait_for()
    field.fill("0.45")
    field.press("Enter")
    field.dispatch_event("change")
    deadline = time.monotonic() + 10
    while "smoothing = 0.45" not in program.ask("parameter:get -module FieldColorProvider"):
        assert time.monotonic() < deadline, program.ask("parameter:get -module FieldColorProvider")
        time.sleep(0.2)
    page.locator("[data-view=parameters] legend:has-text('FieldColorProvider') button").click()
    wait_for(page, "document.querySelector('[data-view=parameters] .ok')?.textContent.includes('stored')")
    stored = list(Path(program.process.args[program.process.args.index("--config") + 1]).glob("private/*.toml"))
    assert stored and "smoothing = 0.45" in stored[0].read_text()
    field.fill("0.3")
    field.dispatch_event("change")


def test_switching_the_ball_model_provider_in_the_modules_view(page: Any, program: WebProgram) -> None:
    choice = page.locator("[data-view=modules] select[data-representation=BallModel]")
    choice.wait_for()
    choice.select_option("SimpleBallModeler")
    deadline = time.monotonic() + 10
    while "provider BallModel: SimpleBallModeler" not in program.ask("modules:list"):
        assert time.monotonic() < deadline, program.ask("modules:list")
        time.sleep(0.2)
    wait_for(page, "tafel.state.modules.graphs.cognition.representations.BallModel.provider === 'SimpleBallModeler'")
    page.locator("[data-view=modules] select[data-representation=BallModel]").select_option("KalmanBallModeler")
    deadline = time.monotonic() + 10
    while "provider BallModel: KalmanBallModeler" not in program.ask("modules:list"):
        assert time.monotonic() < deadline
        time.sleep(0.2)


def test_the_image_view_updates_at_least_ten_times_a_second(page: Any) -> None:
    before = page.evaluate("[tafel.state.images.top.drawn, tafel.state.images.bottom.drawn, performance.now()]")
    time.sleep(3.0)
    after = page.evaluate("[tafel.state.images.top.drawn, tafel.state.images.bottom.drawn, performance.now()]")
    seconds = (after[2] - before[2]) / 1000
    top, bottom = (after[0] - before[0]) / seconds, (after[1] - before[1]) / seconds
    assert top >= 10 and bottom >= 10, (top, bottom)


def test_the_motion_remote_control_walks_the_robot(page: Any, program: WebProgram) -> None:
    page.locator("[data-view=remote] button:has-text('forward')").click()
    deadline = time.monotonic() + 10
    while '"motion": "walk"' not in program.ask("representation:print -name MotionRequest -context motion -format json").replace('":"', '": "'):
        assert time.monotonic() < deadline
        time.sleep(0.2)
    page.locator("[data-view=remote] button:has-text('release')").click()
    wait_for(page, "document.querySelector('[data-view=remote] .ok')?.textContent.includes('released')")
    assert page.problems == []


@pytest.fixture(scope="module")
def recorded(tmp_path_factory: Any) -> Path:
    log = tmp_path_factory.mktemp("log") / "short.mcap"
    running = WebProgram("run", "--platform", "mujoco", "--seconds", "3", "--speed", "max", "--record", str(log),
                         "--debug-port", "0", "--web-port", "0")
    assert running.process.wait(timeout=120) == 0
    running.stop()
    return log


def test_tafel_view_shows_the_recorded_frame_after_a_seek(playwright: Any, recorded: Path, tmp_path_factory: Any) -> None:
    viewer = WebProgram("view", str(recorded), "--web-port", "0")
    browser = launch(playwright)
    try:
        page = browser.new_page(viewport={"width": 1600, "height": 1200})
        problems: list[str] = []
        page.on("pageerror", lambda e: problems.append(str(e)))
        page.on("console", lambda m: problems.append(m.text) if m.type == "error" else None)
        page.goto(viewer.url)
        wait_for(page, "tafel.state.ready && tafel.state.log && tafel.state.log.frame_range[1] > 0")
        assert page.locator("[data-view=log]").is_visible()
        page.select_option("[data-view=representations] select", "RobotPose")
        slider = page.locator("[data-view=log] input[type=range]")
        slider.evaluate("(s) => { s.value = 180; s.dispatchEvent(new Event('input')); s.dispatchEvent(new Event('change')); }")
        wait_for(page, "tafel.state.log.frame === 180 && tafel.state.inspected && tafel.state.inspected.frame > 50")
        time.sleep(0.5)
        shown = page.evaluate("tafel.state.inspected")
        frames = read_log(recorded).frames("cognition")
        recorded_pose = deserialize(RobotPose, frames[shown["frame"]]["RobotPose"].data)
        assert shown["value"]["x"] == pytest.approx(recorded_pose.x) and shown["value"]["y"] == pytest.approx(recorded_pose.y)
        # motion frame 180 is at 1.80 s: cognition's frame then is the 54th (30 Hz)
        assert abs(shown["frame"] - 54) <= 1, shown["frame"]
        page.locator("[data-view=log]").screenshot(path=str(screenshot_dir(tmp_path_factory) / "log.png"))
        page.locator("[data-view=log] button:has-text('step ▶')").click()
        wait_for(page, "tafel.state.log.frame === 181")
        assert problems == []
    finally:
        browser.close()
        viewer.stop()


def test_with_a_token_the_page_asks_for_it(playwright: Any, tmp_path: Path) -> None:
    running = WebProgram("run", "--platform", "dummy", "--debug-port", "0", "--web-port", "0", "--debug-token", "s3cret", cwd=tmp_path)
    browser = launch(playwright)
    try:
        page = browser.new_page()
        page.goto(running.url)
        page.locator("#token-form").wait_for()
        assert not page.evaluate("tafel.state.ready")
        page.fill("#token", "wrong")
        page.click("#token-form button")
        wait_for(page, "document.querySelector('#identity').textContent.includes('wrong token')")
        page.fill("#token", "s3cret")
        page.click("#token-form button")
        wait_for(page, "tafel.state.ready && tafel.state.stopwatches")
        assert "dummy" in page.inner_text("#identity")
    finally:
        browser.close()
        running.stop()


def test_contexts_in_their_own_processes_feed_the_page_too(playwright: Any, tmp_path: Path) -> None:
    running = WebProgram("run", "--platform", "dummy", "--concurrent", "--debug-port", "0", "--web-port", "0", cwd=tmp_path)
    browser = launch(playwright)
    try:
        page = browser.new_page(viewport={"width": 1600, "height": 1200})
        problems: list[str] = []
        page.on("pageerror", lambda e: problems.append(str(e)))
        page.goto(running.url)
        wait_for(page, "tafel.state.ready && tafel.state.robot && tafel.state.stopwatches")
        page.select_option("[data-view=representations] select", "FrameInfo")
        first = wait_for(page, "tafel.state.inspected && tafel.state.inspected.frame")
        wait_for(page, f"tafel.state.inspected.frame > {first + 20}")  # streamed from the context's process
        rates = wait_for(page, "tafel.state.stopwatches.motion && tafel.state.stopwatches.cognition && tafel.state.stopwatches")
        assert rates["motion"]["frame"] > 0 and rates["cognition"]["frame"] > 0
        assert problems == []
    finally:
        browser.close()
        running.stop()
