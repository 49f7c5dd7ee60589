"""``tafel run --watch``: a module's source file that changes is reloaded into the running program.

A thread looks at the modification times of the files that define the program's modules twice a
second; a changed file sends ``module:reload`` for each module it defines through the debug server,
which routes it to the context that runs the module (in the concurrent runtime: to its process). The
reload happens at that context's next frame boundary (``tafel.core.framework.reload``), and its answer (or why
it was refused) is printed like a status line.
"""

from __future__ import annotations

import inspect
import threading
from collections.abc import Callable, Iterable
from pathlib import Path

#: s between two looks at the files
INTERVAL_S = 0.5


def module_files(classes: Iterable[type]) -> dict[Path, list[str]]:
    """Source file -> the names of the modules it defines (classes without a file are left out)."""
    files: dict[Path, list[str]] = {}
    for cls in classes:
        try:
            path = Path(inspect.getsourcefile(cls) or "")
        except (TypeError, OSError):
            continue
        if path.is_file():
            files.setdefault(path.resolve(), []).append(cls.__name__)
    return files


class SourceWatcher:
    """Polls ``files``; ``ask`` runs a debug command and returns its answer, ``report`` prints it."""

    def __init__(self, files: dict[Path, list[str]], ask: Callable[[str], str], report: Callable[[str], None],
                 interval_s: float = INTERVAL_S) -> None:
        self.files = files
        self.ask = ask
        self.report = report
        self.interval_s = interval_s
        self.stopped = threading.Event()
        self.seen = {path: self._stamp(path) for path in files}
        self.thread = threading.Thread(target=self._watch, name="tafel-source-watch", daemon=True)

    def start(self) -> SourceWatcher:
        self.thread.start()
        return self

    def stop(self) -> None:
        self.stopped.set()

    @staticmethod
    def _stamp(path: Path) -> tuple[int, int]:
        try:
            stat = path.stat()
        except OSError:
            return (0, 0)
        return (stat.st_mtime_ns, stat.st_size)

    def _watch(self) -> None:
        while not self.stopped.wait(self.interval_s):
            for path, names in self.files.items():
                stamp = self._stamp(path)
                if stamp == self.seen[path] or stamp == (0, 0):
                    continue  # unchanged, or gone for a moment while an editor saves
                self.seen[path] = stamp
                for name in names:
                    try:
                        answer = self.ask(f"module:reload -module {name}")
                    except Exception as exc:  # noqa: BLE001 - the program's server is stopping, say
                        answer = f"module:reload {name} failed: {exc}"
                    self.report(answer.strip())
