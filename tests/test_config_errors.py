"""Every bad value in configuration or on the command line exits with status 2 and one clear message:
never a traceback, never silence (issue: configuration and command line, security round two)."""

from __future__ import annotations

from pathlib import Path

import pytest

from tafel.tools.cli import main

RUN = ["run", "--platform", "dummy", "--frames", "3", "--speed", "max", "--no-debug"]


def refused(argv: list[str], capsys: pytest.CaptureFixture[str]) -> str:
    with pytest.raises(SystemExit) as exit_:
        main(argv)
    assert exit_.value.code == 2
    err = capsys.readouterr().err
    assert "Traceback" not in err
    return err


@pytest.mark.parametrize(("setting", "message"), [
    ("recording='x'", "recording takes a table ([recording] in a file), got 'x'"),
    ("recording.representations=5", "recording.representations takes a list of representation names"),
    ('recording.representations=["NoSuch"]', "recording.representations: no representation named 'NoSuch'"),
    ("game=5", "game takes a table ([game] in a file), got 5"),
    ("debug.aliases=5", "debug.aliases takes tables, one per alias"),
    ("a.b.c=1", "[a] is not a section of the configuration"),
    ("parameter.HeadMotion.x=1", "[parameter] is not a section of the configuration; did you mean 'parameters'"),
    ("status.show=7", "status.show takes a list of representation names"),
    ('status.show=["NoSuch"]', "status.show: no representation named 'NoSuch'"),
    ("status.shown=[]", "[status] shown is not a setting"),
    ("x=" + "9" * 5000, "a number of 5000 characters; whole numbers in configuration fit 64 bits"),
    ("x=" + "[" * 5000 + "]" * 5000, "nested too deeply"),
    (".".join(["a"] * 3000) + "=1", "a key of 3000 parts; configuration keys have at most 8"),
    ("runtime.cognition_hz=" + str(2**70), "runtime.cognition_hz takes a whole number that fits in 64 bits, got a number of about 22 digits"),
    ('parameters.GameStateProvider.start_state="bogus"', "takes one of"),
])
def test_a_bad_setting_is_one_clear_error(setting: str, message: str, capsys: pytest.CaptureFixture[str]) -> None:
    assert message in refused([*RUN, "--set", setting], capsys)


def test_bad_configuration_files_are_clear_errors(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    (tmp_path / "general.toml").write_text("[parameter.HeadMotion]\nx = 1\n")  # a typo of [parameters...]
    assert "[parameter] is not a section of the configuration; did you mean 'parameters'" in refused([*RUN, "--config", str(tmp_path)], capsys)
    (tmp_path / "general.toml").write_text("[" + ".".join(["a"] * 3000) + "]\nx = 1\n")
    assert "nested more than 8 levels deep" in refused([*RUN, "--config", str(tmp_path)], capsys)


@pytest.mark.parametrize("speed", ["1e-300", "0", "-1", "nan", "inf", "fast"])
def test_speed_takes_a_sane_factor(speed: str, capsys: pytest.CaptureFixture[str]) -> None:
    assert "--speed takes a factor from 0.001 to 1000 or 'max'" in refused([*RUN[:-3], "--speed", speed], capsys)


def test_record_dir_must_be_a_folder(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    file = tmp_path / "a-file"
    file.write_text("")
    assert f"--record-dir {file} is a file; it takes a folder" in refused([*RUN, "--record-dir", str(file)], capsys)


def test_good_settings_still_run(capsys: pytest.CaptureFixture[str]) -> None:
    assert main([*RUN, "--set", 'status.show=["MotionInfo"]', "--set", 'recording.representations=["BallModel"]']) == 0
