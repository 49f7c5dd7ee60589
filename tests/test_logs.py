"""Recording, reading, replaying and exporting MCAP logs, as a user does it."""

from __future__ import annotations

import csv
import json
import os
import re
import resource
import signal
import socket
import subprocess
import sys
import textwrap
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest

from tafel.core import array, representation
from tafel.core.logs import LogWriter, read_log
from tafel.core.logs.serialization import serialize
from tafel.core.runtime.platform import PlatformError, PlatformOptionError
from tafel.platforms.log import LogPlatform
from tests.support.mcap_files import (
    chunk_offsets,
    chunk_record,
    cpu_bomb,
    flip_offsets,
    flipped,
    good_chunk,
    mcap_file,
    with_chunk_inserted,
    zstd_rle,
)
from tests.test_cli_runtime import REPO, dummy, frames, tafel


@pytest.fixture(scope="module")
def recorded(tmp_path_factory) -> Path:
    path = tmp_path_factory.mktemp("logs") / "run.mcap"
    result = dummy("--frames", "600", "--speed", "max", "--record", str(path))
    assert result.returncode == 0, result.stderr
    assert "recorded" in result.stdout and "; 0 dropped" in result.stdout
    return path


def test_recording_has_one_channel_per_context_and_representation(recorded: Path) -> None:
    contents = read_log(recorded)
    assert contents.complete and not contents.problem
    assert set(contents.channels) >= {
        "cognition/FrameInfo", "cognition/BallPercept", "cognition/BallModel", "cognition/HeadMotionRequest",
        "motion/FrameInfo", "motion/JointSensorData", "motion/InertialSensorData", "motion/FsrData", "motion/JointCommand",
    }
    assert contents.channels["cognition/BallModel"].metadata == {"source": "module", "provider": "KalmanBallModeler"}
    assert contents.channels["motion/JointSensorData"].metadata == {"source": "platform"}
    assert contents.channels["motion/FrameInfo"].messages == 600
    assert contents.channels["cognition/FrameInfo"].messages == 180
    assert contents.metadata["motion_hz"] == "100.0"


PLAIN_READER = textwrap.dedent('''
    """Decodes a Tafel log with nothing but mcap and protobuf."""
    import json, sys
    from google.protobuf import descriptor_pb2, descriptor_pool, message_factory
    from mcap.reader import make_reader

    decoded, checks = {}, []
    with open(sys.argv[1], "rb") as handle:
        reader = make_reader(handle)
        classes = {}
        for schema, channel, message in reader.iter_messages():
            if channel.message_encoding == "json":  # Foxglove's series: JSON by name
                json.loads(message.data)
                decoded[channel.topic] = decoded.get(channel.topic, 0) + 1
                continue
            if schema.id not in classes:
                pool = descriptor_pool.DescriptorPool()
                for file in descriptor_pb2.FileDescriptorSet.FromString(schema.data).file:
                    pool.Add(file)
                classes[schema.id] = message_factory.GetMessageClass(pool.FindMessageTypeByName(schema.name))
            value = classes[schema.id].FromString(message.data)
            decoded[channel.topic] = decoded.get(channel.topic, 0) + 1
            if schema.name == "tafel.FrameInfo":
                checks.append((value.time_ns == message.publish_time, value.frame_number == message.sequence,
                               message.log_time > 1_600_000_000 * 10**9))
    project = [name for name in sys.modules if name.split(".")[0] in ("core", "representations", "modules", "platforms", "tools")]
    print(json.dumps({"decoded": decoded, "checks_ok": all(all(c) for c in checks), "project_modules": project}))
''')


def test_a_plain_mcap_and_protobuf_reader_decodes_everything(recorded: Path, tmp_path: Path) -> None:
    script = tmp_path / "plain_reader.py"
    script.write_text(PLAIN_READER)
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    result = subprocess.run([sys.executable, str(script), str(recorded)], capture_output=True, text=True, cwd=tmp_path, env=env, timeout=60)
    assert result.returncode == 0, result.stderr
    report = json.loads(result.stdout)
    assert report["project_modules"] == []
    assert report["checks_ok"]  # publish time = frame time, log time = wall clock, sequence = frame number
    assert report["decoded"]["motion/JointCommand"] == 600 and report["decoded"]["cognition/BallModel"] == 180
    assert report["decoded"]["/joints"] == 600 and report["decoded"]["/scene"] > 0  # Foxglove's channels decode too


@pytest.mark.slow
def test_log_info_summarises_the_recording(recorded: Path) -> None:
    result = tafel("log", "info", str(recorded))
    assert result.returncode == 0, result.stderr
    assert "(complete)" in result.stdout
    assert "frames: cognition 180, motion 600" in result.stdout
    assert re.search(r"motion/JointCommand\s+600 messages", result.stdout)
    info = json.loads(tafel("log", "info", str(recorded), "--json").stdout)
    assert info["channels"]["cognition/BallModel"]["messages"] == 180 and info["duration_s"] == pytest.approx(5.99)


@pytest.mark.slow
def test_replay_reproduces_every_cognition_output_frame_by_frame(recorded: Path, tmp_path: Path) -> None:
    replayed = tmp_path / "replayed.mcap"
    result = tafel("run", "--platform", "log", "--no-debug", "--log", str(recorded), "--speed", "max", "--record", str(replayed))
    assert result.returncode == 0, result.stderr
    assert frames(result.stdout) == {"cognition": 180, "motion": 600}
    original, again = read_log(recorded), read_log(replayed)
    for topic in ("cognition/BallModel", "cognition/HeadMotionRequest", "motion/JointCommand"):
        first = [(m.sequence, m.time_ns, m.data) for m in original.messages if m.topic == topic]
        second = [(m.sequence, m.time_ns, m.data) for m in again.messages if m.topic == topic]
        assert first == second, topic


@pytest.mark.slow
def test_replace_feeds_a_recorded_representation_instead_of_its_module(recorded: Path, tmp_path: Path) -> None:
    modules = tafel("modules", "--platform", "log", "--log", str(recorded), "--replace", "BallModel")
    assert "replaced: KalmanBallModeler (the platform provides BallModel)" in modules.stdout
    replayed = tmp_path / "replaced.mcap"
    result = tafel("run", "--platform", "log", "--no-debug", "--log", str(recorded), "--replace", "BallModel", "--speed", "max",
                   "--record", str(replayed), "--record-reps", "HeadMotionRequest")
    assert result.returncode == 0, result.stderr
    original = [m.data for m in read_log(recorded).messages if m.topic == "cognition/HeadMotionRequest"]
    again = [m.data for m in read_log(replayed).messages if m.topic == "cognition/HeadMotionRequest"]
    assert original == again


@pytest.mark.slow
def test_log_platform_argument_errors(recorded: Path, tmp_path: Path) -> None:
    missing = tafel("run", "--platform", "log")
    assert missing.returncode == 2 and "needs a recording: tafel run --platform log --log FILE.mcap" in missing.stderr
    wrong = tafel("run", "--platform", "log", "--log", str(recorded), "--replace", "BallModle")
    assert wrong.returncode == 2 and "did you mean 'BallModel'" in wrong.stderr
    absent = tafel("run", "--platform", "log", "--log", str(tmp_path / "nope.mcap"))
    assert absent.returncode == 1 and "nope.mcap" in absent.stderr and "Traceback" not in absent.stderr


@pytest.mark.slow
def test_foreign_and_missing_files_get_clear_errors(tmp_path: Path) -> None:
    foreign = tmp_path / "foreign.mcap"
    foreign.write_bytes(os.urandom(1000))
    result = tafel("log", "info", str(foreign))
    assert result.returncode == 1 and f"{foreign} is not an MCAP log" in result.stderr
    assert "Traceback" not in result.stderr
    result = tafel("log", "info", str(tmp_path / "absent.mcap"))
    assert result.returncode == 1 and "absent.mcap" in result.stderr and "Traceback" not in result.stderr


@pytest.mark.parametrize("keep", [0.3, 0.6, 0.9])
def test_truncated_files_yield_what_was_complete_and_name_the_position(recorded: Path, tmp_path: Path, keep: float) -> None:
    data = recorded.read_bytes()
    cut = tmp_path / "cut.mcap"
    cut.write_bytes(data[: int(len(data) * keep)])
    result = tafel("log", "info", str(cut))
    assert result.returncode == 0, result.stderr
    assert "recovered what was complete" in result.stdout
    assert re.search(r"(stopped reading at byte \d+|ends at byte \d+|(record|chunk) at byte \d+ runs past the end)", result.stdout)
    assert "Traceback" not in result.stderr + result.stdout


@pytest.mark.slow
def test_sigkill_while_recording_loses_at_most_the_last_second(tmp_path: Path) -> None:
    path = tmp_path / "killed.mcap"
    process = subprocess.Popen([sys.executable, "-m", "tafel.tools.cli", "run", "--platform", "dummy", "--no-debug", "--record", str(path), "--status-interval", "0.5"],
                               cwd=REPO, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                               env={**os.environ, "PYTHONPATH": str(REPO)})
    last_status_time = 0.0
    try:
        deadline = time.monotonic() + 60
        while time.monotonic() < deadline:
            line = process.stderr.readline()
            match = re.search(r"t=([\d.]+)s", line)
            if match:
                last_status_time = float(match.group(1))
                if last_status_time >= 3.0:
                    break
        process.send_signal(signal.SIGKILL)
        process.wait(timeout=10)
    finally:
        process.kill()
    assert last_status_time >= 3.0
    contents = read_log(path)
    assert not contents.complete
    motion_frames = len(contents.frames("motion"))
    assert motion_frames >= (last_status_time - 1.0) * 100, (motion_frames, last_status_time)
    result = tafel("log", "info", str(path))
    assert result.returncode == 0 and "recovered what was complete" in result.stdout


@pytest.mark.slow
def test_export_csv_and_jsonl(recorded: Path, tmp_path: Path) -> None:
    out = tmp_path / "ball.csv"
    result = tafel("log", "export", str(recorded), "--rep", "BallModel", "--format", "csv", "--out", str(out))
    assert result.returncode == 0, result.stderr
    rows = list(csv.DictReader(out.open()))
    assert len(rows) == 180 and rows[0]["context"] == "cognition" and rows[0]["frame"] == "1"
    assert {"x", "y", "valid", "time_ns"} <= set(rows[0])
    out = tmp_path / "joints.jsonl"
    result = tafel("log", "export", str(recorded), "--rep", "JointSensorData", "--format", "jsonl", "--out", str(out))
    assert result.returncode == 0, result.stderr
    lines = [json.loads(line) for line in out.read_text().splitlines()]
    assert len(lines) == 600 and len(lines[10]["position"]) == 25
    assert "exporting JointSensorData [" not in result.stderr  # no progress bar into a pipe
    wrong = tafel("log", "export", str(recorded), "--rep", "BallModle", "--format", "csv", "--out", str(out))
    assert wrong.returncode == 1 and "did you mean 'BallModel'" in wrong.stderr


@representation
class LogTestImage:
    image: np.ndarray = array((6, 8, 3), np.uint8)


def test_export_png_writes_images(tmp_path: Path) -> None:
    import cv2

    path = tmp_path / "images.mcap"
    writer = LogWriter(path)
    images = []
    for frame in range(1, 4):
        rep = LogTestImage()
        rep.image[:, :, 0] = frame * 40  # red channel (images are RGB)
        images.append(rep.image.copy())
        writer.write("cognition/LogTestImage", LogTestImage, frame * 33_000_000, frame, serialize(rep), {"source": "platform"})
    writer.close()
    out = tmp_path / "png"
    result = tafel("log", "export", str(path), "--rep", "LogTestImage", "--format", "png", "--out", str(out))
    assert result.returncode == 0, result.stderr
    written = sorted(out.glob("*.png"))
    assert [p.name for p in written] == [f"cognition_LogTestImage_image_{i:06d}.png" for i in (1, 2, 3)]
    assert np.array_equal(cv2.cvtColor(cv2.imread(str(written[1])), cv2.COLOR_BGR2RGB), images[1])


def test_stepping_the_replay(recorded: Path) -> None:
    platform = LogPlatform({"log": str(recorded)})
    first = platform.next_step()
    assert first is not None and first[1] == frozenset({"motion", "cognition"})
    platform.pause()
    assert platform.next_step() is None
    platform.step(2)
    second, third = platform.next_step(), platform.next_step()
    assert second is not None and third is not None and platform.next_step() is None
    platform.step(-1)
    again = platform.next_step()
    assert again == second and platform.next_step() is None  # back to the frame before the current one
    platform.goto(100)  # replays up to frame 100 (from cognition's latest frame before it), then pauses
    replayed = list(iter(platform.next_step, None))
    assert 1 <= len(replayed) <= 4 and platform.status()["frames"]["motion"] == 100
    assert {c for _, contexts in replayed for c in contexts} == {"motion", "cognition"}
    assert platform.paused and platform.next_step() is None
    assert platform.timeline()["frame"] == 100 and platform.timeline()["frame_range"] == [1, 600]
    with pytest.raises(PlatformError, match="no motion frame 5000; its motion frames are 1..600"):
        platform.goto(5000)
    with pytest.raises(ValueError, match=r"^context takes cognition or motion, got 'Motion'$"):
        platform.goto(100, "Motion")  # looked for frames of no context before
    with pytest.raises(PlatformOptionError):
        LogPlatform({})


@pytest.mark.slow
def test_concurrent_runs_record_into_one_file(tmp_path: Path) -> None:
    path = tmp_path / "concurrent.mcap"
    result = dummy("--concurrent", "--frames", "150", "--record", str(path))
    assert result.returncode == 0, result.stderr
    contents = read_log(path)
    assert contents.complete
    assert len(contents.frames("motion")) == 150 and len(contents.frames("cognition")) >= 30


@pytest.mark.slow
def test_good_magic_and_garbage_after_is_an_error_naming_file_and_byte(tmp_path: Path) -> None:
    garbage = tmp_path / "garbage.mcap"
    garbage.write_bytes(b"\x89MCAP0\r\n" + bytes(range(200, 256)) * 40)
    for command in (("log", "info", str(garbage)), ("log", "export", str(garbage), "--rep", "BallModel", "--format", "csv",
                                                     "--out", str(tmp_path / "x.csv"))):
        result = tafel(*command)
        assert result.returncode == 1, result.stdout
        assert "garbage.mcap" in result.stderr and re.search(r"at byte \d+", result.stderr), result.stderr
        assert "Traceback" not in result.stderr
    replay = tafel("run", "--platform", "log", "--log", str(garbage), "--no-debug")
    assert replay.returncode != 0 and "garbage.mcap" in replay.stderr and "Traceback" not in replay.stderr


@pytest.mark.slow
def test_a_damaged_chunk_in_the_middle_is_skipped_and_the_rest_is_read(recorded: Path, tmp_path: Path) -> None:
    from tafel.core.logs import LogReader

    with LogReader(recorded) as reader:
        chunks = list(reader.chunks)
        total = sum(1 for _ in reader.messages())
    assert len(chunks) >= 4, "the recording should have several chunks (at most 1 s of log time each)"
    victim = chunks[len(chunks) // 2]
    data = bytearray(recorded.read_bytes())
    data[victim.offset + 60] ^= 0x10  # one flipped bit inside the compressed records
    damaged = tmp_path / "damaged.mcap"
    damaged.write_bytes(bytes(data))
    with LogReader(damaged) as reader:
        survived = sum(1 for _ in reader.messages())
        assert reader.problems and f"chunk at byte {victim.offset} is damaged" in reader.problems[0]
    assert total * 0.6 < survived < total
    info = tafel("log", "info", str(damaged))
    assert info.returncode == 0 and "damaged" in info.stdout
    replay = tafel("run", "--platform", "log", "--log", str(damaged), "--no-debug", "--speed", "max")
    assert replay.returncode == 0, replay.stderr


def test_chunks_hold_at_most_one_second_of_log_time_at_any_speed(recorded: Path) -> None:
    from tafel.core.logs import CHUNK_SPAN_NS, LogReader

    with LogReader(recorded) as reader:  # recorded at --speed max: 6 s of log time in well under a second
        spans = [c.end_ns - c.start_ns for c in reader.chunks]
    assert len(spans) >= 6 and max(spans) < CHUNK_SPAN_NS


def test_the_progress_bar_draws_only_on_a_terminal() -> None:
    import io

    from tafel.tools.logs.log_tools import Progress

    class Terminal(io.StringIO):
        def isatty(self) -> bool:
            return True

    for stream, drawn in ((Terminal(), True), (io.StringIO(), False)):
        progress = Progress("exporting X", 400, stream)
        for done in range(1, 401):
            progress.update(done)
        progress.close()
        assert ("exporting X [####################] 100% (400/400)" in stream.getvalue()) is drawn


def test_exporting_images_from_a_representation_without_images_is_an_error(recorded: Path, tmp_path: Path) -> None:
    result = tafel("log", "export", str(recorded), "--rep", "BallModel", "--format", "png", "--out", str(tmp_path / "png"))
    assert result.returncode == 1
    assert "BallModel holds no image" in result.stderr and "--format csv" in result.stderr


@pytest.mark.slow
def test_the_summary_goes_to_one_stream_and_ran_is_the_length() -> None:
    result = dummy("--frames", "250", "--speed", "max")
    assert result.returncode == 0
    assert "platform dummy (lockstep): ran 2.500 s of platform time" in result.stdout
    assert "wall time" in result.stdout and "fingerprint" in result.stdout and result.stderr == ""


# ------------------------------------------------------------------------------ logs that fight back
def _memory_limited(limit: int) -> Callable[[], None]:
    """For a child process: at most ``limit`` bytes of address space, so a bomb fails it instead of the machine."""
    def apply() -> None:
        resource.setrlimit(resource.RLIMIT_AS, (limit, limit))
    return apply


@pytest.mark.slow
def test_a_chunk_claiming_gigabytes_is_refused_unread_by_every_log_command(recorded: Path, tmp_path: Path) -> None:
    claimed = 2 << 30  # 2 GiB of zeros in 64 kB of zstd, put between the recording's chunks
    bomb = tmp_path / "bomb.mcap"
    bomb.write_bytes(with_chunk_inserted(recorded.read_bytes(), chunk_record(compressed=zstd_rle(claimed), claimed=claimed), 2))
    assert bomb.stat().st_size - recorded.stat().st_size < 70_000
    commands = {
        "info": ("log", "info", str(bomb)),
        "export": ("log", "export", str(bomb), "--rep", "BallModel", "--format", "csv", "--out", str(tmp_path / "x.csv")),
        "convert": ("log", "convert", str(bomb), "--out", str(tmp_path / "converted.mcap")),
        "compare": ("log", "compare", str(recorded), str(bomb)),
        "slice": ("log", "slice", str(bomb), "--out", str(tmp_path / "slice.mcap"), "--seconds", "2"),
        "replay": ("run", "--platform", "log", "--log", str(bomb), "--no-debug", "--speed", "max"),
        "replay-batch": ("replay-batch", str(bomb), "--workers", "1", "--out", str(tmp_path / "batch.csv"),
                         "--artifacts", str(tmp_path / "artifacts")),
    }
    env = {**os.environ, "PYTHONPATH": str(REPO)}
    for name, command in commands.items():
        result = subprocess.run([sys.executable, "-m", "tafel.tools.cli", *command], capture_output=True, text=True, cwd=REPO,
                                env=env, timeout=120, preexec_fn=_memory_limited(1536 << 20))
        output = result.stdout + result.stderr
        assert "Traceback" not in output and "MemoryError" not in output, f"{name}: {output[-2000:]}"
        assert result.returncode == 0, f"{name}: {output[-2000:]}"
        at = chunk_offsets(recorded.read_bytes())[2]
        assert f"chunk at byte {at} is damaged (it claims {claimed} bytes uncompressed, more than" in output, f"{name}: {output[-2000:]}"
    # every other chunk is read: the bomb costs nothing but itself
    assert json.loads(tafel("log", "info", str(bomb), "--json").stdout)["frames"] == {"cognition": 180, "motion": 600}


def test_a_chunk_of_zero_bytes_is_refused_at_its_first_record_and_the_next_chunk_is_read(tmp_path: Path) -> None:
    """8 MiB of zeros are 900,000 empty records of opcode 0, which the mcap library walks one by one (the CPU bomb)."""
    from tafel.core.logs import LogReader

    path = cpu_bomb(tmp_path / "cpu.mcap", claimed=8 << 20)
    with LogReader(path) as reader:
        assert sum(1 for _ in reader.messages()) == 20  # the good chunks before and after
        assert len(reader.problems) == 1, reader.problems
        assert "the chunk at byte 275 is damaged: a record of opcode 0x00" in reader.problems[0]


def test_a_chunk_that_claims_more_than_its_compression_can_hold_is_refused(tmp_path: Path) -> None:
    from tafel.core.logs import LogReader

    claimed = 4 << 20
    honest = zstd_rle(claimed)
    liar = chunk_record(compressed=honest[:40], claimed=claimed)  # 40 bytes of zstd cannot hold 4 MiB
    path = mcap_file(tmp_path / "ratio.mcap", [good_chunk(0, 5), liar, good_chunk(5, 5)])
    with LogReader(path) as reader:
        assert sum(1 for _ in reader.messages()) == 10
        assert f"chunk at byte {path.read_bytes().index(liar)} is damaged (it claims {claimed} bytes uncompressed from 40 bytes " \
               "of zstd data, which no compression gives" in reader.problems[0]


def _chunk_extents(path: Path) -> list[tuple[int, int, int]]:
    """(first byte, end, messages) of every chunk record of an intact recording."""
    from tafel.core.logs import LogReader

    data = path.read_bytes()
    with LogReader(path) as reader:
        extents = []
        for number, chunk in enumerate(reader.chunks):
            length = int.from_bytes(data[chunk.offset + 1:chunk.offset + 9], "little")
            extents.append((chunk.offset, chunk.offset + 9 + length, len(reader.read_chunk(number) or [])))
    return extents


def _survivors(data: bytes, tmp_path: Path) -> tuple[int, list[str]]:
    from tafel.core.logs import LogReader

    damaged = tmp_path / "flipped.mcap"
    damaged.write_bytes(data)
    with LogReader(damaged) as reader:
        return sum(1 for _ in reader.messages()), list(reader.problems)


def test_one_flipped_bit_in_the_first_chunk_loses_only_that_chunk(recorded: Path, tmp_path: Path) -> None:
    extents = _chunk_extents(recorded)
    total = sum(n for _, _, n in extents)
    first, _end, hit = extents[0]
    survived, problems = _survivors(flipped(recorded.read_bytes(), first + 200, 3), tmp_path)
    assert survived == total - hit  # the channels are in the summary, not only in the first chunk
    assert any(f"chunk at byte {first} is damaged" in p for p in problems), problems


def test_one_flipped_bit_in_a_chunk_length_loses_only_that_chunk(recorded: Path, tmp_path: Path) -> None:
    extents = _chunk_extents(recorded)
    total = sum(n for _, _, n in extents)
    start, _end, hit = extents[len(extents) // 2]
    data = recorded.read_bytes()
    for bit in (5, 30, 60):  # shorter, longer, past the end of the file: the summary's index still finds the rest
        survived, problems = _survivors(flipped(data, start + 1 + bit // 8, bit % 8), tmp_path)
        assert survived == total - hit, (bit, problems)
        assert any(f"chunk at byte {start} is damaged" in p for p in problems), problems
    # without the summary (a cut-off recording), the walk finds the next chunk by its signature
    cut = data[:extents[-1][1]]
    intact, _ = _survivors(cut, tmp_path)
    survived, problems = _survivors(flipped(cut, start + 1 + 30 // 8, 30 % 8), tmp_path)
    assert survived == intact - hit, problems
    assert any(f"chunk at byte {start} is damaged" in p and "reading on with the chunk at byte" in p for p in problems), problems


@pytest.mark.parametrize("seed", [1, 2])
def test_a_bit_flipped_anywhere_loses_at_most_the_chunk_it_hits(recorded: Path, tmp_path: Path, seed: int) -> None:
    extents = _chunk_extents(recorded)
    total = sum(n for _, _, n in extents)
    data = recorded.read_bytes()
    for offset, bit in flip_offsets(len(data), 12, seed):
        hit = next(((start, n) for start, end, n in extents if start <= offset < end), None)
        survived, problems = _survivors(flipped(data, offset, bit), tmp_path)
        assert survived >= total - (hit[1] if hit else 0), (offset, bit, problems)
        if survived < total:
            assert hit is not None and any(f"byte {hit[0]}" in p for p in problems), (offset, bit, problems)


def test_a_flipped_bit_in_the_magic_or_the_summary_loses_nothing(recorded: Path, tmp_path: Path) -> None:
    data = recorded.read_bytes()
    total = sum(n for _, _, n in _chunk_extents(recorded))
    summary_start = int.from_bytes(data[-8 - 20:-8 - 12], "little")
    for offset, what in ((2, "magic"), (summary_start + 40, "summary")):
        survived, problems = _survivors(flipped(data, offset, 1), tmp_path)
        assert survived == total, (what, problems)
        assert problems and what in problems[0], problems


def test_log_slice_says_it_found_no_message_in_words(tmp_path: Path) -> None:
    empty = tmp_path / "empty.mcap"
    LogWriter(empty).close()  # a recording stopped before its first frame
    result = tafel("log", "slice", str(empty), "--out", str(tmp_path / "piece.mcap"))
    assert result.returncode == 1
    assert f"{empty} holds no messages of any channel" in result.stderr, result.stderr


def test_log_info_on_an_empty_file_says_it_is_empty(tmp_path: Path) -> None:
    empty = tmp_path / "x.mcap"
    empty.touch()
    result = tafel("log", "info", str(empty))
    assert result.returncode == 1 and f"{empty} is empty (0 bytes)" in result.stderr, result.stderr
    assert "not an MCAP log" not in result.stderr


@pytest.mark.slow
def test_a_start_that_fails_leaves_no_recording_behind(tmp_path: Path) -> None:
    with socket.socket() as taken:
        taken.bind(("127.0.0.1", 0))
        taken.listen()
        port = taken.getsockname()[1]
        result = tafel("run", "--platform", "dummy", "--frames", "50", "--record", str(tmp_path / "x.mcap"), "--debug-port", str(port))
    assert result.returncode != 0 and f"127.0.0.1:{port} is taken" in result.stderr, result.stderr
    assert not (tmp_path / "x.mcap").exists()
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("clock_source", ["runtime", "platform"])  # "platform": logs from before the runtime wrote it
def test_replay_keeps_the_recorded_frame_clock(tmp_path: Path, clock_source: str) -> None:
    from tafel.core.runtime import Limits, LockstepRuntime
    from tafel.core.runtime.program import plan_program
    from tafel.representations import FrameInfo, JointSensorData
    from tests.test_program import CLOCKS_SEEN

    path = tmp_path / "clock.mcap"
    writer = LogWriter(path)
    for frame in range(1, 6):  # numbered 101..105 by FrameInfo (a replay of a slice), 1..5 by the messages
        time_ns = 7_000_000_000 + frame * 10_000_000
        writer.write("motion/FrameInfo", FrameInfo, time_ns, frame, serialize(FrameInfo(frame_number=100 + frame, time_ns=time_ns)),
                     {"source": clock_source})
        writer.write("motion/JointSensorData", JointSensorData, time_ns, frame, serialize(JointSensorData()), {"source": "platform"})
    writer.close()
    platform = LogPlatform({"log": str(path)})
    assert platform.provides == {"motion": (JointSensorData,)}  # the runtime writes the clock, from what the log says
    plans = plan_program({"cognition": {"modules": []}, "motion": {"modules": ["tests.test_program:TpMotionClock"]}}, platform)
    CLOCKS_SEEN.clear()
    LockstepRuntime(plans, platform).run(Limits(speed=None))
    assert CLOCKS_SEEN == [("motion", 100 + k, 7_000_000_000 + k * 10_000_000) for k in range(1, 6)]


@pytest.mark.parametrize(("action", "options", "message"), [
    ("slice", {"start": -1.0, "seconds": None}, "--start takes a finite number of seconds of at least 0, got -1"),
    ("slice", {"start": 0.0, "seconds": 0.0}, "--seconds takes a finite number of seconds above 0, got 0"),
    ("slice", {"start": float("inf"), "seconds": None}, "--start takes a finite number of seconds of at least 0, got inf"),
    ("convert", {"jpeg_quality": 101}, "--jpeg-quality takes a whole number from 1 to 100, got 101"),
])
def test_log_slice_and_convert_refuse_bad_numbers_in_the_one_wording(action: str, options: dict, message: str, capsys) -> None:
    import argparse

    from tafel.tools.logs.log_tools import run_slice

    args = argparse.Namespace(log_command=action, file=Path("in.mcap"), out=Path("out.mcap"), rep=None, **options)
    assert run_slice(args) == 2
    assert capsys.readouterr().err == f"tafel log {action}: error: {message}\n"


def test_log_export_takes_a_context_as_written(capsys) -> None:
    from tafel.tools.cli.dispatch import build_parser

    parser = build_parser()
    args = parser.parse_args(["log", "export", "x.mcap", "--rep", "FrameInfo", "--format", "csv", "--out", "x.csv", "--context", "motion"])
    assert args.context == "motion"
    with pytest.raises(SystemExit) as exited:
        parser.parse_args(["log", "export", "x.mcap", "--rep", "FrameInfo", "--format", "csv", "--out", "x.csv", "--context", "Motion"])
    assert exited.value.code == 2
    assert "argument --context: takes cognition or motion, got 'Motion'" in capsys.readouterr().err
