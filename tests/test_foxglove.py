"""Foxglove's channels in recordings: read back with the ``mcap`` reader and the protobuf schemas that
``foxglove-sdk`` ships (none of Tafel's reading code), from a recording a user makes over the debug
server while the default simulation runs."""

from __future__ import annotations

import json
import logging
import math
import re
import time
from collections import defaultdict
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import cv2
import numpy as np
import pytest
from foxglove import messages as foxglove_messages
from google.protobuf import descriptor_pb2, descriptor_pool, message_factory
from mcap.reader import make_reader

from tests.test_cli_runtime import REPO, tafel
from tests.test_debug_server import Program

REQUESTS = ["BallDetector:draw_candidates", "BallLocator:draw_percept", "Striker:draw_target"]


def sdk_class(name: str) -> Any:
    """The protobuf class of ``foxglove.NAME`` from the schema foxglove-sdk ships with the message."""
    schema = getattr(foxglove_messages, name).get_schema()
    pool = descriptor_pool.DescriptorPool()
    for file in descriptor_pb2.FileDescriptorSet.FromString(schema.data).file:
        pool.Add(file)
    return message_factory.GetMessageClass(pool.FindMessageTypeByName(schema.name))


@pytest.fixture(scope="module")
def recording(tmp_path_factory: pytest.TempPathFactory) -> Iterator[dict[str, list[tuple[int, Any]]]]:
    """topic -> [(log time, decoded message)] of a two-second recording of the default MuJoCo scene."""
    folder = tmp_path_factory.mktemp("foxglove")
    program = Program("--platform", "mujoco", "--speed", "max", "--record-dir", str(folder), cwd=folder)
    try:
        client = program.client()
        for name in REQUESTS:
            assert not client.ask(f"debug_request:set -name {name} -value on").startswith("error:")
        assert not client.ask("log:start -file fox.mcap").startswith("error:")
        start = time.monotonic()
        while "frames" not in client.ask("log:status") or time.monotonic() - start < 4.0:
            time.sleep(0.2)
        assert not client.ask("log:stop").startswith("error:")
        client.close()
    finally:
        program.stop()
    classes = {name: sdk_class(name) for name in ("CompressedImage", "ImageAnnotations", "SceneUpdate", "FrameTransforms",
                                                  "CameraCalibration")}
    decoded: dict[str, list[tuple[int, Any]]] = defaultdict(list)
    with open(folder / "fox.mcap", "rb") as stream:
        for schema, channel, message in make_reader(stream).iter_messages():
            if not channel.topic.startswith("/"):
                continue
            if channel.message_encoding == "json":
                decoded[channel.topic].append((message.log_time, json.loads(message.data)))
            else:
                assert schema.name.startswith("foxglove."), schema.name
                decoded[channel.topic].append((message.log_time, classes[schema.name.split(".")[1]].FromString(message.data)))
    yield decoded


def stamp(message: Any) -> int:
    return message.timestamp.seconds * 1_000_000_000 + message.timestamp.nanos


@pytest.mark.slow
def test_the_images_are_jpegs_of_the_camera_size_with_a_calibration(recording: dict[str, list[tuple[int, Any]]]) -> None:
    for camera in ("top", "bottom"):
        images = recording[f"/camera/{camera}"]
        assert len(images) >= 10
        for _, message in images[:5]:
            assert message.format == "jpeg" and message.frame_id == f"camera_{camera}_optical"
            picture = cv2.imdecode(np.frombuffer(message.data, np.uint8), cv2.IMREAD_COLOR)
            assert picture is not None and picture.shape == (240, 320, 3)
        calibration = recording[f"/camera/{camera}/calibration"][-1][1]
        assert (calibration.width, calibration.height) == (320, 240)
        assert calibration.K[0] > 100 and calibration.K[2] == 160  # focal length from the field of view, centred


@pytest.mark.slow
def test_the_annotations_share_the_images_timestamps(recording: dict[str, list[tuple[int, Any]]]) -> None:
    image_times = {stamp(m) for _, m in recording["/camera/top"]} | {stamp(m) for _, m in recording["/camera/bottom"]}
    annotated = [m for _, m in recording["/camera/top/annotations"] + recording["/camera/bottom/annotations"]
                 if m.circles or m.points or m.texts]
    assert annotated, "the debug requests drew nothing on the images"
    for message in annotated:
        times = {stamp(c) for c in message.circles} | {stamp(p) for p in message.points} | {stamp(t) for t in message.texts}
        assert times <= image_times


@pytest.mark.slow
def test_the_scene_has_the_field_the_robot_and_the_ball(recording: dict[str, list[tuple[int, Any]]]) -> None:
    entities = {entity.id: entity for _, update in recording["/scene"] for entity in update.entities}
    assert {"field", "robot/torso", "robot/feet", "ball/model"} <= set(entities)
    assert len(entities["field"].lines[0].points) > 40 and entities["field"].frame_id == "field"
    assert entities["ball/model"].spheres  # the ball is seen in the default scene
    frames = {(t.parent_frame_id, t.child_frame_id) for _, m in recording["/tf"] for t in m.transforms}
    assert {("field", "robot"), ("robot", "torso"), ("torso", "camera_top"), ("camera_top", "camera_top_optical")} <= frames


@pytest.mark.slow
def test_the_series_have_names_and_log_times_are_wall_clock(recording: dict[str, list[tuple[int, Any]]]) -> None:
    _, joints = recording["/joints"][-1]
    assert set(joints) >= {"position", "command", "stiffness"}
    assert "LKneePitch" in joints["position"] and 0.0 <= joints["stiffness"]["LKneePitch"] <= 1.0
    assert {"accelerometer", "gyroscope", "angles"} <= set(recording["/imu"][-1][1])
    assert "left_front_left" in recording["/fsr"][-1][1]
    timing = {context for _, m in recording["/timing"] for context in m}
    assert timing == {"cognition", "motion"}
    rates = defaultdict(list)
    for _, message in recording["/rates"]:
        for context, rate in message.items():
            rates[context].append(rate)
    assert np.median(rates["motion"]) == pytest.approx(100, rel=0.02) and np.median(rates["cognition"]) == pytest.approx(30, rel=0.05)
    log_times = [t for messages in recording.values() for t, _ in messages]
    now = time.time_ns()
    assert all(now - 3600 * 10**9 < t <= now for t in log_times)  # recorded within the hour, not in 1970


def foxglove_topics(path: Path) -> dict[str, str]:
    with open(path, "rb") as stream:
        summary = make_reader(stream).get_summary()
    assert summary is not None
    return {c.topic: summary.schemas[c.schema_id].name for c in summary.channels.values() if c.topic.startswith("/")}


@pytest.mark.slow
def test_log_convert_adds_the_channels_to_a_log_recorded_without_them(tmp_path: Path) -> None:
    plain, converted = tmp_path / "plain.mcap", tmp_path / "converted.mcap"
    run = tafel("run", "--platform", "mujoco", "--seconds", "1", "--speed", "max", "--no-debug", "--record", str(plain),
                "--set", "foxglove.channels_in_recordings=false")
    assert run.returncode == 0, run.stderr
    assert foxglove_topics(plain) == {}
    result = tafel("log", "convert", str(plain), "--out", str(converted), "--jpeg-quality", "60")
    assert result.returncode == 0, result.stderr
    topics = foxglove_topics(converted)
    assert topics["/camera/top"] == "foxglove.CompressedImage" and topics["/scene"] == "foxglove.SceneUpdate"
    image_class = sdk_class("CompressedImage")
    with open(converted, "rb") as stream:
        images = [image_class.FromString(m.data) for _, c, m in make_reader(stream).iter_messages(topics=["/camera/top"])]
    assert len(images) == 30
    assert cv2.imdecode(np.frombuffer(images[0].data, np.uint8), cv2.IMREAD_COLOR).shape == (240, 320, 3)
    assert tafel("log", "compare", str(plain), str(converted)).returncode == 0  # the representations are untouched


@pytest.mark.slow
def test_log_convert_gives_an_old_log_wall_clock_times_and_refuses_bad_input(tmp_path: Path) -> None:
    converted = tmp_path / "converted.mcap"
    old = REPO / "tests" / "data" / "ball_situation.mcap"  # recorded when log times were frame times
    result = tafel("log", "convert", str(old), "--out", str(converted))
    assert result.returncode == 0, result.stderr
    with open(converted, "rb") as stream:
        times = [(m.log_time, m.publish_time) for _, _, m in make_reader(stream).iter_messages()]
    assert all(log_time > 1_600_000_000 * 10**9 and publish_time < 10**12 for log_time, publish_time in times)
    assert "/scene" in foxglove_topics(converted)
    for args, message in ((["--jpeg-quality", "0"], "--jpeg-quality takes a whole number from 1 to 100, got 0"), ([], "cannot read log")):
        source = old if args else tmp_path / "missing.mcap"
        result = tafel("log", "convert", str(source), "--out", str(tmp_path / "x.mcap"), *args)
        assert result.returncode != 0 and message in result.stderr


def test_the_layout_shows_only_topics_that_exist() -> None:
    from tafel.tools.viewers.foxglove_channels import TOPICS

    layout = json.loads((REPO / "config" / "foxglove" / "tafel-layout.json").read_text())
    text = json.dumps(layout["configById"])
    used = set(re.findall(r'"(/[a-z_/]+)', text)) | {p.split(".")[0] for p in re.findall(r'"(/[a-z_]+\.[\w.]+)"', text)}
    assert used and used <= set(TOPICS), used - set(TOPICS)
    panels = {key.split("!")[0] for key in layout["configById"]}
    assert {"3D", "Image", "Plot", "Parameters"} <= panels


def walk_layout(node: object) -> Iterator[str]:
    if isinstance(node, str):
        yield node
    elif isinstance(node, dict):
        yield from walk_layout(node["first"])
        yield from walk_layout(node["second"])


def test_every_panel_of_the_layout_is_placed() -> None:
    layout = json.loads((REPO / "config" / "foxglove" / "tafel-layout.json").read_text())
    assert sorted(walk_layout(layout["layout"])) == sorted(layout["configById"])


def test_the_programs_log_lines_are_recorded_as_foxglove_logs(tmp_path: Path) -> None:
    from tafel.core.logs.recording import Recorder
    from tafel.tools.launch.recording import foxglove_recording

    recorder = Recorder([])
    recorder.translate_factory = foxglove_recording(recorder, 80)
    recorder.start(tmp_path / "lines.mcap")
    logging.getLogger("tafel.motion").warning("the left knee is hot: %d deg C", 71)
    recorder.stop()
    logging.getLogger("tafel.motion").warning("after the recording: not in it")
    log_class = sdk_class("Log")
    with open(tmp_path / "lines.mcap", "rb") as stream:
        lines = [log_class.FromString(m.data) for _, _, m in make_reader(stream).iter_messages(topics=["/log"])]
    assert [(line.message, line.name) for line in lines] == [("the left knee is hot: 71 deg C", "tafel.motion")]
    assert lines[0].level == log_class.Level.Value("WARNING")


@pytest.mark.slow
@pytest.mark.parametrize("value", ["abc", "500", "0"])
def test_a_wrong_jpeg_quality_is_refused_before_the_run(tmp_path: Path, value: str) -> None:
    result = tafel("run", "--platform", "dummy", "--seconds", "0.2", "--no-debug", "--record", str(tmp_path / "x.mcap"),
                   "--set", f"foxglove.jpeg_quality={value}")
    assert result.returncode == 2 and "foxglove.jpeg_quality takes a whole number from 1 to 100" in result.stderr
    assert "Traceback" not in result.stderr


def test_each_json_channel_has_a_schema_its_messages_fit_field_by_field() -> None:
    """The series topics declare their fields (Foxglove's panels offer them): every message validates, and every
    field it carries is declared, in recordings (``encoded``) as live (the same schemas)."""
    import jsonschema

    from tafel.debug.concepts import ModuleTimes
    from tafel.representations.behavior import ActivationGraph, ActiveOption
    from tafel.representations.infrastructure import FrameInfo
    from tafel.representations.motion import FsrData, InertialSensorData, JointCommand, JointSensorData
    from tafel.tools.viewers.foxglove_channels import JSON_SCHEMAS, FoxgloveTranslator

    translator = FoxgloveTranslator()
    rng = np.random.default_rng(3)
    messages = []
    for frame in range(5):
        t = frame * 10_000_000
        for context, value in (("motion", JointSensorData(position=rng.normal(size=25), temperature=rng.uniform(30, 60, 25))),
                               ("motion", JointCommand(position=rng.normal(size=25), stiffness=rng.uniform(0, 1, 25))),
                               ("motion", InertialSensorData(accelerometer=rng.normal(size=3), gyroscope=rng.normal(size=3),
                                                             angles=rng.normal(size=2))),
                               ("motion", FsrData(pressure=rng.uniform(0, 2, 8))),
                               ("motion", ModuleTimes(names=["WalkingEngine", "StandMotion"], milliseconds=[0.4, 0.1])),
                               ("cognition", ModuleTimes(names=["BallDetector"], milliseconds=[2.5])),
                               ("motion", FrameInfo(frame_number=frame, time_ns=t)), ("cognition", FrameInfo(frame_number=frame, time_ns=t)),
                               ("cognition", ActivationGraph(options=[ActiveOption(name="PlaySoccer", state="playing", time_in_option=0.1 * frame),
                                                                      ActiveOption(name="GoTo", state="walk", depth=1, parameters="x=1 y=2")]))):
            messages += translator.feed(context, value, t)
    by_topic: dict[str, list[dict[str, Any]]] = defaultdict(list)
    for out in messages:
        if isinstance(out.message, dict):
            by_topic[out.topic].append(out.message)
            assert out.encoded().schema_data == JSON_SCHEMAS[out.topic]
    assert set(by_topic) == set(JSON_SCHEMAS) == {"/joints", "/imu", "/fsr", "/timing", "/rates", "/behavior"}
    assert by_topic["/behavior"][-1]["path"] == "PlaySoccer/playing > GoTo/walk" and by_topic["/behavior"][-1]["options"][1]["depth"] == 1
    for topic, sent in by_topic.items():
        schema = json.loads(JSON_SCHEMAS[topic])
        jsonschema.Draft202012Validator.check_schema(schema)
        for message in sent:
            jsonschema.validate(message, schema)
            assert set(message) <= set(schema["properties"]), (topic, message)
    fields = json.loads(JSON_SCHEMAS["/joints"])["properties"]
    assert set(fields) == {"position", "temperature", "command", "stiffness"} and fields["command"]["properties"]["LKneePitch"] == {"type": "number"}
    assert json.loads(JSON_SCHEMAS["/imu"])["properties"]["angles"]["properties"] == {"roll": {"type": "number"}, "pitch": {"type": "number"}}
    with pytest.raises(jsonschema.ValidationError):  # a schema that says something: a wrong message does not fit
        jsonschema.validate({"accelerometer": {"x": "high"}}, json.loads(JSON_SCHEMAS["/imu"]))


def test_the_layout_ships_in_the_package() -> None:
    """Every file of config/foxglove/ is package data of ``tafel.config`` (the wheel test installs and finds it)."""
    import fnmatch
    import tomllib

    patterns = tomllib.loads((REPO / "pyproject.toml").read_text())["tool"]["setuptools"]["package-data"]["tafel.config"]
    shipped = sorted(path.relative_to(REPO / "config").as_posix() for path in (REPO / "config" / "foxglove").iterdir() if path.is_file())
    assert "foxglove/tafel-layout.json" in shipped
    missing = [name for name in shipped if not any(fnmatch.fnmatch(name, pattern) for pattern in patterns)]
    assert not missing, f"add to [tool.setuptools.package-data] tafel.config in pyproject.toml: {missing}"


def test_json_command_requests_say_what_to_send() -> None:
    from tafel.tools.viewers.foxglove_live import command_from_json

    assert command_from_json('{"command": " modules:list "}') == "modules:list"
    assert command_from_json('"ping"') == "ping"
    for bad in ("{", "{}", '{"command": ""}', '{"command": 5}', '{"command": "ping", "x": 1}', "[]", "null"):
        with pytest.raises(ValueError, match=r'send \{"command": "COMMAND LINE"\}'):
            command_from_json(bad)


def test_a_drawn_robot_pose_is_a_triangle_pointing_where_the_robot_faces() -> None:
    from tafel.tools.viewers.foxglove_scene import _outline

    # at (1000, 0) facing +y: the tip 150 mm ahead, the back corners 100 mm behind and 80 mm to either side
    triangle = _outline("robot_pose", [1000.0, 0.0, math.pi / 2])
    assert np.allclose(triangle, [(1080.0, -100.0), (1000.0, 150.0), (920.0, -100.0), (1080.0, -100.0)])


@pytest.mark.parametrize(("key", "value", "message"), [
    ("jpeg_quality", 0, "foxglove.jpeg_quality takes a whole number from 1 to 100, got 0"),
    ("jpeg_quality", 80.5, "foxglove.jpeg_quality takes a whole number from 1 to 100, got 80.5"),
    ("origins", 5, 'foxglove.origins takes a list of web origins such as ["https://app.foxglove.dev"], got 5'),
    ("origins", ["app.foxglove.dev"], "foxglove.origins takes a list of web origins such as "
                                      "[\"https://app.foxglove.dev\"], got ['app.foxglove.dev']"),
])
def test_foxglove_settings_are_refused_in_the_one_wording(key: str, value: object, message: str) -> None:
    from tafel.tools.launch.errors import UsageError
    from tafel.tools.launch.recording import foxglove_origins, jpeg_quality

    check = jpeg_quality if key == "jpeg_quality" else foxglove_origins
    with pytest.raises(UsageError) as error:
        check({"foxglove": {key: value}})
    assert str(error.value) == message
    assert jpeg_quality({"foxglove": {"jpeg_quality": 90}}) == 90
    assert foxglove_origins({"foxglove": {"origins": ["https://app.foxglove.dev"]}}) == ["https://app.foxglove.dev"]
