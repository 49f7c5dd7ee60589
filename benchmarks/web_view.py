"""The web view's cost: the default simulation (MuJoCo, both cameras, speed 1) without a page, then with
three browser tabs open on every view (headless Chromium).

Also: how soon a page learns every plot name the program has (``plot:get``), the way the page does it
(the program's ``PlotNames``, sent when a name is new) and the way it did before (``DebugPlots`` sampled
twice a second across both contexts), each from a fresh WebSocket, 60 s at most.

Reported, for each phase, from the program's own status line (one a second): the loop rates and the
frames lost (frames the loops should have run at their rates in the phase's wall time but did not).
With the tabs: the images each tab received per second and camera, what the page's feed dropped for
slow tabs, and the server's CPU share: the CPU time of the threads that serve the page (the debug
server's network thread and the web view's encoder), as a share of one core. The commands the pages
send run between frames in the loop's thread and are part of its time.

The browser runs on this machine too. By default the program gets core 0 and the browser (Chromium
and Playwright's driver) the others, as when the browser runs on a laptop beside the robot: then the
figures say what serving the page costs the loops. ``--shared-cores`` lets them compete for every
core, which on two cores says how much of the machine three software-rendered tabs take.

    python benchmarks/web_view.py [--seconds 10] [--tabs 3] [--shared-cores]

Prints one JSON line. Needs Playwright and Chromium (see the README).
"""

from __future__ import annotations

import argparse
import json
import os
import re
import statistics
import sys
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

REPO = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(REPO))

from tafel.tools.simulation.match import cpu_seconds as process_cpu_seconds  # noqa: E402
from tests.support.attack import status_rates  # noqa: E402
from tests.support.browser import WebProgram, launch, missing_browser  # noqa: E402

RATES = {"cognition": 30.0, "motion": 100.0}


def cpu_seconds(pid: int) -> float:
    """User and system CPU time of a process (all its threads), in seconds; 0 for one that is gone."""
    return process_cpu_seconds(pid) or 0.0


def browser_cpu_seconds() -> float:
    """CPU time of the browser: every Chromium process on the machine and Playwright's driver."""
    total = 0.0
    for entry in Path("/proc").iterdir():
        if entry.name.isdigit():
            try:
                command = (entry / "cmdline").read_bytes()
                if b"chromium" in command or b"playwright" in command:
                    total += cpu_seconds(int(entry.name))
            except OSError:
                pass
    return total


def thread_cpu_seconds(pid: int, prefix: str) -> float:
    """CPU time of a process's threads whose name starts with ``prefix``."""
    total = 0.0
    for task in Path(f"/proc/{pid}/task").iterdir():
        try:
            if (task / "comm").read_text().startswith(prefix):
                fields = (task / "stat").read_text().rsplit(")", 1)[1].split()
                total += (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")
        except OSError:
            pass
    return total


FRAMES = re.compile(r"(cognition|motion) [\d.]+ Hz (\d+) frames")


def phase(program: WebProgram, seconds: float) -> dict[str, float]:
    """Rates, lost frames and CPU shares over ``seconds`` of the running program."""
    pid = program.process.pid
    start_lines, started = len(program.errors), time.monotonic()
    cpu = [cpu_seconds(pid), thread_cpu_seconds(pid, "tafel-web"), thread_cpu_seconds(pid, "tafel-debug"), browser_cpu_seconds()]
    time.sleep(seconds)
    wall = time.monotonic() - started
    cpu = [after - before for after, before in zip([cpu_seconds(pid), thread_cpu_seconds(pid, "tafel-web"),
                                                    thread_cpu_seconds(pid, "tafel-debug"), browser_cpu_seconds()], cpu)]
    stamped = [(t, line) for t, line in zip(program.error_times[start_lines:], program.errors[start_lines:]) if line.startswith("[tafel]")]
    lines = [line for _, line in stamped]
    result: dict[str, float] = {"program_cpu_share": round(cpu[0] / wall, 3), "web_threads_cpu_share": round((cpu[1] + cpu[2]) / wall, 3),
                                "browser_cpu_share": round(cpu[3] / wall, 3)}
    for name, values in status_rates(lines[1:]).items():
        if values:
            result[f"{name}_mean_hz"] = round(statistics.fmean(values), 2)
            result[f"{name}_min_hz"] = min(values)
    # lost: frames the loop should have run at its rate between the first and the last status line (wall
    # clock), and did not
    counts = {name: [int(n) for line in lines for c, n in FRAMES.findall(line) if c == name] for name in RATES}
    span = stamped[-1][0] - stamped[0][0] if len(stamped) > 1 else 0.0
    for name, frames in counts.items():
        if span > 0 and len(frames) == len(lines):
            result[f"{name}_frames_lost"] = max(0, round(RATES[name] * span - (frames[-1] - frames[0])))
    return result


def name_discovery(program: WebProgram, line: str, names_of: Callable[[dict[str, Any]], list[str]], limit: float = 60.0) -> float | None:
    """Seconds from subscribing with ``line`` until every plot name ``plot:get`` lists has come; None: not within ``limit``."""
    from websockets.sync.client import connect

    wanted = {row.split(" (")[0] for row in program.ask("plot:get").splitlines() if row.strip()}
    url = program.url.replace("http://", "ws://") + "ws"
    seen: set[str] = set()
    with connect(url, max_size=None) as socket:
        started = time.monotonic()
        socket.send(line)
        while time.monotonic() - started < limit:
            try:
                message = socket.recv(timeout=1.0)
            except TimeoutError:
                continue
            if isinstance(message, str) and "topic" in (parsed := json.loads(message)):
                seen.update(names_of(parsed))
                if wanted <= seen:
                    return round(time.monotonic() - started, 2)
    return None


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--seconds", type=float, default=10.0, help="length of each phase")
    parser.add_argument("--tabs", type=int, default=3)
    parser.add_argument("--shared-cores", action="store_true",
                        help="let the browser and the program share every core (by default the program runs on core 0 "
                             "and the browser on the others, as a laptop beside the robot would)")
    args = parser.parse_args()
    missing = missing_browser()
    if missing:
        sys.exit(f"web_view benchmark: {missing}")
    from playwright.sync_api import sync_playwright

    cores = sorted(os.sched_getaffinity(0))
    separate = not args.shared_cores and len(cores) > 1
    program = WebProgram("run", "--platform", "mujoco", "--debug-port", "0", "--web-port", "0", "--status-interval", "1",
                         cpus={cores[0]} if separate else None)
    if separate:  # this process, Playwright's driver and Chromium (started from here) keep off the program's core
        os.sched_setaffinity(0, set(cores[1:]))
    try:
        time.sleep(3.0)  # stand up, first images
        without = phase(program, args.seconds)
        with sync_playwright() as driver:
            browser = launch(driver)
            pages = []
            for _ in range(args.tabs):
                page = browser.new_page(viewport={"width": 1920, "height": 1080})
                page.goto(program.url)
                pages.append(page)
            for page in pages:
                page.wait_for_function("window.tafel && tafel.state.ready && tafel.state.images.top.count > 0", timeout=30000)
                page.evaluate("tafel.state.plots.add('rep:RobotPose', 'x'); tafel.state.plots.add('rep:BallModel', 'x')")
                page.select_option("[data-view=representations] select", "BallModel")
            time.sleep(2.0)
            counts = "[tafel.state.images.top.count, tafel.state.images.bottom.count, performance.now()]"
            before = [page.evaluate(counts) for page in pages]
            served_before = json.loads(program.ask("web:status"))
            with_tabs = phase(program, args.seconds)
            after = [page.evaluate(counts) for page in pages]
            served_after = json.loads(program.ask("web:status"))
            problems = [page.evaluate("[...document.querySelectorAll('.error')].map((e) => e.textContent.trim().slice(0, 120))")
                        for page in pages]
            browser.close()
        names_now = name_discovery(program, "subscribe PlotNames", lambda m: m["value"]["names"])
        names_before = name_discovery(program, "subscribe DebugPlots -hz 2", lambda m: m["value"]["names"])
        per_tab = [{"top_per_s": round((a[0] - b[0]) / ((a[2] - b[2]) / 1000), 1),
                    "bottom_per_s": round((a[1] - b[1]) / ((a[2] - b[2]) / 1000), 1)} for a, b in zip(after, before)]
    finally:
        program.stop()
    print(json.dumps({
        "benchmark": "web_view", "platform": "mujoco", "speed": 1, "phase_s": args.seconds, "tabs": args.tabs,
        "cores": {"program": [cores[0]], "browser": cores[1:]} if separate else {"shared": cores},
        "without_page": without, "with_tabs": with_tabs,
        "images_per_tab": per_tab,
        "feed": {key: served_after[key] - served_before[key] for key in ("encoded", "sent", "dropped", "skipped", "handed_over_dropped")},
        "server_cpu_share": with_tabs["web_threads_cpu_share"],
        "pages_showing_errors": sum(1 for shown in problems if shown),
        "errors_shown": sorted({text for shown in problems for text in shown})[:5],
        "plot_names_s": {"pushed_when_new": names_now, "before_sampled_at_2_hz": names_before},
        "targets": {"cognition_hz": 30.0, "motion_hz": 100.0, "frames_lost": 0, "images_per_tab_and_camera_per_s": 15.0},
    }))


if __name__ == "__main__":
    main()
