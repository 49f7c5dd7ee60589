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

from tafel.core.logs import read_log
from tafel.core.logs.serialization import deserialize
from tafel.representations.modeling import RobotPose
from tests.support.attack import loop_frames, skip_without_headroom
from tests.support.browser import WebProgram, launch, missing_browser, open_page, wait_for

pytestmark = [pytest.mark.slow, pytest.mark.skipif(missing_browser() is not None, reason=str(missing_browser()))]
VIEWS = ("field", "images", "status", "remote", "plots", "stopwatches", "modules", "representations", "requests", "modify",
         "parameters")


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
    yield open_page(browser, program.url)  # its problems: console errors and uncaught exceptions, for the whole session
    browser.close()


def test_the_page_loads_without_errors_and_shows_every_view(page: Any, program: WebProgram, tmp_path_factory: Any) -> None:
    wait_for(page, "tafel.state.robot && tafel.state.images.top.drawn > 5 && tafel.state.stopwatches && tafel.state.modules.graphs.cognition")
    page.evaluate("tafel.state.plots.add('rep:RobotPose', 'x'); tafel.state.plots.add('rep:RobotPose', 'rotation')")
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


def test_a_list_asked_for_before_a_click_does_not_undo_the_click_on_the_page(page: Any, program: WebProgram) -> None:
    """The requests view asks for the list every 3 s; an answer to a question asked before the user's
    click arrives after it and must not show the box as it was (the user would switch it back)."""
    box = "document.querySelector(\"[data-request='FieldBoundaryDetector:draw']\")"
    page.evaluate("""() => {  // hold every answer to the list until the test lets it go
      const connection = tafel.connection;
      window.held = [];
      window.realJson = connection.json;
      connection.json = (line) => line.startsWith("debug_request:list")
        ? window.realJson.call(connection, line).then((value) => new Promise((resolve) => window.held.push(() => resolve(value))))
        : window.realJson.call(connection, line);
    }""")
    try:
        wait_for(page, "window.held.length > 0")  # a list asked for with the box off
        assert page.evaluate(f"{box}.checked") is False
        page.locator("[data-request='FieldBoundaryDetector:draw']").check()
        deadline = time.monotonic() + 10
        while "on  FieldBoundaryDetector:draw" not in program.ask("debug_request:list"):
            assert time.monotonic() < deadline, program.ask("debug_request:list")
            time.sleep(0.2)
        shown = page.evaluate(f"""async () => {{
          tafel.connection.json = window.realJson;
          window.held.forEach((release) => release());
          await new Promise((resolve) => setTimeout(resolve, 300));
          return {box}.checked;
        }}""")
        assert shown is True
    finally:
        page.evaluate("tafel.connection.json = window.realJson; window.held.forEach((release) => release())")
    page.locator("[data-request='FieldBoundaryDetector:draw']").uncheck()
    deadline = time.monotonic() + 10
    while "off FieldBoundaryDetector:draw" not in program.ask("debug_request:list"):
        assert time.monotonic() < deadline, program.ask("debug_request:list")
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


def test_the_modify_panel_pins_a_value_of_the_walk(page: Any, program: WebProgram) -> None:
    field = page.locator("[data-modify='WalkingEngine:foot_lift']")
    field.wait_for()
    row = page.locator("[data-view=modify] tr", has=field)
    field.fill("30")
    row.locator("button:has-text('pin')").click()
    wait_for(page, "document.querySelector('[data-view=modify] .ok')?.textContent.includes('pinned to 30')")
    assert "WalkingEngine:foot_lift = 22  (pinned to 30" in program.ask("modify:list -context motion")
    row.locator("button:has-text('release')").click()
    deadline = time.monotonic() + 10
    while "pinned" in program.ask("modify:list -context motion"):
        assert time.monotonic() < deadline
        time.sleep(0.2)


@pytest.mark.alone
def test_the_image_view_updates_at_least_ten_times_a_second(page: Any, program: WebProgram) -> None:
    """Judged where the program keeps its cognition beat meanwhile (its own frame count): where the machine's cores
    are used up, fewer images are made to be drawn, whatever the page does."""
    def cognition_frame() -> int:
        return loop_frames(program.ask("stopwatch:list"))["cognition"]

    wait_for(page, "tafel.state.images.top.drawn && tafel.state.images.bottom.drawn")  # the first images are in
    start = time.monotonic(), cognition_frame()
    before = page.evaluate("[tafel.state.images.top.drawn, tafel.state.images.bottom.drawn, performance.now()]")
    time.sleep(3.0)
    after = page.evaluate("[tafel.state.images.top.drawn, tafel.state.images.bottom.drawn, performance.now()]")
    end = time.monotonic(), cognition_frame()
    seconds = (after[2] - before[2]) / 1000
    top, bottom = (after[0] - before[0]) / seconds, (after[1] - before[1]) / seconds
    assert top >= 3 and bottom >= 3, (top, bottom)  # the view follows at all
    skip_without_headroom({"cognition": (end[1] - start[1]) / (end[0] - start[0])}, "the page")
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


def test_every_plot_has_its_own_labelled_axis_and_a_read_out_under_the_mouse(page: Any) -> None:
    # the charts the page makes, as uPlot instances (the page calls the global uPlot by name)
    page.evaluate("""() => { if (window.charts) return; const U = window.uPlot; window.charts = [];
      window.uPlot = Object.assign(function (...a) { const u = new U(...a); charts.push(u); return u; }, U); }""")
    page.evaluate("""() => { const shown = tafel.state.plots.series.map((s) => s.label);
      for (const path of ['x', 'rotation', 'y']) if (!shown.includes(`RobotPose.${path}`)) tafel.state.plots.add('rep:RobotPose', path); }""")
    wait_for(page, "charts.length && charts.at(-1).data[0].length > 20")
    chart = "charts.at(-1)"
    count = page.evaluate(f"{chart}.series.length - 1")
    assert count >= 3  # RobotPose.x and y (thousands, negative too), rotation (about ±3)
    axes = page.evaluate(f"""{chart}.axes.slice(1).map((a) => ({{scale: a.scale, label: a.label, size: a._size,
      ticks: a._values, widest: Math.max(...(a._values || []).map((t) => {chart}.ctx.measureText(String(t)).width))}}))""")
    scales = page.evaluate(f"{chart}.series.slice(1).map((s) => s.scale)")
    labels = page.evaluate(f"{chart}.series.slice(1).map((s) => s.label)")
    assert len(set(scales)) == count, scales  # a scale of its own for each series, so none is flattened
    for scale, label in zip(scales, labels):
        axis = next(a for a in axes if a["scale"] == scale)
        assert axis["label"] and label.split(".")[-1] in axis["label"], (label, axis)
        assert axis["ticks"] and len(set(axis["ticks"])) >= 2, axis  # labelled ticks, not a lone "0"
        assert axis["widest"] <= axis["size"], axis  # negative labels fit their axis
    box = page.locator("[data-view=plots] .u-over").bounding_box()
    page.mouse.move(box["x"] + box["width"] * 0.7, box["y"] + box["height"] / 2)
    readout = wait_for(page, r"""(() => { const values = [...document.querySelectorAll('[data-view=plots] .u-legend .u-series')]
      .slice(1).map((row) => row.querySelector('.u-value')?.textContent); return values.length && values.every((v) => /\d/.test(v)) && values; })()""")
    assert len(readout) == count
    legend = page.locator("[data-view=plots] .u-legend").bounding_box()
    panel = page.locator("[data-view=plots] .panel-body").bounding_box()
    assert legend["y"] + legend["height"] <= panel["y"] + panel["height"] + 1  # the read-out is inside the panel
    page.mouse.move(0, 0)


def test_the_module_graph_shows_both_contexts_with_arrows_and_fits_and_zooms(page: Any, tmp_path_factory: Any) -> None:
    graph = "[data-view=modules] svg.graph"
    page.locator(graph).wait_for()
    lanes = page.evaluate(f"[...document.querySelectorAll('{graph} g.lane')].map((g) => g.dataset.context)")
    assert lanes == ["cognition", "motion"]
    edges = page.evaluate(f"[...document.querySelectorAll('{graph} path.edge')].map((p) => p.getAttribute('marker-end'))")
    assert edges and all(edges), "every edge ends in an arrowhead"
    # readable as it opens: module names at least 10 px high on the screen
    heights = page.evaluate(f"[...document.querySelectorAll('{graph} g.module text.name')].map((t) => t.getBoundingClientRect().height)")
    assert heights and min(heights) >= 10, heights
    # fitted: every module and representation lies inside the visible picture
    page.locator("[data-view=modules] button:has-text('fit')").click()
    inside = f"""(() => {{ const view = document.querySelector('{graph}').getBoundingClientRect();
      return [...document.querySelectorAll('{graph} g.node')].every((n) => {{ const b = n.getBoundingClientRect();
        return b.top >= view.top - 1 && b.bottom <= view.bottom + 1 && b.left >= view.left - 1 && b.right <= view.right + 1; }}); }})()"""
    assert wait_for(page, inside, timeout=5)
    # zoom with the wheel, pan by dragging
    first = page.evaluate(f"document.querySelector('{graph} g.node').getBoundingClientRect().width")
    box = page.locator(graph).bounding_box()
    page.mouse.move(box["x"] + box["width"] / 2, box["y"] + box["height"] / 2)
    page.mouse.wheel(0, -400)
    zoomed = wait_for(page, f"(() => {{ const w = document.querySelector('{graph} g.node').getBoundingClientRect().width; return w > {first} * 1.2 && w; }})()")
    before = page.evaluate(f"document.querySelector('{graph} g.node').getBoundingClientRect().left")
    page.mouse.down()
    page.mouse.move(box["x"] + box["width"] / 2 + 120, box["y"] + box["height"] / 2 + 10, steps=5)
    page.mouse.up()
    after = page.evaluate(f"document.querySelector('{graph} g.node').getBoundingClientRect().left")
    assert after - before == pytest.approx(120, abs=3), (before, after, zoomed)
    page.locator("[data-view=modules] button:has-text('fit')").click()


def test_an_invalid_ball_model_is_no_disc_on_the_field(page: Any) -> None:
    orange = """(() => { const c = document.querySelector('[data-view=field] canvas');
      const d = c.getContext('2d').getImageData(0, 0, c.width, c.height).data; let n = 0;
      for (let i = 0; i < d.length; i += 4) if (d[i] > 200 && d[i + 1] > 100 && d[i + 1] < 170 && d[i + 2] < 60) n++; return n; })()"""
    # the page as it shows a ball model 6 m uncertain one metre ahead of the robot, then the same model
    # once it lost the ball (the program's own ball models held back meanwhile): nothing of the first
    # may stay, on the carpet or beside it
    page.evaluate("""() => { const c = tafel.connection; c.realDispatch = c.dispatch;
      c.dispatch = (topic, m) => (topic === 'BallModel' && !m.injected ? undefined : c.realDispatch(topic, m)); }""")
    try:
        for valid in (True, False):
            drawn = page.evaluate("tafel.state.fieldDrawn")
            page.evaluate("""(valid) => tafel.connection.dispatch('BallModel', {topic: 'BallModel', context: 'cognition', frame: 1,
              time_ns: 0, injected: true, value: {valid, seen: false, x: 1000, y: 0, vx: 0, vy: 0, position_std: 6000,
              time_since_seen: valid ? 2 : 4}})""", valid)
            wait_for(page, f"tafel.state.fieldDrawn >= {drawn + 2}")  # drawn since
            pixels = page.evaluate(orange)
            assert (pixels >= 10) if valid else (pixels == 0), (valid, pixels)  # the ball itself, or nothing orange
    finally:
        page.evaluate("() => { tafel.connection.dispatch = tafel.connection.realDispatch; }")


def test_the_status_panel_shows_game_state_score_and_pose(page: Any, program: WebProgram) -> None:
    status = "[data-view=status] .panel-body"
    text = wait_for(page, f"(() => {{ const t = document.querySelector('{status}').innerText; return /score/.test(t) && t; }})()")
    state = re.search(r'"state": "(\w+)"', program.ask("representation:print -name GameState -format json").replace('":"', '": "'))
    assert state and state.group(1) in text, text
    assert re.search(r"score \d+ : \d+", text), text
    assert re.search(r"pose x=-?\d+ y=-?\d+ mm", text), text


def test_the_header_never_covers_a_panel_title(page: Any) -> None:
    page.set_viewport_size({"width": 1600, "height": 700})  # a laptop's screen: the page scrolls
    try:
        for view in ("stopwatches", "modules", "representations"):
            title = page.locator(f"[data-view={view}] .panel-title")
            title.evaluate("(t) => t.scrollIntoView()")  # as far up as the page lets it go
            time.sleep(0.2)
            box = title.bounding_box()
            hit = page.evaluate("([x, y]) => document.elementFromPoint(x, y)?.closest('.panel-head') !== null",
                                [box["x"] + box["width"] / 2, box["y"] + box["height"] / 2])
            assert hit, f"the {view} panel's title is covered"
    finally:
        page.set_viewport_size({"width": 1600, "height": 1700})
        page.evaluate("window.scrollTo(0, 0); document.querySelector('#scroller')?.scrollTo(0, 0)")


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
        # a log is watched, not driven: no remote control, no recording
        assert not page.locator("[data-view=remote]").is_visible()
        assert not page.locator("[data-view=status] button:has-text('start recording')").is_visible()
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
