"""Writing one's own modules: the representations' import names, module folders (``--module-path``),
installed packages of modules (entry point group ``tafel.modules``), and configuration that adds them."""

from __future__ import annotations

import json
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parent.parent
TAFEL = [sys.executable, "-m", "tafel.tools.cli"]

#: a module of one's own with a representation of its own, as a user writes it (imports from the README)
COUNTER = '''
from tafel.core import Module, provides, representation, requires
from tafel.representations import BallPercept, FrameInfo


@representation
class BallSightings:
    """Frames run, and frames in which the ball was seen."""
    frames: int = 0
    seen: int = 0


@requires(BallPercept, FrameInfo)
@provides(BallSightings)
class BallSightingCounter(Module):
    def __init__(self) -> None:
        self.frames = 0
        self.seen = 0

    def execute(self) -> None:
        self.frames += 1
        self.seen += int(self.ball_percept.seen)
        self.ball_sightings.frames, self.ball_sightings.seen = self.frames, self.seen
'''


def tafel(*args: str, env: dict[str, str] | None = None, cwd: Path = REPO) -> subprocess.CompletedProcess:
    environment = {**os.environ, "PYTHONPATH": str(REPO), **(env or {})}
    return subprocess.run([*TAFEL, *args], capture_output=True, text=True, timeout=300, cwd=cwd, env=environment)


@pytest.fixture
def own(tmp_path: Path) -> tuple[Path, Path]:
    """A folder with the module file (and a test beside it, which is not imported), and a configuration
    folder whose general layer adds the module to cognition's list."""
    modules = tmp_path / "my_modules"
    modules.mkdir()
    (modules / "ball_sightings.py").write_text(COUNTER)
    (modules / "test_ball_sightings.py").write_text("raise RuntimeError('tests are not imported as modules')\n")
    config = tmp_path / "my_config"
    config.mkdir()
    (config / "general.toml").write_text('[cognition]\nadd = ["BallSightingCounter"]\n')
    return modules, config


def order(output: str, context: str) -> list[str]:
    found = re.search(rf"^{context} \(.*?\)\n  order: (.*)$", output, re.MULTILINE)
    assert found, output
    return found[1].split(" -> ")


# --------------------------------------------------------------------- representations by their package
def test_the_shipped_representations_import_from_the_package() -> None:
    from tafel.representations import BallModel, BallPercept, FrameInfo, MotionType, field
    from tafel.representations.infrastructure import FrameInfo as frame_info_in_its_file
    from tafel.representations.modeling import BallModel as ball_model_in_its_file
    from tafel.representations.perception import BallPercept as ball_percept_in_its_file

    assert (BallModel, BallPercept, FrameInfo) == (ball_model_in_its_file, ball_percept_in_its_file, frame_info_in_its_file)
    assert MotionType.stand.name == "stand"
    assert field.__name__ == "tafel.representations.field"  # files of the package stay what they were


def test_every_registered_representation_is_reachable_from_the_package() -> None:
    import tafel.representations as representations
    from tafel.core.framework.representation import registered_representations

    representations.load_all()
    shipped = {name: cls for name, cls in registered_representations().items() if cls.__module__.startswith("tafel.representations.")}
    assert len(shipped) > 40
    assert {name: getattr(representations, name) for name in shipped} == shipped
    assert set(shipped) <= set(dir(representations))


def test_a_misspelt_representation_name_suggests_the_right_one() -> None:
    import tafel.representations as representations

    with pytest.raises(AttributeError, match="did you mean 'BallPercept'"):
        representations.BallPercpt  # noqa: B018 - the lookup is the test


def test_the_readme_module_example_runs_as_written(tmp_path: Path) -> None:
    """The code blocks of README's "Writing a module" (before its subsections), run in a fresh interpreter."""
    readme = (REPO / "README.md").read_text()
    section = readme.split("\n## Writing a module\n", 1)[1].split("\n### ", 1)[0]
    blocks = re.findall(r"```python\n(.*?)```", section, re.DOTALL)
    assert len(blocks) >= 2
    script = tmp_path / "example.py"
    script.write_text("\n\n".join(blocks) + "\nprint(sorted(r.__name__ for r in SimpleBallModeler.requirements().reads()), flush=True)\n")
    result = subprocess.run([sys.executable, str(script)], capture_output=True, text=True, timeout=120,
                            env={**os.environ, "PYTHONPATH": str(REPO)}, cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    assert "BallPercept" in result.stdout and "FrameInfo" in result.stdout


# ------------------------------------------------------------------------------- --module-path DIR
@pytest.mark.slow
def test_without_the_module_path_the_module_is_unknown(own: tuple[Path, Path]) -> None:
    _, config = own
    result = tafel("modules", "--platform", "dummy", "--config", str(config))
    assert result.returncode == 2
    assert "BallSightingCounter" in result.stderr


@pytest.mark.slow
def test_modules_lists_a_module_from_a_folder_added_by_configuration(own: tuple[Path, Path]) -> None:
    modules, config = own
    result = tafel("modules", "--platform", "dummy", "--config", str(config), "--module-path", str(modules))
    assert result.returncode == 0, result.stderr
    assert "BallSightingCounter" in order(result.stdout, "cognition")


def sightings(log: Path) -> list[dict]:
    """The recorded BallSightings, frame by frame (through ``tafel log export``)."""
    out = log.with_suffix(".jsonl")
    result = tafel("log", "export", str(log), "--rep", "BallSightings", "--format", "jsonl", "--out", str(out))
    assert result.returncode == 0, result.stderr
    return [json.loads(line) for line in out.read_text().splitlines()]


@pytest.mark.slow
@pytest.mark.parametrize("concurrent", [False, True])
def test_a_run_loads_the_folder_and_records_the_modules_representation(own: tuple[Path, Path], tmp_path: Path,
                                                                       concurrent: bool) -> None:
    """Also in the concurrent runtime, whose context processes must import the same module files."""
    modules, config = own
    log = tmp_path / "run.mcap"
    result = tafel("run", "--platform", "dummy", "--module-path", str(modules), "--config", str(config), "--frames", "20",
                   "--speed", "max", "--no-debug", "--record", str(log), "--record-reps", "BallSightings",
                   *(["--concurrent"] if concurrent else []), cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    assert "module errors: none" in result.stdout
    rows = sightings(log)
    assert rows, "no BallSightings recorded"
    assert [row["frames"] for row in rows] == list(range(1, len(rows) + 1))  # one count per cognition frame, all recorded
    assert all(row["context"] == "cognition" for row in rows)


@pytest.mark.slow
@pytest.mark.parametrize(("files", "message"), [
    ({}, "holds no Python files"),
    ({"broken.py": "x = 1\ny = (\n"}, r"importing broken failed \(at .*broken.py:2\): SyntaxError"),
    ({"raises.py": "import os\nraise ValueError('the detector is not ready')\n"}, r"importing raises failed \(at .*raises.py:2\): ValueError: the detector"),
    ({"json.py": "x = 1\n"}, r"the name 'json' is already taken by .*json.*rename the file"),
])
def test_a_folder_that_cannot_be_loaded_says_why(tmp_path: Path, files: dict[str, str], message: str) -> None:
    folder = tmp_path / "mods"
    folder.mkdir()
    for name, text in files.items():
        (folder / name).write_text(text)
    result = tafel("modules", "--platform", "dummy", "--module-path", str(folder))
    assert result.returncode == 2
    assert re.search(message, result.stderr), result.stderr


@pytest.mark.slow
def test_a_missing_folder_is_an_error(tmp_path: Path) -> None:
    result = tafel("modules", "--platform", "dummy", "--module-path", str(tmp_path / "nowhere"))
    assert result.returncode == 2
    assert "no such folder" in result.stderr


# ------------------------------------------------------------------- installed packages: entry points
def install_fake_package(site: Path, entry: str) -> None:
    """A package as pip would leave it: the code, and a dist-info that declares the entry point."""
    (site / "team_modules").mkdir(parents=True)
    (site / "team_modules" / "__init__.py").write_text(COUNTER)
    info = site / "team_modules-1.0.dist-info"
    info.mkdir()
    (info / "METADATA").write_text("Metadata-Version: 2.1\nName: team-modules\nVersion: 1.0\n")
    (info / "entry_points.txt").write_text(f"[tafel.modules]\nteam = {entry}\n")


@pytest.mark.slow
def test_an_installed_package_announces_its_modules_by_entry_point(own: tuple[Path, Path], tmp_path: Path) -> None:
    _, config = own
    site = tmp_path / "site"
    install_fake_package(site, "team_modules")
    result = tafel("modules", "--platform", "dummy", "--config", str(config), env={"PYTHONPATH": f"{REPO}{os.pathsep}{site}"})
    assert result.returncode == 0, result.stderr
    assert "BallSightingCounter" in order(result.stdout, "cognition")


@pytest.mark.slow
def test_a_broken_entry_point_is_reported_and_does_not_stop_other_programs(tmp_path: Path) -> None:
    site = tmp_path / "site"
    install_fake_package(site, "team_modules.missing_file")
    result = tafel("modules", "--platform", "dummy", env={"PYTHONPATH": f"{REPO}{os.pathsep}{site}"})
    assert result.returncode == 0, result.stderr
    assert "entry point team = team_modules.missing_file" in result.stderr


# --------------------------------------------------------------------------- configuration edits
@pytest.mark.slow
def test_a_misspelt_module_added_in_configuration_suggests_the_right_name(own: tuple[Path, Path]) -> None:
    modules, config = own
    (config / "general.toml").write_text('[cognition]\nadd = ["BallSightingCountr"]\n')
    result = tafel("modules", "--platform", "dummy", "--config", str(config), "--module-path", str(modules))
    assert result.returncode == 2
    assert "did you mean 'BallSightingCounter'" in result.stderr


@pytest.mark.slow
def test_configuration_removes_a_shipped_module_without_restating_the_list(tmp_path: Path) -> None:
    (tmp_path / "general.toml").write_text('[cognition]\nremove = ["GameControllerReporter"]\n')
    result = tafel("modules", "--platform", "dummy", "--config", str(tmp_path))
    assert result.returncode == 0, result.stderr
    assert "GameControllerReporter" not in order(result.stdout, "cognition")
    assert "SoccerBehavior" in order(result.stdout, "cognition")
    (tmp_path / "general.toml").write_text('[cognition]\nremove = ["GameControlerReporter"]\n')
    result = tafel("modules", "--platform", "dummy", "--config", str(tmp_path))
    assert result.returncode == 2
    assert "did you mean 'GameControllerReporter'" in result.stderr



# ------------------------------------------------------- the batch commands: scenarios and replay-batch
#: a module of one's own that replaces a shipped provider: a ball always 1234 mm ahead
FIXED_BALL = '''
from tafel.core import Module, provides, requires
from tafel.representations import BallModel, FrameInfo


@requires(FrameInfo)
@provides(BallModel)
class FixedBallModeler(Module):
    def execute(self) -> None:
        self.ball_model.x, self.ball_model.valid = 1234.0, True
'''

#: a scenario that succeeds only if the module of one's own runs (its representation counts 20 frames)
COUNTING_SCENARIO = '''
name = "counts"
duration_s = 2.0
cameras = false
required_success_rate = 1.0

[[robots]]
start = [0.0, 0.0, 0.0]

[[success]]
predicate = "representation"
name = "BallSightings"
field = "frames"
at_least = 20
'''


@pytest.mark.slow  # a simulator in a worker process
def test_scenarios_run_with_modules_of_ones_own(own: tuple[Path, Path], tmp_path: Path) -> None:
    modules, _ = own
    scenario = tmp_path / "counts.toml"
    scenario.write_text(COUNTING_SCENARIO)
    unknown = tafel("scenarios", "run", str(scenario), "--repeat", "1", cwd=tmp_path)
    assert unknown.returncode == 2 and "no representation named 'BallSightings'" in unknown.stderr  # without the folder
    done = tafel("scenarios", "run", str(scenario), "--repeat", "1", "--workers", "1", "--module-path", str(modules),
                 "--add-module", "cognition:BallSightingCounter", "--out", str(tmp_path / "runs.jsonl"), cwd=tmp_path)
    assert done.returncode == 0, done.stdout + done.stderr
    row = json.loads((tmp_path / "runs.jsonl").read_text().splitlines()[0])
    assert row["success"] is True, row


@pytest.mark.slow  # a recorded run and a worker process
def test_replay_batch_replays_with_a_module_of_ones_own(tmp_path: Path) -> None:
    (tmp_path / "mods").mkdir()
    (tmp_path / "mods" / "fixed_ball.py").write_text(FIXED_BALL)
    recorded = tafel("run", "--platform", "dummy", "--frames", "100", "--speed", "max", "--no-debug", "--record", str(tmp_path / "g.mcap"),
                     "--record-reps", "all", cwd=tmp_path)
    assert recorded.returncode == 0, recorded.stderr
    done = tafel("replay-batch", str(tmp_path / "g.mcap"), "--module-path", str(tmp_path / "mods"), "--workers", "1",
                 "--remove-module", "cognition:KalmanBallModeler", "--add-module", "cognition:FixedBallModeler",
                 "--set", "cognition.providers.BallModel=FixedBallModeler", "--metric", "BallModel.x", "--out", str(tmp_path / "b.csv"),
                 cwd=tmp_path)
    assert done.returncode == 0, done.stdout + done.stderr
    assert "1234 replayed" in done.stdout  # the mean of BallModel.x over the replay: the module's ball


@pytest.mark.slow
@pytest.mark.parametrize(("command", "arguments", "message"), [
    ("replay-batch", ["--module-path", "nowhere"], "nowhere: no such folder; give the folder that holds your module files"),
    ("replay-batch", ["--add-module", "cognition:BallSightingCountr"], "unknown module 'BallSightingCountr': did you mean 'BallSightingCounter'"),
    ("replay-batch", ["--remove-module", "cognition:Kalman"], "Kalman is not in [cognition] modules; did you mean 'KalmanBallModeler'"),
    ("scenarios", ["--add-module", "motion:BallSightingCountr"], "unknown module 'BallSightingCountr': did you mean 'BallSightingCounter'"),
    ("scenarios", ["--add-module", "brain:BallSightingCounter"], "CONTEXT takes cognition or motion"),
])
def test_the_batch_commands_refuse_bad_module_options_before_any_run(own: tuple[Path, Path], tmp_path: Path, command: str,
                                                                     arguments: list[str], message: str) -> None:
    modules, _ = own
    target = tmp_path / "any.mcap"
    target.write_bytes(b"never read: the options are refused first")
    if command == "scenarios":
        target = tmp_path / "counts.toml"
        target.write_text(COUNTING_SCENARIO)
    found = ["--module-path", str(modules)] if "nowhere" not in arguments else []
    result = tafel(*(["scenarios", "run"] if command == "scenarios" else [command]), str(target), *found, *arguments,
                   "--out", str(tmp_path / "rows.csv"), cwd=tmp_path)
    assert result.returncode == 2, result.stdout + result.stderr
    assert message in result.stderr, result.stderr
    assert not (tmp_path / "rows.csv").exists()
