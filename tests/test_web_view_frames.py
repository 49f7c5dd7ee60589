"""The web view and the frames things were made in: drawings over the image they were computed from,
and new plot names as soon as the program has them. The program runs a test module
(``tests/support/frame_stamp.py``) that writes each frame's number into the top image and starts a plot
on request; the main browser tests (``test_web_view.py``) run without it, so their screenshots show
only what ships.
"""

from __future__ import annotations

import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from tests.support.browser import WebProgram, launch, missing_browser, open_page, wait_for

pytestmark = [pytest.mark.slow, pytest.mark.skipif(missing_browser() is not None, reason=str(missing_browser()))]
FRAME_STAMP = "tests.support.frame_stamp:FrameStamp"


@pytest.fixture(scope="module")
def program(tmp_path_factory: Any) -> Iterator[WebProgram]:
    folder: Path = tmp_path_factory.mktemp("stamped")
    running = WebProgram("run", "--platform", "mujoco", "--debug-port", "0", "--web-port", "0",
                         "--add-module", f"cognition:{FRAME_STAMP}", cwd=folder)
    yield running
    running.stop()


@pytest.fixture(scope="module")
def page(program: WebProgram) -> Iterator[Any]:
    from playwright.sync_api import sync_playwright

    with sync_playwright() as driver:
        browser = launch(driver)
        view = open_page(browser, program.url)
        wait_for(view, "tafel.state.images.top.drawn > 3")
        yield view
        assert view.problems == []
        browser.close()


def test_a_new_plot_name_reaches_the_page_soon(page: Any, program: WebProgram) -> None:
    page.evaluate("document.querySelector('[data-view=plots]').scrollIntoView()")
    options = "[...document.querySelectorAll('[data-view=plots] option')].map((o) => o.textContent)"
    assert "FrameStamp:frame" not in page.evaluate(options)
    program.ask("debug_request:set -name FrameStamp:plot -value on")
    try:
        # before the program pushed new names, they took about 25 s to come (a 2 Hz sample of both contexts)
        wait_for(page, f"{options}.includes('FrameStamp:frame')", timeout=10)
    finally:
        program.ask("debug_request:set -name FrameStamp:plot -value off")


def test_image_drawings_are_drawn_over_the_image_they_were_made_from(page: Any, program: WebProgram) -> None:
    # the page's drawing calls on the top image: an image clears the stamp, a drawn text is the stamp
    page.evaluate("""() => { const top = document.querySelector('[data-view=images] canvas'); const C = CanvasRenderingContext2D.prototype;
      const draw = C.drawImage, text = C.fillText; window.stamp = null;
      C.drawImage = function (...a) { if (this.canvas === top) window.stamp = null; return draw.apply(this, a); };
      C.fillText = function (...a) { if (this.canvas === top) window.stamp = String(a[0]); return text.apply(this, a); }; }""")
    program.ask("debug_request:set -name FrameStamp:draw -value on")
    try:
        pairs = []
        deadline = time.monotonic() + 30
        while len(pairs) < 40:
            assert time.monotonic() < deadline, pairs
            frame, stamp = page.evaluate("[tafel.state.images.top.frame, window.stamp]")
            if stamp is not None and (not pairs or pairs[-1][0] != frame):
                pairs.append((frame, int(stamp)))
            time.sleep(0.05)
        wrong = [(frame, stamp) for frame, stamp in pairs if frame != stamp]
        assert wrong == [], f"{len(wrong)} of {len(pairs)} images carried another frame's drawings: {wrong[:5]}"
    finally:
        program.ask("debug_request:set -name FrameStamp:draw -value off")
