"""Modules from outside the package: folders of module files and installed packages of modules.

A module registers itself by class name when its file is imported, so loading a module means
importing its file. Two ways, both used by ``tafel run``, ``tafel modules`` and the context processes
of the concurrent runtime (which must know the same modules and representations):

- a folder (``--module-path DIR``): every ``*.py`` file and package in it is imported under its own
  name, with the folder added to ``sys.path`` (so that the context processes, which import module
  classes by reference, find them too). Files starting with ``_`` or ``test_`` and ``conftest.py`` are
  left out, so tests may live beside the modules.
- an installed package that names its modules in the entry point group ``tafel.modules``, e.g. in its
  ``pyproject.toml``: ``[project.entry-points."tafel.modules"] my_team = "my_team.modules"``. Each entry
  point is loaded (its module imported) at start.
"""

from __future__ import annotations

import importlib
import importlib.util
import logging
import sys
import traceback
from collections.abc import Iterable
from pathlib import Path

from tafel.core.framework.errors import TafelError

ENTRY_POINT_GROUP = "tafel.modules"
log = logging.getLogger("tafel.modules")

#: the folders imported so far in this process, in order (the concurrent runtime hands them to its processes)
_FOLDERS: list[str] = []
_ENTRY_POINTS_LOADED: list[bool] = []


class ModulePathError(TafelError, ValueError):
    """A module folder that cannot be loaded as given."""


def loaded_folders() -> list[str]:
    """The module folders this process has imported, in order."""
    return list(_FOLDERS)


def module_files(folder: Path) -> list[str]:
    """The importable names in ``folder``: its ``*.py`` files and packages, tests and private files left out."""
    names = []
    for path in sorted(folder.iterdir()):
        if path.name.startswith(("_", "test_", ".")) or path.name == "conftest.py":
            continue
        if path.is_file() and path.suffix == ".py" and path.stem.isidentifier():
            names.append(path.stem)
        elif path.is_dir() and (path / "__init__.py").is_file() and path.name.isidentifier():
            names.append(path.name)
    return names


def _where(name: str) -> Path | None:
    """The file ``name`` imports from today (None when nothing of that name is importable)."""
    module = sys.modules.get(name)
    origin = getattr(module, "__file__", None) if module is not None else None
    if origin is None and module is None:
        try:
            spec = importlib.util.find_spec(name)
        except (ImportError, ValueError):
            return None
        origin = spec.origin if spec is not None else None
    return Path(origin).resolve() if origin else None


def import_folder(folder: str | Path) -> list[str]:
    """Import every module file in ``folder``; the names imported. ``ModulePathError`` says what was wrong."""
    path = Path(folder).expanduser().resolve()
    if not path.is_dir():
        raise ModulePathError(f"--module-path {folder}: no such folder; give the folder that holds your module files (*.py)")
    names = module_files(path)
    if not names:
        raise ModulePathError(f"--module-path {folder}: the folder holds no Python files (*.py or packages) to import")
    if str(path) not in sys.path:
        sys.path.append(str(path))
    for name in names:
        where = _where(name)
        if where is not None and path not in where.parents:
            raise ModulePathError(f"{path / name}: the name {name!r} is already taken by {where}; rename the file "
                                  "(a module file's name must not be that of another Python module)")
        try:
            importlib.import_module(name)
        except Exception as exc:  # noqa: BLE001 - the user's code may raise anything: say where and what
            frames = [f for f in traceback.extract_tb(exc.__traceback__) if Path(f.filename).resolve().is_relative_to(path)]
            if isinstance(exc, SyntaxError) and exc.filename:
                at = f" (at {exc.filename}:{exc.lineno})"
                detail = f"SyntaxError: {exc.msg}"
            else:
                at = f" (at {frames[-1].filename}:{frames[-1].lineno})" if frames else ""
                detail = f"{type(exc).__name__}: {exc}"
            raise ModulePathError(f"--module-path {folder}: importing {name} failed{at}: {detail}") from exc
    if str(path) not in _FOLDERS:
        _FOLDERS.append(str(path))
    return names


def load_entry_points() -> list[str]:
    """Load every installed ``tafel.modules`` entry point (once); the names of those loaded.

    A broken package is logged with what went wrong and skipped: it must not stop programs that do not
    use its modules (those that do then fail with the unknown module's name).
    """
    from importlib.metadata import entry_points

    if _ENTRY_POINTS_LOADED:
        return []
    _ENTRY_POINTS_LOADED.append(True)
    loaded = []
    for entry in entry_points(group=ENTRY_POINT_GROUP):
        try:
            entry.load()
        except Exception as exc:  # noqa: BLE001 - someone else's package: report it, go on
            log.warning("entry point %s = %s (group %s) cannot be loaded, its modules are unknown: %s: %s",
                        entry.name, entry.value, ENTRY_POINT_GROUP, type(exc).__name__, exc)
            continue
        loaded.append(entry.name)
    return loaded


def load_modules(folders: Iterable[str | Path] = ()) -> None:
    """The installed packages' modules, then those of each folder, in order."""
    load_entry_points()
    for folder in folders:
        import_folder(folder)
