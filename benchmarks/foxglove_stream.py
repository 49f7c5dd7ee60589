"""What Foxglove's channels cost, in recordings and live, in the default MuJoCo simulation.

- Recording: the default program at --speed max records 10 simulated seconds without a recording, with a
  recording of only Tafel's channels, and with the Foxglove channels too. Reported per cognition frame:
  the process's CPU time (ms; the loops and the writer thread together) and the wall time.
- Live: ``tafel run --foxglove`` at --speed max for 10 simulated seconds with no client, then with one
  client subscribed to every topic (our own client of the WebSocket protocol): wall time per cognition
  frame, against the same run without ``--foxglove``.
- Speed 1: 10 simulated seconds with one client subscribed to everything and, as the baseline, without
  the server: the wall time they took, the frames lost (wall time beyond 10 s, times 130 frames a
  second), the status line's mean rates, and the rate of ``/camera/top`` messages the client received.

    python benchmarks/foxglove_stream.py

Prints one JSON line. Target: no frames lost at speed 1 with one client subscribed.
"""

from __future__ import annotations

import json
import os
import re
import subprocess
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(REPO))
os.environ.setdefault("MUJOCO_GL", "egl")

from tests.support.foxglove_client import FoxgloveClient  # noqa: E402

SIMULATED_S = 10.0
COGNITION_FRAMES = int(SIMULATED_S * 30)


def tafel_run(*options: str, client: bool = False, seconds: float = SIMULATED_S, speed: str = "max") -> dict[str, float]:
    """One ``tafel run`` of the default MuJoCo scene: wall and CPU seconds, and what a client saw."""
    with tempfile.TemporaryDirectory() as folder:
        command = [sys.executable, "-m", "tafel.tools.cli", "run", "--platform", "mujoco", "--seconds", str(seconds), "--speed", speed,
                   "--debug-port", "0", "--status-interval", "1", *options]
        process = subprocess.Popen(command, cwd=folder, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                                   env={**os.environ, "PYTHONPATH": str(REPO)})
        seen: dict[str, float] = {}
        if client:
            url = None
            while url is None:
                line = process.stdout.readline()
                if not line:
                    raise RuntimeError(process.stderr.read())
                match = re.search(r"foxglove server listening on (\S+)", line)
                url = match.group(1) if match else None
            viewer = FoxgloveClient(url)
            viewer.subscribe(*sorted(viewer.wait_for(viewer.topics)))
            start = time.monotonic()
            while process.poll() is None and not viewer.closed:
                viewer.pump(0.2)
            seen = {"camera_top_messages": len(viewer.received.get("/camera/top", [])), "client_s": time.monotonic() - start}
            viewer.close()
        out, err = process.communicate()
        if process.returncode != 0:
            raise RuntimeError(err)
        wall = float(re.search(r"wall time ([\d.]+) s", out).group(1))
        return {"wall_s": wall, "status": err, **seen}


def cpu_run(*options: str) -> dict[str, float]:
    """CPU seconds (children's user + system) and wall seconds of one run."""
    before = os.times()
    result = tafel_run(*options)
    after = os.times()
    return {"cpu_s": (after.children_user - before.children_user) + (after.children_system - before.children_system), **result}


def per_frame(result: dict[str, float], key: str) -> float:
    return round(result[key] / COGNITION_FRAMES * 1000.0, 3)


def main() -> None:
    with tempfile.TemporaryDirectory() as folder:
        log = str(Path(folder) / "run.mcap")
        plain = cpu_run("--no-debug")
        tafel_only = cpu_run("--no-debug", "--record", log, "--set", "foxglove.channels_in_recordings=false")
        with_foxglove = cpu_run("--no-debug", "--record", log)
    live_off = cpu_run()
    live_idle = cpu_run("--foxglove", "0")
    before = os.times()
    live_client = tafel_run("--foxglove", "0", client=True)
    after = os.times()
    live_client["cpu_s"] = (after.children_user - before.children_user) + (after.children_system - before.children_system)
    speed1_alone = tafel_run(speed="1")
    speed1 = tafel_run("--foxglove", "0", client=True, speed="1")

    def lost(run: dict[str, float]) -> int:
        """Frames a run at speed 1 fell behind its wall clock: (wall - simulated seconds) x 130 frames/s."""
        return max(0, round((run["wall_s"] - SIMULATED_S) * 130))

    rates = [tuple(map(float, m)) for m in re.findall(r"cognition ([\d.]+) Hz \d+ frames \| motion ([\d.]+) Hz", speed1["status"])]
    steady = rates[2:] or rates  # the first seconds include start-up
    cognition = sum(r[0] for r in steady) / len(steady)
    motion = sum(r[1] for r in steady) / len(steady)
    print(json.dumps({
        "benchmark": "foxglove_stream",
        "recording_ms_per_cognition_frame": {
            "cpu_without_recording": per_frame(plain, "cpu_s"), "cpu_tafel_channels": per_frame(tafel_only, "cpu_s"),
            "cpu_with_foxglove_channels": per_frame(with_foxglove, "cpu_s"),
            "wall_without_recording": per_frame(plain, "wall_s"), "wall_tafel_channels": per_frame(tafel_only, "wall_s"),
            "wall_with_foxglove_channels": per_frame(with_foxglove, "wall_s")},
        "live_ms_per_cognition_frame": {
            "cpu_without_server": per_frame(live_off, "cpu_s"), "cpu_server_no_client": per_frame(live_idle, "cpu_s"),
            "cpu_one_client_everything": per_frame(live_client, "cpu_s"),
            "wall_without_server": per_frame(live_off, "wall_s"), "wall_server_no_client": per_frame(live_idle, "wall_s"),
            "wall_one_client_everything": per_frame(live_client, "wall_s")},
        "speed_1_one_client_everything": {
            "status_line_cognition_hz": round(cognition, 2), "status_line_motion_hz": round(motion, 2),
            "wall_s_for_10_simulated_s": speed1["wall_s"], "frames_lost": lost(speed1),
            "camera_top_messages_per_s": round(speed1["camera_top_messages"] / speed1["client_s"], 2)},
        "speed_1_without_server": {"wall_s_for_10_simulated_s": speed1_alone["wall_s"], "frames_lost": lost(speed1_alone)},
        "target": {"frames_lost_at_speed_1_with_one_client": 0},
    }))


if __name__ == "__main__":
    main()
