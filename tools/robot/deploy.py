"""``tafel robots`` and ``tafel deploy ROBOT``: put the program on a robot in one command.

The robots are the ``[[robots]]`` tables of ``robots.toml`` in the configuration (the shipped folder,
then ``--config DIR``; a later table of the same name replaces an earlier one). A deploy:

1. builds what the robot needs in a local staging folder: the ``tafel`` wheel (reproducible: the same
   source gives the same bytes), the wheels of its dependencies for the robot's Python and processor
   (``dependencies = "wheels"``; a robot whose ``python`` has them already says ``"robot"``), the
   configuration layers (``general.toml``, ``platform/``, the robot's ``robot/NAME.toml``, motions),
   a ``RELEASE`` file naming the build by its content's hash, and ``deploy_robot.sh``;
2. copies only what changed with rsync over SSH (the user's own SSH configuration: keys, jump hosts);
3. runs ``deploy_robot.sh`` on the robot, which installs the release into ``TARGET/releases/ID`` (a
   virtual environment), checks that it imports, points ``TARGET/current`` at it and (re)starts the
   program: a systemd user service, or a plain background process. A release that fails to install or
   to start is rolled back: the robot keeps the version it had.

Every failure (a robot that does not answer, a full disk, a failed start) is a ``DeployError`` whose
message says what happened on which robot; the command exits with status 1.
"""

from __future__ import annotations

import argparse
import hashlib
import os
import shlex
import shutil
import subprocess
import sys
import time
import tomllib
from collections.abc import Sequence
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from importlib import metadata
from pathlib import Path
from typing import Any, Literal

from tafel.core.framework.values import Range, convert, refusal

#: the shipped configuration (the repository's config/ folder)
REPOSITORY = Path(__file__).resolve().parents[2]  # tools/robot/deploy.py: the project, what the wheel is built from
DEFAULT_CONFIG = REPOSITORY / "config"
ROBOT_SCRIPT = Path(__file__).resolve().parent / "deploy_robot.sh"
#: dependencies a robot never needs: the simulators (PyBullet has no wheels for any robot anyway)
SIMULATOR_DEPENDENCIES = frozenset({"mujoco", "pybullet"})
#: s to wait for a robot's SSH answer
CONNECT_TIMEOUT_S = 5
#: configuration a robot gets; private layers stay on the developer's machine
CONFIG_PARTS = ("general.toml", "platform", "motions")


class DeployError(Exception):
    """A deploy or a look at the robots that failed; the message names the robot and what went wrong."""


@dataclass(frozen=True)
class Robot:
    """One ``[[robots]]`` table of ``robots.toml``."""

    name: str
    address: str
    port: int = 22
    user: str = "nao"
    target: str = "/home/nao/tafel"
    player: int = 0
    team: int = 0
    #: the robot's Python (it makes the virtual environment)
    python: str = "python3"
    #: "wheels": ship the dependencies' wheels; "robot": use the packages the robot's ``python`` has
    dependencies: str = "wheels"
    #: "systemd" (a user service) or "process" (a background process with a pid file)
    service: str = "systemd"
    #: the program the service runs, as arguments of ``tafel``
    command: str = "run --platform nao"
    #: s a ``run`` program may take to report that each of its contexts ran a frame (``--ready-file``;
    #: under systemd ``READY=1``) before its start counts as failed
    start_timeout_s: float = 120.0
    #: s the program must go on living after that report (other commands than ``run``: after their start)
    start_check_s: float = 3.0
    #: MB the robot must have free beyond what a release needs
    min_free_mb: int = 50

    @property
    def destination(self) -> str:
        return f"{self.user}@{self.address}"


#: what each key of a ``[[robots]]`` table takes: (type, range, what would be right in words or None for the type's)
ROBOT_KEYS: dict[str, tuple[Any, Range | None, str | None]] = {
    "name": (str, None, "a robot's name (text, not empty)"), "address": (str, None, "a host name or IP address (text, not empty)"),
    "port": (int, Range(1, 65535), "an SSH port from 1 to 65535"), "user": (str, None, None), "target": (str, None, None),
    "player": (int, Range(0, 20), "a player number from 1 to 20, or 0 for none"),
    "team": (int, Range(0, 254), "a team number from 1 to 254, or 0 for none"), "python": (str, None, None),
    "dependencies": (Literal["wheels", "robot"], None, None), "service": (Literal["systemd", "process"], None, None),
    "command": (str, None, None), "start_timeout_s": (float, Range(0.0, low_open=True), None),
    "start_check_s": (float, Range(0.0, low_open=True), None), "min_free_mb": (int, Range(0), None),
}


def load_robots(config_dirs: Sequence[Path]) -> dict[str, Robot]:
    """The robots of every layer's ``robots.toml``, by name; a wrong key or value is a ``DeployError``."""
    robots: dict[str, Robot] = {}
    for folder in config_dirs:
        path = folder / "robots.toml"
        if not path.is_file():
            continue
        try:
            tables = tomllib.loads(path.read_text()).get("robots", [])
        except (tomllib.TOMLDecodeError, OSError) as exc:
            raise DeployError(f"{path}: {exc}") from None
        convert(tables, list[dict[str, Any]], where=f"{path}: robots", text=False, expected="[[robots]] tables", error=DeployError)
        for index, table in enumerate(tables):
            where = f"{path}: robot {index + 1}"
            unknown = sorted(set(table) - set(ROBOT_KEYS))
            if unknown:
                raise DeployError(f"{where}: unknown keys {', '.join(unknown)}; a robot knows {', '.join(ROBOT_KEYS)}")
            for required in ("name", "address"):
                if required not in table:
                    raise DeployError(f"{where}: '{required}' is required ({ROBOT_KEYS[required][2]})")
            values = {key: convert(table[key], kind, where=f"{where}: {key}", bounds=bounds, text=False, expected=expected,
                                   error=DeployError) for key, (kind, bounds, expected) in ROBOT_KEYS.items() if key in table}
            for required in ("name", "address"):
                if not values[required]:
                    raise refusal(f"{where}: {required}", str(ROBOT_KEYS[required][2]), values[required], DeployError)
            robot = Robot(**values)
            robots[robot.name] = robot
    return robots


# ------------------------------------------------------------------------------------------ transport
def ssh_command(robot: Robot, ssh_config: Path | None) -> list[str]:
    """``ssh`` with the user's configuration, never asking for a password (a deploy runs unattended)."""
    options = ["-p", str(robot.port), "-o", "BatchMode=yes", "-o", f"ConnectTimeout={CONNECT_TIMEOUT_S}"]
    return ["ssh", *(["-F", str(ssh_config)] if ssh_config else []), *options]


def on_robot(robot: Robot, ssh_config: Path | None, script: str, timeout: float = 600) -> subprocess.CompletedProcess:
    """Run a shell ``script`` on the robot; a robot that does not answer is a ``DeployError``."""
    try:
        result = subprocess.run([*ssh_command(robot, ssh_config), robot.destination, script], capture_output=True, text=True,
                                timeout=timeout, stdin=subprocess.DEVNULL)
    except subprocess.TimeoutExpired:
        raise DeployError(f"{robot.name} ({robot.destination}:{robot.port}) did not finish within {timeout:g} s") from None
    if result.returncode == 255:  # ssh's own failure: no route, refused, no key
        raise DeployError(f"{robot.name} ({robot.destination}:{robot.port}) does not answer: {last_line(result.stderr)}")
    return result


def last_line(text: str) -> str:
    """The line that says most: ssh's own complaint where there is one, else the last line."""
    lines = [line for line in text.strip().splitlines() if line.strip()]
    complaints = [line for line in lines if line.startswith("ssh:")]
    return (complaints or lines or ["(no message)"])[-1]


# ------------------------------------------------------------------------------------------ building
def stage_release(robot: Robot, config_dirs: Sequence[Path], staging: Path, robot_python: tuple[str, str] | None) -> str:
    """Fill ``staging`` with what the robot needs; returns the release's id (its content's hash)."""
    for part in ("config", "wheels"):
        (staging / part).mkdir(parents=True, exist_ok=True)
    build_wheel(staging / "wheels")
    if robot.dependencies == "wheels":
        assert robot_python is not None
        download_dependencies(staging / "wheels", *robot_python)
    shutil.rmtree(staging / "config")
    (staging / "config").mkdir()
    for folder in config_dirs:
        for part in CONFIG_PARTS:
            source = folder / part
            if source.is_dir():
                shutil.copytree(source, staging / "config" / part, dirs_exist_ok=True)
            elif source.is_file():
                shutil.copy2(source, staging / "config" / part)
        robot_layer = folder / "robot" / f"{robot.name}.toml"
        if robot_layer.is_file():
            (staging / "config" / "robot").mkdir(exist_ok=True)
            shutil.copy2(robot_layer, staging / "config" / "robot" / robot_layer.name)
    shutil.copy2(ROBOT_SCRIPT, staging / ROBOT_SCRIPT.name)
    digest = hashlib.sha256()
    for path in sorted(p for p in staging.rglob("*") if p.is_file() and p.name != "RELEASE"):
        digest.update(str(path.relative_to(staging)).encode())
        digest.update(path.read_bytes())
    release = f"{metadata.version('tafel')}-{digest.hexdigest()[:12]}"
    (staging / "RELEASE").write_text(release + "\n")
    return release


def build_wheel(wheels: Path) -> None:
    """The ``tafel`` wheel, built reproducibly (fixed timestamps), replacing the last one."""
    for old in wheels.glob("tafel-*.whl"):
        old.unlink()
    env = {**os.environ, "SOURCE_DATE_EPOCH": "315532800"}
    result = subprocess.run([sys.executable, "-m", "pip", "wheel", "--no-deps", "-q", "-w", str(wheels),
                             str(REPOSITORY)], capture_output=True, text=True, env=env)
    if result.returncode != 0:
        raise DeployError(f"cannot build the tafel wheel: {last_line(result.stderr)}")


def robot_requirements() -> list[str]:
    """tafel's run-time dependencies without the simulators."""
    requirements = []
    for requirement in metadata.requires("tafel") or []:
        if "extra ==" in requirement:
            continue
        name = requirement.split(";")[0].strip()
        if name.split(">")[0].split("=")[0].split("<")[0].strip().lower() not in SIMULATOR_DEPENDENCIES:
            requirements.append(name)
    return requirements


def download_dependencies(wheels: Path, python_version: str, platform_tag: str) -> None:
    """Wheels of the dependencies for the robot's Python and processor (kept between deploys)."""
    result = subprocess.run([sys.executable, "-m", "pip", "download", "-q", "--only-binary=:all:", "--python-version", python_version,
                             "--platform", platform_tag, "-d", str(wheels), *robot_requirements()], capture_output=True, text=True)
    if result.returncode != 0:
        raise DeployError(f"cannot fetch the dependencies for Python {python_version} on {platform_tag}: {last_line(result.stderr)}")


def robot_python(robot: Robot, ssh_config: Path | None) -> tuple[str, str]:
    """The robot's Python version (``3.11``) and the wheel platform tag it accepts."""
    probe = (f"{shlex.quote(robot.python)} -c 'import sys, sysconfig; "
             "print(\"%d.%d\" % sys.version_info[:2], sysconfig.get_platform())'")
    result = on_robot(robot, ssh_config, probe, timeout=30)
    try:
        version, platform = result.stdout.split()
    except ValueError:
        raise DeployError(f"{robot.name}: cannot run {robot.python} there: {last_line(result.stderr)}") from None
    return version, "manylinux2014_" + platform.split("-")[-1].replace("-", "_")


def copy(robot: Robot, ssh_config: Path | None, staging: Path, dry_run: bool) -> list[str]:
    """rsync the staging folder to ``TARGET/stage``: only what changed. Returns the files it copied (or would)."""
    shell = " ".join(shlex.quote(part) for part in ssh_command(robot, ssh_config))
    command = ["rsync", "-rlt", "--checksum", "--delete", "--itemize-changes", "--mkpath", "-e", shell,
               *(["--dry-run"] if dry_run else []), f"{staging}/", f"{robot.destination}:{robot.target}/stage/"]
    result = subprocess.run(command, capture_output=True, text=True, stdin=subprocess.DEVNULL)
    if result.returncode == 255 or "Connection" in result.stderr and result.returncode != 0:
        raise DeployError(f"{robot.name} ({robot.destination}:{robot.port}) does not answer: {last_line(result.stderr)}")
    if "No space left" in result.stderr:
        raise DeployError(f"{robot.name}: the robot's disk is full; nothing was installed ({last_line(result.stderr)})")
    if result.returncode != 0:
        raise DeployError(f"{robot.name}: copying failed: {last_line(result.stderr)}")
    return [line.split(" ", 1)[1] for line in result.stdout.splitlines() if line[:2] in ("<f", ">f") and " " in line]


# ------------------------------------------------------------------------------------------ commands
def command_deploy(args: argparse.Namespace) -> int:
    robots = load_robots([DEFAULT_CONFIG, *([args.config] if args.config else [])])
    if args.robot not in robots:
        from tafel.core.framework.naming import did_you_mean

        known = ", ".join(robots) or "none (add [[robots]] tables to robots.toml in your --config folder)"
        print(f"tafel deploy: error: no robot named {args.robot!r}; {did_you_mean(args.robot, robots)}; robots: {known}", file=sys.stderr)
        return 2
    robot = robots[args.robot]
    config_dirs = [DEFAULT_CONFIG, *([args.config] if args.config else [])]
    staging = Path(args.staging or Path.home() / ".cache" / "tafel" / "deploy" / robot.name)
    started = time.monotonic()
    try:
        on_robot(robot, args.ssh_config, "true", timeout=CONNECT_TIMEOUT_S + 10)  # answers at all?
        python = robot_python(robot, args.ssh_config) if robot.dependencies == "wheels" else None
        release = stage_release(robot, config_dirs, staging, python)
        copied = copy(robot, args.ssh_config, staging, args.dry_run)
        if args.dry_run:
            print(f"{robot.name}: would copy {len(copied)} files to {robot.destination}:{robot.target}/stage/")
            for name in copied:
                print(f"  {name}")
            print(f"{robot.name}: would install release {release} and (re)start: tafel {robot.command}")
            return 0
        result = on_robot(robot, args.ssh_config, install_script(robot))
    except DeployError as exc:
        print(f"tafel deploy: error: {exc}", file=sys.stderr)
        return 1
    for line in result.stdout.splitlines():
        print(f"{robot.name}: {line}")
    if result.returncode != 0:
        reason = last_line(result.stderr)
        for line in result.stderr.strip().splitlines():  # what led there: the program's last lines, a failed install
            if line.strip() and line != reason:
                print(f"{robot.name}: {line}", file=sys.stderr)
        print(f"tafel deploy: error: {robot.name}: {reason}", file=sys.stderr)
        return 1
    print(f"{robot.name}: release {release} runs ({len(copied)} files copied, {time.monotonic() - started:.1f} s)")
    return 0


def install_script(robot: Robot) -> str:
    """The command line that runs ``deploy_robot.sh`` on the robot with the robot's settings."""
    settings = {"TARGET": robot.target, "PYTHON": robot.python, "DEPENDENCIES": robot.dependencies, "SERVICE": robot.service,
                "COMMAND": robot.command, "START_TIMEOUT_S": f"{robot.start_timeout_s:g}", "START_CHECK_S": f"{robot.start_check_s:g}", "MIN_FREE_MB": str(robot.min_free_mb)}
    assignments = " ".join(f"{key}={shlex.quote(value)}" for key, value in settings.items())
    return f"{assignments} sh {shlex.quote(robot.target + '/stage/' + ROBOT_SCRIPT.name)}"


def command_robots(args: argparse.Namespace) -> int:
    try:
        robots = load_robots([DEFAULT_CONFIG, *([args.config] if args.config else [])])
    except DeployError as exc:
        print(f"tafel robots: error: {exc}", file=sys.stderr)
        return 2
    if not robots:
        print("no robots: add [[robots]] tables (name, address) to robots.toml in your --config folder")
        return 0

    def look(robot: Robot) -> str:
        try:
            result = on_robot(robot, args.ssh_config, f"cat {shlex.quote(robot.target)}/current/RELEASE 2>/dev/null || echo none",
                              timeout=CONNECT_TIMEOUT_S + 5)
        except DeployError as exc:
            return f"does not answer ({str(exc).split(': ', 1)[-1]})"
        release = result.stdout.strip() or "none"
        return "answers, runs no tafel release" if release == "none" else f"answers, release {release}"

    with ThreadPoolExecutor(max_workers=min(16, len(robots))) as pool:
        answers = list(pool.map(look, robots.values()))
    for robot, answer in zip(robots.values(), answers):
        who = f"player {robot.player} of team {robot.team}" if robot.player else "no player number"
        print(f"{robot.name:12} {robot.destination}:{robot.port} {robot.target} ({who}): {answer}")
    return 0


def run_command(args: argparse.Namespace) -> int:
    """Entry point of both subcommands (``args.command`` says which)."""
    return command_deploy(args) if args.command == "deploy" else command_robots(args)

