"""The package installs anywhere: one import name, the configuration inside, no source tree needed."""

from __future__ import annotations

import os
import subprocess
import sys
import sysconfig
import tomllib
import urllib.request
import venv
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parent.parent
PACKAGE_FOLDERS = ("core", "debug", "modules", "platforms", "representations", "tools")


def test_every_package_folder_is_listed_in_pyproject() -> None:
    listed = set(tomllib.loads((REPO / "pyproject.toml").read_text())["tool"]["setuptools"]["packages"])
    found = {
        "tafel." + str(init.parent.relative_to(REPO)).replace(os.sep, ".")
        for top in PACKAGE_FOLDERS for init in (REPO / top).rglob("__init__.py")
    }
    assert found, "no package folders found"
    missing = found - listed
    assert not missing, f"add these to [tool.setuptools] packages in pyproject.toml: {sorted(missing)}"
    assert "tafel.config" in listed


def test_the_project_owns_one_import_name() -> None:
    import tafel.core
    import tafel.modules.motion.kinematics as kinematics

    assert callable(kinematics.link_poses) and callable(kinematics.sole_in_torso)
    assert callable(tafel.core.serialize) and callable(tafel.core.deserialize) and callable(tafel.core.representation)
    offenders = []
    for path in REPO.glob("*/**/*.py"):
        if path.parts[len(REPO.parts)] in {".venv", "build", ".git"}:
            continue
        for number, line in enumerate(path.read_text().splitlines(), start=1):
            stripped = line.strip()
            for top in PACKAGE_FOLDERS:
                if stripped.startswith((f"from {top}.", f"from {top} import", f"import {top}")) and not stripped.startswith(f"import {top}_"):
                    offenders.append(f"{path.relative_to(REPO)}:{number}: {stripped}")
    assert not offenders, "imports without the tafel prefix:\n" + "\n".join(offenders)


@pytest.mark.slow
def test_a_built_wheel_runs_from_anywhere(tmp_path: Path) -> None:
    """Build the wheel, install it into a fresh virtualenv that cannot see the source tree, run it."""
    wheels = tmp_path / "wheels"
    subprocess.run([sys.executable, "-m", "pip", "wheel", "--no-deps", "-q", "-w", str(wheels), str(REPO)],
                   check=True, capture_output=True, timeout=300)
    wheel = next(wheels.glob("tafel-*.whl"))
    env_dir = tmp_path / "env"
    venv.create(env_dir, with_pip=False)
    python = env_dir / "bin" / "python"
    site = subprocess.run([str(python), "-c", "import sysconfig; print(sysconfig.get_paths()['purelib'])"],
                          check=True, capture_output=True, text=True).stdout.strip()
    # The dependencies come from this interpreter's site-packages as a plain path entry: its .pth files
    # (among them the editable install's finder) are not processed, so the source tree stays out of reach.
    Path(site, "deps.pth").write_text(sysconfig.get_paths()["purelib"] + "\n")
    subprocess.run([sys.executable, "-m", "pip", "--python", str(python), "install", "--no-deps", "-q", str(wheel)],
                   check=True, capture_output=True, timeout=300)
    work = tmp_path / "elsewhere"
    work.mkdir()
    env = {k: v for k, v in os.environ.items() if k not in {"PYTHONPATH", "VIRTUAL_ENV"}}
    env["PATH"] = f"{env_dir / 'bin'}:{env['PATH']}"
    where = subprocess.run([str(python), "-c", "import tafel.core, tafel.tools.cli, tafel.tools.launch.defaults as d; print(tafel.core.__file__); print(d.DEFAULT_CONFIG)"],
                           cwd=work, env=env, check=True, capture_output=True, text=True).stdout.split()
    assert all(str(REPO) not in line for line in where), f"the installed package resolves into the source tree: {where}"
    assert Path(where[1], "general.toml").is_file(), "the default configuration does not ship inside the package"
    assert Path(where[1], "foxglove", "tafel-layout.json").is_file(), "the Foxglove layout does not ship inside the package"
    tafel = str(env_dir / "bin" / "tafel")
    run = subprocess.run([tafel, "run", "--platform", "dummy", "--seconds", "2", "--speed", "max", "--no-debug",
                          "--record", "run.mcap"], cwd=work, env=env, capture_output=True, text=True, timeout=120)
    assert run.returncode == 0, run.stderr
    assert "motion: 200 frames" in run.stdout
    info = subprocess.run([tafel, "log", "info", "run.mcap"], cwd=work, env=env, capture_output=True, text=True, timeout=60)
    assert info.returncode == 0, info.stderr
    assert "motion/JointSensorData" in info.stdout
    # the web page and its vendored libraries ship too
    served = subprocess.Popen([tafel, "run", "--platform", "dummy", "--seconds", "20", "--debug-port", "0", "--web-port", "0"],
                              cwd=work, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        url = ""
        for line in served.stdout:
            if line.startswith("web view at "):
                url = line.split()[3]
                break
        assert url, served.stderr.read()
        for path in ("", "app.js", "vendor/uPlot.iife.min.js", "vendor/gridstack-all.js", "vendor/dagre.min.js", "vendor/LICENSE.uPlot"):
            with urllib.request.urlopen(url + path, timeout=10) as answer:
                assert answer.status == 200 and len(answer.read()) > 500, path
    finally:
        served.terminate()
        served.wait(timeout=30)
