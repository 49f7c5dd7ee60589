"""Hot reload: a module's new code replaces the running instance at a frame boundary, keeping the
blackboard and parameters; what cannot run is refused or rolled back, and the loop never stops."""

from __future__ import annotations

import importlib
import re
import sys
import textwrap
import time
from collections.abc import Iterator
from pathlib import Path

import pytest

from tafel.core.framework.manager import ModuleManager
from tafel.core.framework.module import _KNOWN
from tafel.core.framework.reload import ModuleReloader, ReloadError
from tafel.core.framework.representation import _REGISTRY
from tafel.representations.infrastructure import FrameInfo
from tests.test_debug_server import Program

COUNTER = textwrap.dedent('''
    from dataclasses import dataclass

    from tafel.core import Module, provides, representation, requires
    from tafel.representations.infrastructure import FrameInfo


    @representation
    class Tally:
        """Counted by the module under reload."""
        count: int = 0


    @requires(FrameInfo)
    @provides(Tally)
    class Counter(Module):
        @dataclass
        class Parameters:
            step: int = 1
            spare: float = 0.5

        def execute(self) -> None:
            self.tally.count += self.parameters.step
''')


@pytest.fixture
def counting(tmp_path: Path, request: pytest.FixtureRequest) -> Iterator[tuple[Path, ModuleManager, ModuleReloader]]:
    """A module file of its own (a fresh Python name per test), its manager and reloader."""
    name = f"reload_{request.node.name.split('[')[0][-40:]}"
    path = tmp_path / f"{name}.py"
    path.write_text(COUNTER)
    sys.path.insert(0, str(tmp_path))
    try:
        module = importlib.import_module(name)
        manager = ModuleManager([module.Counter], external=[FrameInfo], parameters={"Counter": {"step": 2}})
        yield path, manager, ModuleReloader(manager, probation_frames=3)
    finally:  # the names are the process's: free them for the next test
        sys.path.remove(str(tmp_path))
        sys.modules.pop(name, None)
        _KNOWN.pop("Counter", None)
        for rep in [n for n, c in _REGISTRY.items() if c.__module__ == name]:
            del _REGISTRY[rep]


def tally(manager: ModuleManager) -> int:
    return manager.blackboard.get("Tally").count


def edit(path: Path, old: str, new: str) -> None:
    text = path.read_text()
    assert old in text
    path.write_text(text.replace(old, new))


def test_new_code_runs_from_the_next_frame_with_the_blackboard_and_parameters_kept(counting) -> None:
    path, manager, reloader = counting
    for _ in range(3):
        manager.execute()
    assert tally(manager) == 6
    manager.module("Counter").parameters.step = 5  # as parameter:set does while it runs
    edit(path, "+= self.parameters.step", "+= self.parameters.step * 10")
    answer = reloader.reload("Counter")
    assert re.search(r"reloaded Counter from .* at frame 3; parameters kept: spare, step", answer), answer
    manager.execute()
    assert tally(manager) == 6 + 50  # the state stayed, the new code and the running parameter value apply


def test_a_module_annotated_with_a_representation_of_its_own_file_reloads(tmp_path: Path) -> None:
    """As the README's tutorial writes modules: the representation beside the module, ``tally: Tally`` in the class
    body, no ``from __future__ import annotations``. The new class's annotation names the file's new Tally; it must
    name the one on the blackboard (a new user's report: refused with a message that contradicted itself)."""
    name = "reload_annotated_counter"
    annotated = COUNTER.replace("class Counter(Module):\n", "class Counter(Module):\n    tally: Tally\n")
    assert "    tally: Tally" in annotated
    (tmp_path / f"{name}.py").write_text(annotated)
    sys.path.insert(0, str(tmp_path))
    try:
        module = importlib.import_module(name)
        manager = ModuleManager([module.Counter], external=[FrameInfo])
        reloader = ModuleReloader(manager, probation_frames=3)
        manager.execute()
        edit(tmp_path / f"{name}.py", "+= self.parameters.step", "+= self.parameters.step * 10")
        assert "reloaded Counter" in reloader.reload("Counter")
        manager.execute()
        assert tally(manager) == 1 + 10
    finally:
        sys.path.remove(str(tmp_path))
        sys.modules.pop(name, None)
        _KNOWN.pop("Counter", None)
        for rep in [n for n, c in _REGISTRY.items() if c.__module__ == name]:
            del _REGISTRY[rep]


def test_a_parameter_the_new_code_no_longer_declares_is_named(counting) -> None:
    path, manager, reloader = counting
    edit(path, "        spare: float = 0.5\n", "")
    assert "dropped (no longer declared): spare" in reloader.reload("Counter")


@pytest.mark.parametrize(("old", "new", "why"), [
    ("+= self.parameters.step", "+= (", "does not import: SyntaxError"),
    ("from dataclasses import dataclass", "import no_such_package_here", "does not import: ModuleNotFoundError"),
    ("@requires(FrameInfo)", "@requires(FrameInfo, CameraMatrixTop)\n",
     "MissingProviderError"),
    ("count: int = 0", "count: int = 0\n    extra: float = 0.0", "changed; a representation's shape cannot change while the program runs: restart it"),
    ("class Counter(Module):", "class Renamed(Module):", "no longer defines the module class Counter"),
])
def test_what_cannot_run_is_refused_and_the_old_code_goes_on(counting, old: str, new: str, why: str) -> None:
    path, manager, reloader = counting
    if "CameraMatrixTop" in new:
        edit(path, "from tafel.representations.infrastructure import FrameInfo",
             "from tafel.representations.infrastructure import FrameInfo\nfrom tafel.representations.motion import CameraMatrixTop")
    manager.execute()
    edit(path, old, new)
    with pytest.raises(ReloadError, match=re.escape(why)) as refused:
        reloader.reload("Counter")
    assert "the old version keeps running" in str(refused.value)
    manager.execute()
    assert tally(manager) == 4  # step 2, twice: the old code ran on
    assert reloader.events[-1] == str(refused.value)


def test_a_new_version_that_raises_in_its_first_frames_is_rolled_back_with_the_old_state(counting) -> None:
    path, manager, reloader = counting
    manager.execute()
    old = manager.module("Counter")
    edit(path, "self.tally", "raise RuntimeError('broken'); self.tally")
    reloader.reload("Counter")
    manager.execute()  # raises, is counted, and rolled back after the frame
    assert re.search(r"rolled back Counter at frame 2: the new version raised RuntimeError: broken", reloader.events[-1])
    assert manager.module("Counter") is old
    manager.execute()
    assert tally(manager) == 4  # frames 1 and 3 by the old instance; frame 2's failed write was undone
    assert manager.errors() == {"Counter": (1, "RuntimeError: broken")}  # the rolled-back version's failure is still counted


def test_a_new_version_that_passes_its_probation_stays(counting) -> None:
    path, manager, reloader = counting
    edit(path, "+= self.parameters.step", "+= 100")
    reloader.reload("Counter")
    for _ in range(5):
        manager.execute()
    assert tally(manager) == 500 and not any("rolled back" in e for e in reloader.events)


def test_an_unknown_module_is_a_clear_error(counting) -> None:
    _, _, reloader = counting
    with pytest.raises(Exception, match="Countr"):
        reloader.reload("Countr")


@pytest.mark.slow
@pytest.mark.parametrize("concurrent", [False, True], ids=["lockstep", "concurrent"])
def test_watch_reloads_an_edited_file_into_the_running_program(tmp_path: Path, concurrent: bool) -> None:
    folder = tmp_path / "team"
    folder.mkdir()
    source = folder / "team_counter.py"
    source.write_text(COUNTER)
    program = Program("--watch", "--module-path", str(folder), "--add-module", "cognition:Counter",
                      *(["--concurrent"] if concurrent else []), "--status-interval", "60")
    try:
        def count() -> int:
            return int(re.search(r"count: (\d+)", program.ask("representation:print Tally")).group(1))

        first = count()
        time.sleep(0.5)
        assert count() > first  # step 1 per frame
        edit(source, "+= self.parameters.step", "+= 1000")
        deadline = time.monotonic() + 20
        before = count()
        while count() - before < 1000 and time.monotonic() < deadline:
            time.sleep(0.2)
        assert count() - before >= 1000, "".join(program.errors)
        assert count() >= first  # the count went on from where it was: the blackboard was kept
        edit(source, "+= 1000", "+= (")  # a syntax error: refused, the program goes on
        deadline = time.monotonic() + 20
        while not any("refused to reload Counter" in line for line in program.errors) and time.monotonic() < deadline:
            time.sleep(0.2)
        assert any("does not import: SyntaxError" in line for line in program.errors), "".join(program.errors)
        still = count()
        time.sleep(0.5)
        assert count() > still
    finally:
        out, err = program.stop()
    assert program.process.returncode == 0, err
