"""The dependency direction is the architecture: the import-linter contracts in pyproject.toml hold; the lint
rules pass, and mypy finds no type error in core/, representations/ and modules/."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent


def tool(name: str) -> str:
    """A test dependency's command, from this environment first."""
    command = shutil.which(name, path=str(Path(sys.executable).parent)) or shutil.which(name)
    assert command, f"{name} comes with the test dependencies: pip install -e '.[test]'"
    return command


def test_the_layering_contracts_hold() -> None:
    command = tool("lint-imports")
    result = subprocess.run([command, "--no-cache"], cwd=REPO, capture_output=True, text=True, timeout=120)
    assert result.returncode == 0, result.stdout + result.stderr
    assert "0 broken" in result.stdout


def test_the_code_passes_the_lint_rules() -> None:
    """pyproject.toml's [tool.ruff] rules (pyflakes, pycodestyle, import order, bugbear) over the whole tree."""
    result = subprocess.run([tool("ruff"), "check", "--no-cache", "."], cwd=REPO, capture_output=True, text=True, timeout=120)
    assert result.returncode == 0, result.stdout + result.stderr


def test_core_representations_and_modules_type_check() -> None:
    """mypy over core/, representations/ and modules/ ([tool.mypy] in pyproject.toml, through .ci/mypy): the
    annotations of what modules read and write reach the type checker, and nothing there has a type error."""
    result = subprocess.run(["bash", str(REPO / ".ci" / "mypy")], cwd=REPO, capture_output=True, text=True, timeout=600,
                            env={**os.environ, "PYTHON": sys.executable})
    assert result.returncode == 0, result.stdout + result.stderr
    assert "Success: no issues found" in result.stdout, result.stdout
