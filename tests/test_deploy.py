"""``tafel deploy`` and ``tafel robots`` against a real SSH server on loopback, installing into a
temporary folder as the robot: dry run, first and second deploy, a failed start that rolls back, a
robot that does not answer, a full disk."""

from __future__ import annotations

import os
import re
import signal
import subprocess
import sys
import time
from collections.abc import Iterator
from pathlib import Path

import pytest

from tafel.tools.robot.deploy import DeployError, load_robots
from tests.support.ssh_server import SshServer, free_port, missing
from tests.test_cli_runtime import REPO, TAFEL

pytestmark = pytest.mark.skipif(bool(missing()), reason=missing() or "ssh tools present")


def robots_toml(server: SshServer, robot_folder: Path, **extra: object) -> str:
    settings = {"name": "robo", "address": "127.0.0.1", "port": server.port, "user": server.user, "target": str(robot_folder),
                "player": 3, "team": 5, "python": sys.executable, "dependencies": "robot", "service": "process",
                "command": "run --platform dummy --no-debug --status-interval 60", "start_check_s": 2.0, **extra}
    lines = ["[[robots]]"] + [f"{key} = {value!r}" if not isinstance(value, str) else f'{key} = "{value}"' for key, value in settings.items()]
    return "\n".join(lines) + "\n"


def tafel(*args: str, timeout: float = 300) -> subprocess.CompletedProcess:
    return subprocess.run([*TAFEL, *args], capture_output=True, text=True, timeout=timeout, cwd=REPO,
                          env={**os.environ, "PYTHONPATH": str(REPO)})


@pytest.fixture(scope="module")
def robot(tmp_path_factory: pytest.TempPathFactory) -> Iterator[dict[str, Path | SshServer]]:
    base = tmp_path_factory.mktemp("deploy")
    server = SshServer(base / "sshd")
    config = base / "config"
    config.mkdir()
    (config / "robots.toml").write_text(robots_toml(server, base / "robot"))
    things = {"server": server, "config": config, "target": base / "robot", "staging": base / "staging"}
    yield things
    pid = base / "robot" / "tafel.pid"
    if pid.exists():
        try:
            os.kill(int(pid.read_text()), 9)
        except (ProcessLookupError, ValueError):
            pass
    server.close()


def deploy(robot: dict, *extra: str) -> subprocess.CompletedProcess:
    return tafel("deploy", "robo", "--config", str(robot["config"]), "--ssh-config", str(robot["server"].config),
                 "--staging", str(robot["staging"]), *extra)


def running_pid(target: Path) -> int:
    pid = int((target / "tafel.pid").read_text())
    os.kill(pid, 0)  # raises when it is not running
    return pid


@pytest.mark.slow
def test_dry_run_first_and_second_deploy_and_the_robot_list(robot: dict) -> None:
    target: Path = robot["target"]
    dry = deploy(robot, "--dry-run")
    assert dry.returncode == 0, dry.stderr
    assert re.search(r"would copy \d+ files", dry.stdout) and "RELEASE" in dry.stdout and "tafel-0" in dry.stdout
    assert not (target / "current").exists()  # a dry run changes nothing

    started = time.monotonic()
    first = deploy(robot)
    first_s = time.monotonic() - started
    assert first.returncode == 0, first.stdout + first.stderr
    release = (target / "current" / "RELEASE").read_text().strip()
    assert f"release {release} runs" in first.stdout and "installed release" in first.stdout
    pid = running_pid(target)

    second = deploy(robot)
    assert second.returncode == 0, second.stdout + second.stderr
    copied = [int(re.search(r"\((\d+) files copied", run.stdout).group(1)) for run in (first, second)]
    # only what changed travels: the configuration and the script stay; at most the wheel and RELEASE
    # (the wheel is reproducible, so an unchanged source copies nothing at all)
    assert copied[1] <= 2 < copied[0], copied
    assert running_pid(target) != pid  # restarted
    print(f"first deploy {first_s:.1f} s")

    release = (target / "current" / "RELEASE").read_text().strip()
    listing = tafel("robots", "--config", str(robot["config"]), "--ssh-config", str(robot["server"].config))
    assert listing.returncode == 0, listing.stderr
    assert re.search(rf"robo .*player 3 of team 5.*answers, release {re.escape(release)}", listing.stdout), listing.stdout


@pytest.mark.slow
def test_a_release_that_fails_to_start_leaves_the_robot_on_the_one_it_had(robot: dict, tmp_path: Path) -> None:
    target: Path = robot["target"]
    if not (target / "current").exists():
        assert deploy(robot).returncode == 0
    before = (target / "current").resolve()
    broken = tmp_path / "broken"
    broken.mkdir()
    # the program must report its start: no timer decides, however short (this one is shorter than Python's start)
    (broken / "robots.toml").write_text(robots_toml(robot["server"], target, start_check_s=0.05))
    (broken / "general.toml").write_text("[runtime]\nmotion_hz = -5\n")  # the program refuses to start
    result = tafel("deploy", "robo", "--config", str(broken), "--ssh-config", str(robot["server"].config),
                   "--staging", str(tmp_path / "staging"))
    assert result.returncode == 1
    assert "failed to start; the robot runs" in result.stderr and "again" in result.stderr
    assert "motion_hz" in result.stderr  # the program's own words on why
    assert (target / "current").resolve() == before
    running_pid(target)  # the old release runs again


@pytest.mark.slow
def test_a_full_disk_is_a_clear_error_and_changes_nothing(robot: dict, tmp_path: Path) -> None:
    target: Path = robot["target"]
    full = tmp_path / "full"
    full.mkdir()
    (full / "robots.toml").write_text(robots_toml(robot["server"], target, min_free_mb=10**9))
    before = (target / "current").resolve() if (target / "current").exists() else None
    result = tafel("deploy", "robo", "--config", str(full), "--ssh-config", str(robot["server"].config), "--staging", str(tmp_path / "s"))
    assert result.returncode == 1
    assert "not enough space on the robot" in result.stderr
    assert ((target / "current").resolve() if (target / "current").exists() else None) == before


@pytest.mark.slow
def test_a_robot_that_does_not_answer_is_a_clear_error(tmp_path: Path) -> None:
    (tmp_path / "robots.toml").write_text(f'[[robots]]\nname = "gone"\naddress = "127.0.0.1"\nport = {free_port()}\n'
                                          'dependencies = "robot"\n')
    result = tafel("deploy", "gone", "--config", str(tmp_path), "--dry-run", "--staging", str(tmp_path / "s"))
    assert result.returncode == 1
    assert re.search(r"gone \(nao@127\.0\.0\.1:\d+\) does not answer: .*(refused|Connection)", result.stderr), result.stderr
    listing = tafel("robots", "--config", str(tmp_path))
    assert listing.returncode == 0 and "does not answer" in listing.stdout


@pytest.mark.parametrize(("text", "message"), [
    ('[[robots]]\nname = "a"\n', "'address' is required"),
    ('[[robots]]\nname = "a"\naddress = "x"\nprot = 22\n', "unknown keys prot"),
    ('[[robots]]\nname = "a"\naddress = "x"\nport = "22"\n', "robot 1: port takes an SSH port from 1 to 65535, got '22'"),
    ('[[robots]]\nname = "a"\naddress = "x"\nport = 70000\n', "robot 1: port takes an SSH port from 1 to 65535, got 70000"),
    ('[[robots]]\nname = "a"\naddress = "x"\nservice = "cron"\n', "robot 1: service takes one of systemd, process, got 'cron'"),
    ('[[robots]]\nname = "a"\naddress = "x"\ndependencies = "pip"\n', "robot 1: dependencies takes one of wheels, robot, got 'pip'"),
    ('[[robots]]\nname = "a"\naddress = ""\n', "robot 1: address takes a host name or IP address (text, not empty), got ''"),
    ('[[robots]]\nname = "a"\naddress = "x"\nstart_check_s = 0\n', "start_check_s takes a finite number above 0, got 0"),
    ('[[robots]]\nname = "a"\naddress = "x"\nplayer = 21\n', "player takes a player number from 1 to 20, or 0 for none, got 21"),
    ('robots = 5\n', "robots takes [[robots]] tables, got 5"),
    ('[[robots\n', "robots.toml"),
])
def test_bad_robot_tables_are_clear_errors(tmp_path: Path, text: str, message: str) -> None:
    (tmp_path / "robots.toml").write_text(text)
    with pytest.raises(DeployError, match=re.escape(message)):
        load_robots([tmp_path])


@pytest.mark.slow
def test_under_systemd_the_start_counts_when_the_program_reports_it_and_a_failed_one_rolls_back(robot: dict, tmp_path: Path) -> None:
    """The robot's script with ``service = "systemd"`` against a stand-in ``systemctl`` that starts a
    ``Type=notify`` unit as systemd does (no systemd runs here), on the release the deploys above installed."""
    target: Path = robot["target"]
    if not (target / "current").exists():
        assert deploy(robot).returncode == 0
    pid = target / "tafel.pid"
    if pid.exists():  # the process-mode program of the tests above
        os.kill(int(pid.read_text()), signal.SIGKILL)
        pid.unlink()
    fake = tmp_path / "bin"
    fake.mkdir()
    (fake / "systemctl").write_text(f'#!/bin/sh\nexec {sys.executable} {REPO / "tests/support/fake_systemctl.py"} "$@"\n')
    (fake / "systemctl").chmod(0o755)
    unit = tmp_path / "home/.config/systemd/user/tafel.service"
    good = "run --platform dummy --no-debug --status-interval 60"

    def script(command: str) -> subprocess.CompletedProcess:
        settings = {"TARGET": str(target), "PYTHON": sys.executable, "DEPENDENCIES": "robot", "SERVICE": "systemd",
                    "COMMAND": command, "START_TIMEOUT_S": "60", "START_CHECK_S": "0.05", "MIN_FREE_MB": "0",
                    "HOME": str(tmp_path / "home"), "PATH": f"{fake}:{os.environ['PATH']}"}
        return subprocess.run(["sh", str(target / "stage/deploy_robot.sh")], capture_output=True, text=True, timeout=180,
                              env={**os.environ, **settings})

    def active() -> bool:
        return subprocess.run([str(fake / "systemctl"), "--user", "is-active", "--quiet", "tafel.service"],
                              env={**os.environ, "HOME": str(tmp_path / "home")}).returncode == 0

    try:
        started = script(good)
        assert started.returncode == 0, started.stdout + started.stderr
        assert "running release" in started.stdout
        assert "Type=notify" in unit.read_text() and f"--ready-file {target}/tafel.ready" in unit.read_text()
        assert active()
        broken = script(good + " --set runtime.motion_hz=-5")  # refuses to start: never reports
        assert broken.returncode == 1
        assert "failed to start; the robot runs" in broken.stderr and "again" in broken.stderr
        assert "Type=simple" in unit.read_text() and "motion_hz" not in unit.read_text()  # the one it had
        assert active()
    finally:
        subprocess.run([str(fake / "systemctl"), "--user", "stop", "tafel.service"], env={**os.environ, "HOME": str(tmp_path / "home")})
