"""Scenario files, the success judge, seeds and intervals; ``tafel scenarios run`` end to end, on 1 and 2
local workers and on Ray; the shipped scenarios."""

from __future__ import annotations

import csv
import json
import math
import os
import subprocess
import sys
from pathlib import Path
from typing import Any

import pytest
from hypothesis import given
from hypothesis import strategies as st

from tafel.core.logs import LogReader
from tafel.tools.simulation.batch import BatchInfo, run_jobs
from tafel.tools.simulation.scenario_file import ScenarioError, load_scenario
from tafel.tools.simulation.scenarios import _Judge, perturbed_start, play, run_seed, summarize, wilson_interval

REPO = Path(__file__).resolve().parent.parent
SHIPPED = sorted((REPO / "config" / "scenarios").glob("*.toml"))

GOOD = """\
name = "small"
duration_s = 5.0
required_success_rate = 0.5
set = ["parameters.KalmanBallModeler.friction=0.4"]

[[robots]]
start = [0.0, 0.0, 0.0]

[ball]
position = [1000.0, 0.0]

[perturbation]
robot_x_mm = 100.0
sensor_noise = [0.5, 2.0]

[[success]]
predicate = "robot_near_ball"
within_mm = 400.0

[[success]]
predicate = "no_fall"
"""


def write(tmp_path: Path, text: str, name: str = "scenario.toml") -> Path:
    path = tmp_path / name
    path.write_text(text)
    return path


def tafel(*args: str, cwd: Path, timeout: float = 600) -> subprocess.CompletedProcess:
    env = {**os.environ, "PYTHONPATH": str(REPO), "MUJOCO_GL": os.environ.get("MUJOCO_GL", "egl")}
    return subprocess.run([sys.executable, "-m", "tafel.tools.cli", *args], capture_output=True, text=True, timeout=timeout, cwd=cwd, env=env)


# ------------------------------------------------------------------------------------- the files
def test_every_shipped_scenario_file_loads() -> None:
    names = [load_scenario(path).name for path in SHIPPED]
    assert {"find the ball", "walk to the ball", "kick towards the goal", "get up after a push", "striker scores from its own half"} <= set(names)


def test_a_scenario_that_judges_perception_renders_like_a_camera_unless_it_says_otherwise(tmp_path: Path) -> None:
    """Realism is on (mild) where a predicate judges what the robot saw; off where nothing does; a file's own word wins."""
    judged = GOOD + '\n[[success]]\npredicate = "ball_model_accurate"\nwithin_mm = 300.0\n'
    assert load_scenario(write(tmp_path, GOOD)).realism == "off"
    assert load_scenario(write(tmp_path, judged)).realism == "mild"
    assert load_scenario(write(tmp_path, 'realism = "full"\n' + judged)).realism == "full"
    with pytest.raises(ScenarioError, match="realism takes one of off, mild, full, got 'photo'"):
        load_scenario(write(tmp_path, 'realism = "photo"\n' + GOOD))


def test_a_good_file_gives_every_value(tmp_path: Path) -> None:
    scenario = load_scenario(write(tmp_path, GOOD))
    assert scenario.duration_s == 5.0 and scenario.robot_start == (0.0, 0.0, 0.0) and scenario.ball == (1000.0, 0.0)
    assert scenario.overrides == ("parameters.KalmanBallModeler.friction=0.4",)
    assert scenario.perturbation.robot_x_mm == 100.0 and scenario.perturbation.sensor_noise == (0.5, 2.0)
    near, no_fall = scenario.success
    assert (near.predicate, near.parameters["within_mm"], near.within_s, near.when) == ("robot_near_ball", 400.0, 5.0, "eventually")
    assert no_fall.when == "always"


@pytest.mark.parametrize(("change", "line", "message"), [
    (('predicate = "robot_near_ball"', 'predicate = "robot_near_bal"'), 17,
     "no predicate 'robot_near_bal'; did you mean 'robot_near_ball'"),
    (("duration_s = 5.0\n", ""), 1, "the file's top level needs duration_s (a number of seconds above 0 and at most 3600)"),
    (("duration_s = 5.0", 'duration_s = "long"'), 2, "duration_s in the file's top level takes a number of seconds above 0 and at most 3600, got 'long'"),
    (("duration_s = 5.0", "duration_s = 1e308"), 2, "takes a number of seconds above 0 and at most 3600, got 1e+308"),
    (("start = [0.0, 0.0, 0.0]", "start = [1e9, 0.0, 0.0]"), 7, "start in [[robots]] number 1 takes [x_mm, y_mm, rotation_deg], three numbers, x and y on the carpet"),
    (("position = [1000.0, 0.0]", "position = [0.0, -9000.0]"), 10, "position in [ball] takes [x_mm, y_mm], two numbers on the carpet"),
    (('set = ["parameters.KalmanBallModeler.friction=0.4"]', 'set = ["parameter.KalmanBallModeler.friction=0.4"]'), 4,
     "set: [parameter] is not a section of the configuration; did you mean 'parameters'"),
    (('set = ["parameters.KalmanBallModeler.friction=0.4"]', 'set = ["game=5"]'), 4, "set: game takes a table ([game] in a file), got 5"),
    (("start = [0.0, 0.0, 0.0]", "start = [0.0, 0.0]"), 7, "start in [[robots]] number 1 takes [x_mm, y_mm, rotation_deg], three numbers"),
    (("within_mm = 400.0", 'within_mm = "near"'), 18, "within_mm in [[success]] number 1 takes a number, got 'near'"),
    (("robot_x_mm = 100.0", "robot_x_mn = 100.0"), 13, "[perturbation] has no key 'robot_x_mn'; did you mean 'robot_x_mm'"),
    (("sensor_noise = [0.5, 2.0]", "sensor_noise = [2.0, 0.5]"), 14, "sensor_noise in [perturbation] takes [low, high], two numbers with low <= high"),
    (("required_success_rate = 0.5", "required_success_rate = 1.5"), 3, "required_success_rate in the file's top level takes a number from 0 to 1"),
    (('set = ["parameters.KalmanBallModeler.friction=0.4"]', 'set = ["friction"]'), 4, "--set takes KEY=VALUE with a dotted key"),
    (("position = [1000.0, 0.0]", "position = 1000.0, 0.0"), 10, "not TOML"),
    (("robot_x_mm = 100.0", "robot_x_mm = -5.0"), 13, "robot_x_mm in [perturbation] takes a spread (plus or minus), 0 or more, got -5"),
    (("sensor_noise = [0.5, 2.0]", "sensor_noise = [0.5, 200.0]"), 14,
     "sensor_noise takes [low, high] factors from 0 to 100 (1: the NAO's noise), got [0.5, 200.0]"),
    (("within_mm = 400.0", "within_mm = 400.0\nfor_s = -1.0"), 19, "for_s takes a time of 0 s or more, got -1"),
    (("within_mm = 400.0", "within_mm = 400.0\nafter_s = 9.0"), 19, "after_s takes a time from 0 to below within_s (5 s), got 9"),
])
def test_a_bad_file_is_an_error_that_names_the_file_the_line_and_what_would_be_right(
        tmp_path: Path, change: tuple[str, str], line: int, message: str) -> None:
    path = write(tmp_path, GOOD.replace(*change))
    with pytest.raises(ScenarioError) as error:
        load_scenario(path)
    assert str(error.value).startswith(f"{path}:{line}: "), str(error.value)
    assert message in str(error.value)


def test_a_file_nested_thousands_of_levels_deep_is_a_clear_error(tmp_path: Path) -> None:
    path = write(tmp_path, GOOD + "deep = " + "[" * 5000 + "]" * 5000 + "\n")
    with pytest.raises(ScenarioError, match="nested too deeply to be a scenario"):
        load_scenario(path)


def test_a_push_outside_the_run_or_too_strong_is_refused(tmp_path: Path) -> None:
    event = '\n[[events]]\nat_s = {at}\npush_n = [{force}, 0.0]\n'
    with pytest.raises(ScenarioError, match=r"scenario.toml:24: at_s takes a time within the run, from 0 to below 5 s, got 7$"):
        load_scenario(write(tmp_path, GOOD + event.format(at=7.0, force=300.0)))
    with pytest.raises(ScenarioError, match=r"scenario.toml:25: push_n takes \[fx, fy\] up to 500 N, got \[900.0, 0.0\]"):
        load_scenario(write(tmp_path, GOOD + event.format(at=1.0, force=900.0)))
    assert load_scenario(write(tmp_path, GOOD + event.format(at=1.0, force=300.0))).events[0].force_n == (300.0, 0.0)


def test_predicates_over_representations_are_checked_against_the_representations(tmp_path: Path) -> None:
    entry = '\n[[success]]\npredicate = "representation"\nname = "{name}"\nfield = "{field}"\nequals = true\n'
    path = write(tmp_path, GOOD + entry.format(name="BallModl", field="valid"))
    with pytest.raises(ScenarioError, match=r"scenario.toml:25: no representation named 'BallModl'; did you mean 'BallModel'"):
        load_scenario(path)
    path = write(tmp_path, GOOD + entry.format(name="BallModel", field="vaild"))
    with pytest.raises(ScenarioError, match=r"scenario.toml:26: BallModel has no field 'vaild'; did you mean 'valid'"):
        load_scenario(path)
    path = write(tmp_path, GOOD + entry.format(name="BallModel", field="valid").replace("equals = true\n", ""))
    with pytest.raises(ScenarioError, match=r"scenario.toml:23: a representation predicate needs equals, at_least or at_most"):
        load_scenario(path)
    path = write(tmp_path, GOOD + entry.format(name="BallModel", field="valid") + 'context = "Cognition"\n')
    with pytest.raises(ScenarioError, match=r"scenario.toml:28: context takes cognition or motion, got 'Cognition'$"):
        load_scenario(path)
    path = write(tmp_path, GOOD + entry.format(name="BallModel", field="valid") + 'context = "cognition"\n')
    assert load_scenario(path).success[-1].parameters["context"] == "cognition"


@pytest.mark.slow  # worker processes / a subprocess: end to end
def test_the_command_refuses_a_bad_file_with_status_2_before_running_anything(tmp_path: Path) -> None:
    path = write(tmp_path, GOOD.replace('predicate = "no_fall"', 'predicate = "no_falls"'))
    done = tafel("scenarios", "run", str(path), "--out", str(tmp_path / "runs.csv"), cwd=tmp_path, timeout=60)
    assert done.returncode == 2
    assert f"{path}:21: no predicate 'no_falls'; did you mean 'no_fall'" in done.stderr
    assert not (tmp_path / "runs.csv").exists()
    listed = tafel("scenarios", "predicates", cwd=tmp_path, timeout=60)
    assert listed.returncode == 0 and "ball_in_goal (eventually)" in listed.stdout and "no_fall (always)" in listed.stdout


# ------------------------------------------------------------------------------------- the judge
class FakeWorld:
    """Ground truth set by hand: the robot at ``x`` (mm), the ball at ``ball``, standing or not."""

    def __init__(self) -> None:
        self.x, self.ball_at, self.standing = 0.0, (1000.0, 0.0), True

    def ball(self) -> tuple[float, float]:
        return self.ball_at

    def robot(self) -> tuple[float, float, float]:
        return self.x, 0.0, 0.0

    def posture(self) -> str:
        return "upright" if self.standing else "lying front"

    def torso_height(self) -> float:
        return 330.0 if self.standing else 100.0

    def representation(self, name: str, context: str) -> Any:
        raise AssertionError("not used here")


def judged(tmp_path: Path, success: str, timeline: list[tuple[float, float, bool]], duration: float = 5.0) -> tuple[bool, str, float] | None:
    """Run the judge over (time, robot x, standing) samples; (success, reason, when decided)."""
    text = GOOD.split("[[success]]")[0].replace("duration_s = 5.0", f"duration_s = {duration}") + success
    judge, world = _Judge(load_scenario(write(tmp_path, text))), FakeWorld()
    for now, x, standing in timeline:
        world.x, world.standing = x, standing
        judge.check(world, now)
        if judge.outcome is not None:
            return (*judge.outcome, now)
    return None


def test_an_eventually_predicate_succeeds_when_it_first_holds_and_fails_at_its_deadline(tmp_path: Path) -> None:
    walk = [(t / 10, t * 40.0, True) for t in range(60)]  # 400 mm/s towards the ball at 1000 mm
    entry = '[[success]]\npredicate = "robot_near_ball"\nwithin_mm = 300.0\nwithin_s = {within}\n'
    assert judged(tmp_path, entry.format(within=3.0), walk) == (True, "", 1.8)
    success, reason, when = judged(tmp_path, entry.format(within=1.0), walk)
    assert (success, when) == (False, 1.0) and reason == "robot_near_ball(within_mm=300.0) did not hold within 1 s"


def test_for_s_needs_an_unbroken_stretch_and_after_s_ignores_what_came_before(tmp_path: Path) -> None:
    # near the ball at 0.5 s, away again at 0.7 s, back from 1.0 s on
    samples = [(t / 10, 900.0 if 5 <= t < 7 or t >= 10 else 0.0, True) for t in range(50)]
    entry = '[[success]]\npredicate = "robot_near_ball"\nfor_s = 0.5\n'
    assert judged(tmp_path, entry, samples) == (True, "", 1.5)
    assert judged(tmp_path, entry.replace("for_s = 0.5", "after_s = 2.0"), samples) == (True, "", 2.0)


def test_an_always_predicate_fails_the_run_when_it_breaks_and_holds_it_otherwise(tmp_path: Path) -> None:
    entries = '[[success]]\npredicate = "robot_near_ball"\n\n[[success]]\npredicate = "no_fall"\n'
    falls = [(t / 10, 0.0, t < 12) for t in range(50)]
    assert judged(tmp_path, entries, falls) == (False, "no_fall broke at 1.20 s", 1.2)
    # alone, an always predicate decides at the end of the run; after its within_s it is no longer checked
    assert judged(tmp_path, '[[success]]\npredicate = "no_fall"\n', [(t / 10, 0.0, True) for t in range(51)]) == (True, "", 5.0)
    assert judged(tmp_path, '[[success]]\npredicate = "no_fall"\nwithin_s = 1.0\n', [(t / 10, 0.0, t < 12) for t in range(51)]) == (True, "", 5.0)


# -------------------------------------------------------------------------- seeds and intervals
def test_run_seeds_are_stable_and_differ_between_runs_and_scenarios() -> None:
    assert run_seed(0, "find the ball", 0) == 718630365  # the same on every machine: the rows of a CI run can be redone
    seeds = {run_seed(base, name, run) for base in (0, 1) for name in ("a", "b") for run in range(50)}
    assert len(seeds) == 200 and all(0 <= s < 2**31 for s in seeds)


@given(st.integers(0, 2**31 - 1))
def test_perturbed_starts_stay_within_the_files_spreads(seed: int) -> None:
    scenario = load_scenario(REPO / "config" / "scenarios" / "find_ball.toml")
    start = perturbed_start(scenario, seed)
    p = scenario.perturbation
    assert abs(start.robot[0] - scenario.robot_start[0]) <= p.robot_x_mm and abs(start.robot[1] - scenario.robot_start[1]) <= p.robot_y_mm
    assert abs(math.degrees(start.robot[2]) - scenario.robot_start[2]) <= p.robot_rotation_deg + 1e-9
    assert abs(start.ball[0] - scenario.ball[0]) <= p.ball_x_mm and p.sensor_noise[0] <= start.sensor_noise <= p.sensor_noise[1]
    assert perturbed_start(scenario, seed) == start


def test_wilson_intervals_match_the_published_values() -> None:
    assert wilson_interval(0, 10) == pytest.approx((0.0, 0.2775), abs=1e-4)
    assert wilson_interval(10, 10) == pytest.approx((0.7225, 1.0), abs=1e-4)
    assert wilson_interval(8, 10) == pytest.approx((0.4902, 0.9433), abs=1e-4)


@given(st.integers(1, 500).flatmap(lambda n: st.tuples(st.integers(0, n), st.just(n))))
def test_the_interval_holds_the_observed_rate(counts: tuple[int, int]) -> None:
    successes, runs = counts
    low, high = wilson_interval(successes, runs)
    assert 0.0 <= low <= successes / runs <= high <= 1.0


def test_a_rate_below_the_requirement_fails_the_summary(tmp_path: Path) -> None:
    scenario = load_scenario(write(tmp_path, GOOD))  # requires 0.5
    rows = [{"scenario": "small", "success": s, "time_to_success_s": 1.0} for s in (True, False, False)]
    table, passed = summarize([scenario], rows)
    assert not passed and table[0]["rate"] == pytest.approx(1 / 3) and table[0]["successes"] == 1
    assert summarize([scenario], rows[:2])[1]


# ------------------------------------------------------------------------------- worker death
def crash_once(marker: str) -> dict[str, Any]:
    """A job whose first worker dies (as one killed by the kernel would); it succeeds on the next."""
    path = Path(marker)
    if not path.exists():
        path.write_text("died once")
        os._exit(9)
    return {"success": True, "pid": os.getpid()}


@pytest.mark.slow  # worker processes / a subprocess: end to end
def test_a_job_whose_worker_dies_runs_again_and_is_reported_once(tmp_path: Path) -> None:
    markers = [str(tmp_path / f"job{i}") for i in range(4)]
    reported: list[int] = []
    info = BatchInfo()
    rows = run_jobs(crash_once, markers, workers=2, on_result=lambda index, row: reported.append(index), info=info)
    assert [r["success"] for r in rows] == [True] * 4
    assert sorted(reported) == [0, 1, 2, 3]  # each once
    assert info.retried >= 1 and all(Path(m).exists() for m in markers)


# ------------------------------------------------------------------------------------ end to end
SUCCEEDS = """\
name = "finds the ball beside it"
duration_s = 6.0
required_success_rate = 1.0

[[robots]]
start = [0.0, 0.0, 0.0]

[ball]
position = [800.0, 900.0]  # 48 degrees to the left: out of the cameras' view until the head turns

[perturbation]
robot_rotation_deg = 5.0
ball_x_mm = 100.0

[[success]]
predicate = "ball_model_accurate"
within_mm = 250.0
within_s = 6.0
"""
FAILS = """\
name = "a goal from the centre in one second"
duration_s = 1.0
required_success_rate = 0.5

[[robots]]
start = [0.0, 0.0, 0.0]

[ball]
position = [300.0, 0.0]

[[success]]
predicate = "ball_in_goal"
"""


def rows_of(path: Path) -> list[dict[str, str]]:
    with path.open() as f:
        return list(csv.DictReader(f))


@pytest.mark.slow
def test_success_and_failure_are_detected_and_a_failed_run_keeps_a_replayable_log(tmp_path: Path) -> None:
    files = [write(tmp_path, SUCCEEDS, "succeeds.toml"), write(tmp_path, FAILS, "fails.toml")]
    done = tafel("scenarios", "run", *map(str, files), "--repeat", "2", "--seed", "3", "--workers", "2",
                 "--out", str(tmp_path / "runs.csv"), "--artifacts", str(tmp_path / "logs"), cwd=tmp_path)
    assert done.returncode == 1, done.stdout + done.stderr  # the second scenario is below its requirement
    rows = rows_of(tmp_path / "runs.csv")
    assert [(r["scenario"], r["run"], r["success"]) for r in rows] == [
        ("finds the ball beside it", "0", "True"), ("finds the ball beside it", "1", "True"),
        ("a goal from the centre in one second", "0", "False"), ("a goal from the centre in one second", "1", "False")]
    assert all(0.1 < float(r["time_to_success_s"]) <= 6.0 for r in rows[:2]) and all(r["log"] == "" for r in rows[:2])
    for row in rows[2:]:
        assert row["reason"] == "ball_in_goal(goal=opponent) did not hold within 1 s"
        assert float(row["sim_s"]) == pytest.approx(1.0, abs=0.011)
        with LogReader(row["log"]) as log:  # kept, readable, and holding what a replay needs
            assert {"motion/JointSensorData", "cognition/CameraImageTop", "cognition/BallModel"} <= set(log.channels)
    assert "finds the ball beside it                 2    100%" in done.stdout and "BELOW" in done.stdout
    replay = tafel("run", "--platform", "log", "--log", rows[2]["log"], "--speed", "max", "--no-debug", cwd=tmp_path, timeout=120)
    assert replay.returncode == 0, replay.stderr


@pytest.mark.slow
def test_without_a_shared_folder_a_failed_runs_log_travels_back_with_its_row(tmp_path: Path) -> None:
    """What a Ray cluster's worker does when the caller gave no --artifacts: the log comes back as bytes."""
    from tafel.tools.simulation.scenarios import Job, run_job

    scenario = load_scenario(write(tmp_path, FAILS))
    row = run_job(Job(scenario, 0, 5, artifacts=None))
    assert row["success"] is False and row["log"] == "scenario-run0-seed5.mcap"
    (tmp_path / "back.mcap").write_bytes(row["log_bytes"])
    with LogReader(tmp_path / "back.mcap") as log:
        assert "cognition/BallModel" in log.channels


def comparable(rows: list[dict[str, Any]]) -> list[tuple]:
    """What must not depend on where a run ran: everything but wall time and the log's path."""
    return [tuple(v for k, v in sorted(r.items()) if k not in ("wall_s", "log")) for r in rows]


@pytest.mark.slow
def test_the_same_seeds_give_the_same_rows_with_one_worker_two_workers_and_ray(tmp_path: Path) -> None:
    path = REPO / "config" / "scenarios" / "find_ball.toml"  # perturbed start, sensor noise, turning to find the ball
    results = {}
    where = [("one", ["--workers", "1"]), ("two", ["--workers", "2"])]
    try:
        import ray  # noqa: F401

        where.append(("ray", ["--ray", "--workers", "2"]))
    except ImportError:
        pass
    for name, option in where:
        out = tmp_path / f"{name}.jsonl"
        done = tafel("scenarios", "run", str(path), "--repeat", "2", "--seed", "11", *option, "--out", str(out), "--no-logs", cwd=tmp_path)
        assert done.returncode == 0, done.stdout + done.stderr
        results[name] = [json.loads(line) for line in out.read_text().splitlines()]
    assert len(results["one"]) == 2 and len({r["seed"] for r in results["one"]}) == 2
    assert len({r["sensor_noise"] for r in results["one"]}) == 2  # the runs really differ
    for name in results:
        assert comparable(results[name]) == comparable(results["one"]), name
    if "ray" not in results:
        pytest.skip("the ray extra is not installed (pip install -e '.[ray]'): 1 and 2 workers agreed, Ray was not tried")


@pytest.mark.slow
def test_ray_runs_a_batch_on_a_local_instance_with_two_cpus(tmp_path: Path) -> None:
    pytest.importorskip("ray", reason="the ray extra is not installed (pip install -e '.[ray]')")
    markers = [str(tmp_path / f"job{i}") for i in range(3)]
    info = BatchInfo()
    rows = run_jobs(crash_once, markers, workers=2, ray="local", info=info)
    assert [r["success"] for r in rows] == [True] * 3  # each worker died once; Ray ran the task again
    assert info.where == "ray (local)" and info.workers == 2


@pytest.mark.slow
def test_the_striker_scores_from_its_own_half_in_three_of_four_perturbed_runs(tmp_path: Path) -> None:
    """The shipped scenario, judged by ground truth over four seeded starts anywhere in the own half (two
    rounds on two workers; the file's own requirement, 80 %, asks for a larger sample than a test can run)."""
    shipped = (REPO / "config" / "scenarios" / "striker_scores.toml").read_text()
    assert "required_success_rate = 0.8" in shipped
    path = write(tmp_path, shipped.replace("required_success_rate = 0.8", "required_success_rate = 0.75"), "striker_scores.toml")
    done = tafel("scenarios", "run", str(path), "--repeat", "4", "--seed", "17", "--workers", "2",
                 "--out", str(tmp_path / "runs.csv"), "--artifacts", str(tmp_path / "logs"), cwd=tmp_path)
    rows = rows_of(tmp_path / "runs.csv")
    assert done.returncode == 0, done.stdout[-3000:] + done.stderr[-3000:]
    assert sum(r["success"] == "True" for r in rows) >= 3, rows


LOCALIZED_IN_THE_OPPONENT_HALF = """
duration_s = 3.0
required_success_rate = 1.0
cameras = {cameras}

[[robots]]
start = [2400.0, 0.0, 0.0]
told_pose = {told}

[ball]
position = [3000.0, 0.0]

[[success]]
predicate = "representation"
name = "RobotPose"
field = "x"
at_least = 1800.0
after_s = 1.0
for_s = 1.0

[[success]]
predicate = "representation"
name = "RobotPose"
field = "valid"
equals = true
after_s = 1.0
for_s = 1.0
"""


@pytest.mark.slow
@pytest.mark.parametrize(("told", "cameras"), [("true", "true"), ("false", "false")])
def test_a_robot_started_in_the_opponent_half_knows_where_it_is_only_when_told(tmp_path: Path, told: str, cameras: str) -> None:
    """The rules never place a robot in the opponent half in PLAYING, so one started there is taken for its
    twin in the own half unless the scenario tells it the start (``told_pose``), as kick_to_goal does."""
    scenario = load_scenario(write(tmp_path, LOCALIZED_IN_THE_OPPONENT_HALF.format(told=told, cameras=cameras)))
    assert scenario.told_pose is (told == "true")
    row = play(scenario, 1)
    assert row["success"] is (told == "true"), row["reason"]


def test_told_pose_is_true_or_false(tmp_path: Path) -> None:
    text = GOOD.replace("start = [0.0, 0.0, 0.0]", "start = [0.0, 0.0, 0.0]\ntold_pose = 1")
    with pytest.raises(ScenarioError, match="told_pose"):
        load_scenario(write(tmp_path, text))
    assert load_scenario(write(tmp_path, GOOD)).told_pose is False
    assert load_scenario(REPO / "config" / "scenarios" / "kick_to_goal.toml").told_pose is True
