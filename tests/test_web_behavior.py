"""The Behaviour view in headless Chromium: the active option path the program reports (ActivationGraph)
appears in the page, the option graph is drawn with that path highlighted, the strip fills, and a log's
seek shows the recorded frame's options."""

from __future__ import annotations

import json
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from tafel.core.logs import read_log
from tafel.core.logs.serialization import deserialize
from tafel.representations.behavior import ActivationGraph
from tests.support.browser import WebProgram, launch, missing_browser, open_page, wait_for
from tests.test_web_view import screenshot_dir

pytestmark = [pytest.mark.slow, pytest.mark.skipif(missing_browser() is not None, reason=str(missing_browser()))]


@pytest.fixture(scope="module")
def playwright() -> Iterator[Any]:
    from playwright.sync_api import sync_playwright

    with sync_playwright() as driver:
        yield driver


def test_the_behaviour_view_shows_the_active_options_and_highlights_them_in_the_graph(playwright: Any, tmp_path: Path,
                                                                                      tmp_path_factory: Any) -> None:
    program = WebProgram("run", "--platform", "dummy", "--debug-port", "0", "--web-port", "0", "--config", str(tmp_path), cwd=tmp_path)
    browser = launch(playwright)
    try:
        page = open_page(browser, program.url)
        wait_for(page, "tafel.state.behavior && tafel.state.behavior.graph && tafel.state.behavior.frames > 20")
        said = json.loads(program.ask("representation:print -name ActivationGraph -format json"))["value"]["options"]
        assert said and said[0]["name"] == "PlaySoccer"
        behavior = page.locator("[data-view=behavior]")
        for option in said:  # the program's active options, by name and state, in the path table
            row = behavior.locator(f"table.active-path tr[data-option={option['name']}]")
            wait_for(page, f"document.querySelector('[data-view=behavior] tr[data-option={option['name']}]') !== null")
            assert option["state"] in row.inner_text()
        # drawn: a box per option, the active ones (and their states) highlighted
        drawn = page.evaluate("[...document.querySelectorAll('[data-view=behavior] g.option')].map((g) => g.dataset.option)")
        assert {"PlaySoccer", "Play", "Striker", "Goalkeeper", "GoTo"} <= set(drawn)
        active = page.evaluate("[...document.querySelectorAll('[data-view=behavior] g.option.active')].map((g) => g.dataset.option)")
        assert "PlaySoccer" in active and set(active) <= {o["name"] for o in said} | {"GoTo", "Striker", "Play"}
        root_state = page.evaluate("document.querySelector('[data-view=behavior] g.option[data-option=PlaySoccer] rect.state.active')"
                                   ".dataset.state")
        assert root_state == said[0]["state"]
        wait_for(page, "tafel.state.behavior.history.length > 30")
        strip = page.evaluate("(() => { const c = document.querySelector('[data-view=behavior] canvas.history-strip');"
                              " const d = c.getContext('2d').getImageData(0, 0, c.width, c.height).data;"
                              " let n = 0; for (let i = 3; i < d.length; i += 4) if (d[i]) n++; return n; })()")
        assert strip > 500  # the strip is painted
        time.sleep(0.5)
        behavior.screenshot(path=str(screenshot_dir(tmp_path_factory) / "behavior.png"))
        assert page.problems == []
    finally:
        browser.close()
        program.stop()


def test_on_a_log_a_seek_shows_the_recorded_frames_options(playwright: Any, tmp_path: Path) -> None:
    log = tmp_path / "short.mcap"
    recording = WebProgram("run", "--platform", "dummy", "--seconds", "3", "--record", str(log), "--debug-port", "0", "--web-port", "0",
                           cwd=tmp_path)
    assert recording.process.wait(timeout=120) == 0
    recording.stop()
    viewer = WebProgram("view", str(log), "--web-port", "0")
    browser = launch(playwright)
    try:
        page = open_page(browser, viewer.url)
        wait_for(page, "tafel.state.ready && tafel.state.log && tafel.state.log.frame_range[1] > 0")
        slider = page.locator("[data-view=log] input[type=range]")
        slider.evaluate("(s) => { s.value = 150; s.dispatchEvent(new Event('input')); s.dispatchEvent(new Event('change')); }")
        wait_for(page, "tafel.state.log.frame === 150 && tafel.state.behavior.active.length > 0")
        time.sleep(0.5)
        shown = page.evaluate("tafel.state.behavior")
        recorded = deserialize(ActivationGraph, read_log(log).frames("cognition")[shown["frame"]]["ActivationGraph"].data)
        assert [(o["name"], o["state"]) for o in shown["active"]] == [(o.name, o.state) for o in recorded.options]
        assert shown["active"][0]["time_in_option"] == pytest.approx(recorded.options[0].time_in_option)
        assert page.problems == []
    finally:
        browser.close()
        viewer.stop()
