"""Damaged and hostile logs: how much a flipped bit costs, and what a bomb costs ``tafel log info``.

1. Records a real program (the dummy platform, ``tafel run --record``) long enough for 10 chunks (a
   chunk holds at most one second of frame time), and counts the messages of each chunk.
2. Flips one bit at 50 seeded places of the file, one at a time, reads each damaged copy with the
   log reader, and reports the share of messages recovered (mean and minimum), and in how many cases
   everything but the chunk the bit hit was kept (target: all; at least 90 % on average).
3. Runs ``tafel log info`` as a child process on two bombs built by hand (tests/support/mcap_files.py):
   a 33 kB file whose chunk claims 1 GiB of zeros, and an 8.4 kB one claiming 275 MB of zero records;
   reports each child's peak resident memory and CPU time (``os.wait4``), next to the intact recording's
   (target: under 200 MB).
Prints one JSON line.
"""

from __future__ import annotations

import argparse
import json
import logging
import os
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path
from typing import Any

REPO = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(REPO))

from tafel.core.logs import LogReader  # noqa: E402
from tests.support.mcap_files import cpu_bomb, flip_offsets, flipped, memory_bomb  # noqa: E402

TAFEL = [sys.executable, "-m", "tafel.tools.cli"]


def record(path: Path, frames: int) -> None:
    """A recording of the dummy platform at full speed (one chunk per second of frame time)."""
    result = subprocess.run([*TAFEL, "run", "--platform", "dummy", "--no-debug", "--speed", "max", "--frames", str(frames),
                             "--record", str(path)], capture_output=True, text=True, cwd=REPO,
                            env={**os.environ, "PYTHONPATH": str(REPO)}, timeout=300)
    if result.returncode != 0:
        raise SystemExit(f"recording failed: {result.stderr}")


def chunk_extents(path: Path) -> list[tuple[int, int, int]]:
    """(first byte, end, messages) of every chunk record of the intact recording."""
    data = path.read_bytes()
    with LogReader(path) as reader:
        assert not reader.problems, reader.problems
        return [(c.offset, c.offset + 9 + int.from_bytes(data[c.offset + 1:c.offset + 9], "little"), len(reader.read_chunk(n) or []))
                for n, c in enumerate(reader.chunks)]


def recovered(data: bytes, folder: Path) -> int:
    damaged = folder / "damaged.mcap"
    damaged.write_bytes(data)
    try:
        with LogReader(damaged) as reader:
            return sum(1 for _ in reader.messages())
    except Exception:  # noqa: BLE001 - a file the reader refuses recovers nothing
        return 0


def child_cost(*args: str) -> dict[str, Any]:
    """Peak resident memory (MB) and CPU seconds of one ``tafel`` child process, from its own rusage."""
    with tempfile.TemporaryFile() as output:
        process = subprocess.Popen([*TAFEL, *args], stdout=output, stderr=output, cwd=REPO, env={**os.environ, "PYTHONPATH": str(REPO)})
        _pid, status, usage = os.wait4(process.pid, 0)  # this child's own peak, not the recording's before it
        process.returncode = os.waitstatus_to_exitcode(status)
        output.seek(0)
        text = output.read().decode(errors="replace")
    return {"peak_mb": round(usage.ru_maxrss / 1024, 1), "cpu_s": round(usage.ru_utime + usage.ru_stime, 2),
            "exit": process.returncode, "refused_chunks": text.count("is damaged")}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--flips", type=int, default=50)
    parser.add_argument("--seed", type=int, default=7)
    parser.add_argument("--frames", type=int, default=1000, help="motion frames recorded (100 Hz: 10 s, 10 chunks)")
    args = parser.parse_args()
    logging.getLogger("tafel.log").setLevel(logging.ERROR)  # each damaged copy is reported; the figures are the point
    with tempfile.TemporaryDirectory() as folder:
        work = Path(folder)
        log = work / "run.mcap"
        record(log, args.frames)
        extents = chunk_extents(log)
        total = sum(n for _, _, n in extents)
        data = log.read_bytes()
        shares, kept_rest, in_chunks = [], 0, 0
        for offset, bit in flip_offsets(len(data), args.flips, args.seed):
            hit = next((n for start, end, n in extents if start <= offset < end), 0)
            in_chunks += hit > 0
            survived = recovered(flipped(data, offset, bit), work)
            shares.append(survived / total)
            kept_rest += survived >= total - hit
        bombs = {
            "memory_bomb": memory_bomb(work / "memory.mcap", claimed=1 << 30),
            "cpu_bomb": cpu_bomb(work / "cpu.mcap", claimed=275 << 20),
        }
        costs = {"intact": {**child_cost("log", "info", str(log)), "bytes": len(data)}}
        for name, path in bombs.items():
            costs[name] = {**child_cost("log", "info", str(path)), "bytes": path.stat().st_size}
    print(json.dumps({
        "recording": {"bytes": len(data), "chunks": len(extents), "messages": total},
        "flips": args.flips, "seed": args.seed, "flips_inside_chunks": in_chunks,
        "recovered_share": {"mean": round(statistics.fmean(shares), 4), "min": round(min(shares), 4)},
        "kept_all_but_the_hit_chunk": f"{kept_rest}/{args.flips}",
        "log_info": costs,
        "targets": {"mean_share": 0.9, "all_but_the_hit_chunk": "every case", "bomb_peak_mb": 200},
        "met": statistics.fmean(shares) >= 0.9 and kept_rest == args.flips
               and all(c["peak_mb"] < 200 for k, c in costs.items() if k != "intact"),
    }))


if __name__ == "__main__":
    main()
