"""The black-box recorder: the last seconds of everything in bounded memory, saved on a trigger to a log
that replays like any other, while the program goes on."""

from __future__ import annotations

import re
import time
from pathlib import Path

import pytest

from tafel.core.framework.config import ConfigError
from tafel.core.logs import read_log
from tafel.core.logs.blackbox import BlackBox, Condition, conditions_from_config
from tafel.core.logs.serialization import serialize
from tafel.representations.game import GameState, Penalty
from tafel.representations.infrastructure import FrameInfo
from tafel.representations.motion import ChestButton
from tafel.representations.motion_control import FallPhase, FallState
from tests.test_cli_runtime import tafel
from tests.test_debug_server import Program
from tests.test_rules import game

S = 1_000_000_000


def feed(box: BlackBox, seconds: float, hz: float = 100.0, topic: str = "motion/FrameInfo") -> None:
    for frame in range(int(seconds * hz)):
        box.write(topic, FrameInfo, int(frame / hz * S), frame, serialize(FrameInfo(frame_number=frame, time_ns=int(frame / hz * S))))


def saved(box: BlackBox, timeout: float = 10.0) -> Path:
    deadline = time.monotonic() + timeout
    while not box.saves and time.monotonic() < deadline:
        time.sleep(0.02)
    assert box.saves, "nothing saved"
    return Path(box.saves[-1][1])


def test_the_ring_keeps_the_last_seconds_and_saves_them_with_the_trigger(tmp_path: Path) -> None:
    box = BlackBox(tmp_path, seconds=2.0)
    feed(box, 5.0)
    assert 199 <= len(box.ring) <= 201  # 2 s at 100 Hz
    assert box.save("test trigger", 4 * S) is not None
    log = read_log(saved(box))
    frames = sorted(m.sequence for m in log.messages)
    assert frames[0] >= 299 and frames[-1] == 499
    assert log.metadata["blackbox_trigger"] == "test trigger" and log.metadata["blackbox_time_s"] == "4.000"


def test_memory_is_bounded_and_heavy_messages_are_thinned(tmp_path: Path) -> None:
    box = BlackBox(tmp_path, seconds=60.0, max_bytes=50_000, heavy_period_s=0.5)
    feed(box, 10.0)
    assert box.bytes <= 50_000
    image = BlackBox(tmp_path, seconds=10.0, heavy_period_s=0.5)
    big = b"x" * 100_000
    for frame in range(60):  # 2 s of a 30 Hz camera
        image.write("cognition/CameraImageTop", FrameInfo, int(frame / 30 * S), frame, big)
    assert len(image.ring) == 4  # one each 0.5 s


def test_triggers_in_the_stream(tmp_path: Path) -> None:
    fired: list[str] = []
    box = BlackBox(tmp_path, conditions=[Condition("FrameInfo", "frame_number", at_least=50, for_s=0.2, context="motion")])
    box.save = lambda trigger, time_ns=None: fired.append(trigger)  # type: ignore[method-assign]
    box.triggers.fire = box.save
    for phase, at in ((FallPhase.upright, 1), (FallPhase.falling, 2), (FallPhase.lying_front, 3)):
        box.write("motion/FallState", FallState, at * S, at, serialize(FallState(phase=phase)))
    for presses, at in ((1, 10), (2, 10.5), (3, 11), (4, 11.2)):
        box.write("motion/ChestButton", ChestButton, int(at * S), 0, serialize(ChestButton(presses=presses)))
    feed(box, 1.0)
    assert fired == ["fall (falling)", "chest button pressed three times", "FrameInfo.frame_number >= 50 for 0.2 s"]


def test_a_penalty_triggers_once(tmp_path: Path) -> None:
    fired: list[str] = []
    box = BlackBox(tmp_path)
    box.triggers.fire = lambda trigger, time_ns: fired.append(trigger)
    state = game(penalty=Penalty.player_pushing)
    assert state.penalized
    for at in range(3):
        box.write("cognition/GameState", GameState, at * S, at, serialize(state))
    assert fired == ["GameController penalty"]


def test_saves_within_the_cooldown_are_counted_not_written(tmp_path: Path) -> None:
    box = BlackBox(tmp_path, cooldown_s=60.0)
    feed(box, 0.5)
    assert box.save("first") is not None
    assert box.save("second") is None and box.suppressed == 1
    saved(box)
    assert "1 triggers within a cooldown" in box.status()


TRIGGER = "[[blackbox.triggers]] number 1: "


@pytest.mark.parametrize(("table", "message"), [
    (5, "blackbox.triggers takes tables: [[blackbox.triggers]] with name, field and equals, at_least or at_most, got 5"),
    ([{"name": "BallModel"}], TRIGGER + "field takes a field's name (dotted for nested ones), got None"),
    ([{"field": "valid"}], TRIGGER + "name takes a representation's name, got None"),
    ([{"name": "BallModel", "field": "valid"}], TRIGGER + "give equals, at_least or at_most"),
    ([{"name": "BallModel", "field": "valid", "equals": False, "for_s": 1e308}],
     TRIGGER + "for_s takes a finite number of seconds of at least 0, got 1e+308"),
    ([{"name": "BallModel", "field": "valid", "equals": False, "for_s": -1}],
     TRIGGER + "for_s takes a finite number of seconds of at least 0, got -1"),
    ([{"name": "BallModel", "field": "x", "at_least": "3"}],  # a string was compared with a number, never held
     TRIGGER + "at_least takes a finite number of at most 1e+12 in size, got '3'"),
    ([{"name": "BallModel", "field": "valid", "equals": False, "when": 1}], TRIGGER + "unknown keys when"),
    ([{"name": "BallModel", "field": "valid", "equals": False, "context": "Cognition"}],  # matched no topic, never fired
     TRIGGER + "context takes cognition or motion, got 'Cognition'"),
])
def test_bad_trigger_tables_are_clear_errors(table: object, message: str) -> None:
    with pytest.raises(ConfigError, match="^" + re.escape(message)):
        conditions_from_config(table)


def test_a_trigger_of_one_context_keeps_its_context() -> None:
    [condition] = conditions_from_config([{"name": "FrameInfo", "field": "frame_number", "at_least": 10, "context": "motion"}])
    assert condition.context == "motion" and condition.at_least == 10.0


@pytest.mark.parametrize(("table", "message"), [
    ({"seconds": 0}, "blackbox.seconds takes a finite number of seconds above 0 and at most 1e+06, got 0"),
    ({"max_mb": True}, "blackbox.max_mb takes a finite number of MB above 0 and at most 1e+06, got True"),
    ({"image_period_s": "0.5"}, "blackbox.image_period_s takes a finite number of seconds above 0 and at most 1e+06, got '0.5'"),
    ({"enabled": "no"}, "blackbox.enabled takes on/off or true/false, got 'no'"),  # a non-empty string was "on"
])
def test_bad_blackbox_settings_say_what_would_be_right(table: dict, message: str) -> None:
    from tafel.tools.launch.errors import UsageError
    from tafel.tools.launch.recording import make_blackbox

    with pytest.raises(UsageError) as error:
        make_blackbox(None, {}, {"blackbox": table}, None)  # type: ignore[arg-type]
    assert str(error.value) == message
    assert make_blackbox(None, {}, {"blackbox": {"enabled": False}}, None) is None  # type: ignore[arg-type]


@pytest.mark.slow
def test_a_configured_trigger_saves_a_log_that_replays(tmp_path: Path) -> None:
    logs = tmp_path / "logs"
    run = tafel("run", "--platform", "dummy", "--frames", "1500", "--speed", "max", "--no-debug", "--record-dir", str(logs),
                "--set", "blackbox.enabled=true", "--set", "blackbox.seconds=5",
                "--set", 'blackbox.triggers=[{name="FrameInfo", field="frame_number", at_least=1000, context="motion"}]')
    assert run.returncode == 0, run.stderr
    assert "black box saved (FrameInfo.frame_number >= 1000)" in run.stderr
    (path,) = logs.glob("blackbox-*.mcap")
    info = tafel("log", "info", str(path))
    assert "blackbox_trigger=FrameInfo.frame_number >= 1000" in info.stdout, info.stdout
    assert re.search(r"frames: cognition 1[45]\d, motion (49\d|50\d)", info.stdout), info.stdout  # 5 s
    replay = tafel("run", "--platform", "log", "--log", str(path), "--speed", "max", "--no-debug")
    assert replay.returncode == 0, replay.stderr
    assert re.search(r"motion: (49\d|50\d) frames", replay.stdout), replay.stdout


@pytest.mark.slow
def test_blackbox_save_in_the_concurrent_runtime_holds_both_contexts(tmp_path: Path) -> None:
    logs = tmp_path / "logs"
    program = Program("--concurrent", "--record-dir", str(logs), "--set", "blackbox.enabled=true", "--set", "blackbox.seconds=3")
    try:
        time.sleep(4.0)
        answer = program.ask("blackbox:save")
        # on a loaded machine the start may have missed frames, which saved already: then within the cooldown
        assert re.search(r"saving the last 3 s to .*blackbox-.*blackbox-save\.mcap|not saved: a save happened less than 10 s ago",
                         answer), answer
        # a save is listed once its writer has finished the file (the file is there from its start): wait for that
        saved = r"saves: (blackbox:save|motion missed frames|cognition frames without cognition|motion frames without cognition)"
        deadline = time.monotonic() + 30
        while not re.search(saved, status := program.ask("blackbox:status")) and time.monotonic() < deadline:
            time.sleep(0.2)
        assert re.search(saved, status), status
    finally:
        program.stop()
    path = max(logs.glob("blackbox-*.mcap"))
    contexts = {m.topic.split("/")[0] for m in read_log(path).messages}
    assert contexts == {"cognition", "motion"}


def test_the_concurrent_runtimes_black_box_drain_ends_quietly_when_its_queue_fails() -> None:
    """At a run's end the queue may be torn down under the drain thread (CI saw a thread traceback on stderr after
    a stop for malformed LoLA packets): any failure to read ends the drain, after what it drained is written."""
    from tafel.core.runtime.concurrent import ConcurrentRuntime

    written: list[tuple] = []

    class Sink:
        def write(self, *item: object) -> None:
            written.append(item)

    class Source:
        def __init__(self, failure: Exception) -> None:
            self.items: list = [("motion", 1), ("motion", 2)]
            self.failure = failure

        def get(self) -> object:
            if self.items:
                return self.items.pop(0)
            raise self.failure

    for failure in (EOFError(), OSError("handle is closed"), ValueError("closed"), TypeError("'NoneType' object cannot be interpreted as an integer")):
        written.clear()
        ConcurrentRuntime._drain_into(Source(failure), Sink())  # returns, raises nothing
        assert written == [("motion", 1), ("motion", 2)]
