"""The dependency direction is the architecture: the import-linter contracts in pyproject.toml hold."""

from __future__ import annotations

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
