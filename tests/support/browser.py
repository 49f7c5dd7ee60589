"""Headless Chromium for the web view's tests and benchmark, driven by Playwright.

Debian's ``chromium`` package is used (``apt-get install chromium``); Playwright's own browser
download is not needed. ``TAFEL_CHROMIUM`` may name another executable.
"""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
import threading
import time
from pathlib import Path
from typing import Any

from tests.support.processes import stop_program

REPO = Path(__file__).resolve().parents[2]
#: flags for a machine without display or internet: no sandbox (root), no GPU, no background traffic
CHROMIUM_FLAGS = ["--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run", "--disable-background-networking",
                  "--disable-component-update", "--disable-sync", "--disable-dev-shm-usage"]


def chromium_path() -> str | None:
    return os.environ.get("TAFEL_CHROMIUM") or shutil.which("chromium") or shutil.which("chromium-browser")


def missing_browser() -> str | None:
    """Why browser tests cannot run here, or None."""
    try:
        import playwright.sync_api  # noqa: F401
    except ImportError:
        return "Playwright is not installed (pip install -e '.[test]')"
    if chromium_path() is None:
        return "no Chromium: install Debian's package (sudo apt-get install chromium) or set TAFEL_CHROMIUM"
    return None


def launch(playwright: Any) -> Any:
    return playwright.chromium.launch(executable_path=chromium_path(), args=CHROMIUM_FLAGS)


def wait_for(page: Any, expression: str, timeout: float = 20.0) -> Any:
    """Poll a JavaScript expression of the page until it is truthy; its value."""
    deadline = time.monotonic() + timeout
    while True:
        value = page.evaluate(expression)
        if value:
            return value
        assert time.monotonic() < deadline, f"the page never made {expression} true"
        time.sleep(0.1)


def open_page(browser: Any, url: str, width: int = 1600, height: int = 1700) -> Any:
    """A tab on ``url``, ready (connected, the program's commands known); ``page.problems`` collects
    console errors and uncaught exceptions."""
    view = browser.new_context(viewport={"width": width, "height": height}).new_page()
    view.problems = []
    view.on("console", lambda m: view.problems.append(f"console {m.type}: {m.text}") if m.type == "error" else None)
    view.on("pageerror", lambda e: view.problems.append(f"page error: {e}"))
    view.goto(url)
    wait_for(view, "window.tafel && tafel.state.ready")
    return view


class WebProgram:
    """A ``tafel`` subprocess (``run`` or ``view``) with the addresses of its debug server and page."""

    def __init__(self, *args: str, cwd: Path = REPO, cpus: set[int] | None = None) -> None:
        pin = (lambda: os.sched_setaffinity(0, cpus)) if cpus else None  # noqa: E731 - the program's threads inherit it
        self.process = subprocess.Popen([sys.executable, "-m", "tafel.tools.cli", *args], cwd=cwd, stdout=subprocess.PIPE,
                                        stderr=subprocess.PIPE, text=True, env={**os.environ, "PYTHONPATH": str(REPO)},
                                        preexec_fn=pin)
        self.output: list[str] = []
        self.errors: list[str] = []
        self.debug: tuple[str, int] | None = None
        self.url = ""
        for line in self.process.stdout:
            self.output.append(line)
            if match := re.match(r"debug server listening on ([\d.]+):(\d+)", line):
                self.debug = (match.group(1), int(match.group(2)))
            if match := re.match(r"web view at (http://\S+)", line):
                self.url = match.group(1)
                break
        assert self.url and self.debug, "".join(self.output) + self.process.stderr.read()
        #: when each line of ``errors`` arrived (monotonic s): status lines come at wall-clock intervals
        self.error_times: list[float] = []
        self.readers = [threading.Thread(target=lambda: self.output.extend(self.process.stdout), daemon=True),
                        threading.Thread(target=self._drain_errors, daemon=True)]
        for reader in self.readers:
            reader.start()

    def _drain_errors(self) -> None:
        for line in self.process.stderr:
            self.error_times.append(time.monotonic())
            self.errors.append(line)

    def ask(self, line: str) -> str:
        from tafel.debug.client import DebugClient

        assert self.debug is not None
        with DebugClient(*self.debug) as client:
            return client.ask(line)

    def stop(self) -> tuple[str, str]:
        return stop_program(self.process, self.readers, self.output, self.errors)
