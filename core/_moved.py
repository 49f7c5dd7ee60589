"""Import paths of modules that moved into core's wings keep working: ``tafel.core.manager`` is
``tafel.core.framework.manager`` (the same module object), for code written before the wings."""

from __future__ import annotations

import importlib
import importlib.abc
import importlib.machinery
import importlib.util
import sys
from types import ModuleType

#: old module name -> where it lives now
MOVED = {
    "tafel.core.access": "tafel.core.framework.access",
    "tafel.core.blackbox": "tafel.core.logs.blackbox",
    "tafel.core.clock": "tafel.core.runtime.clock",
    "tafel.core.config": "tafel.core.framework.config",
    "tafel.core.dot": "tafel.core.framework.dot",
    "tafel.core.errors": "tafel.core.framework.errors",
    "tafel.core.extensions": "tafel.core.framework.extensions",
    "tafel.core.graph": "tafel.core.framework.graph",
    "tafel.core.handover": "tafel.core.runtime.handover",
    "tafel.core.logfile": "tafel.core.logs",
    "tafel.core.logs.logfile": "tafel.core.logs",
    "tafel.core.manager": "tafel.core.framework.manager",
    "tafel.core.module": "tafel.core.framework.module",
    "tafel.core.naming": "tafel.core.framework.naming",
    "tafel.core.parameters": "tafel.core.framework.parameters",
    "tafel.core.platform": "tafel.core.runtime.platform",
    "tafel.core.program": "tafel.core.runtime.program",
    "tafel.core.pytest_plugin": "tafel.core.testing.pytest_plugin",
    "tafel.core.recording": "tafel.core.logs.recording",
    "tafel.core.reload": "tafel.core.framework.reload",
    "tafel.core.representation": "tafel.core.framework.representation",
    "tafel.core.serialization": "tafel.core.logs.serialization",
    "tafel.core.statistics": "tafel.core.runtime.statistics",
    "tafel.core.status": "tafel.core.runtime.status",
    "tafel.core.validation": "tafel.core.framework.validation",
    "tafel.core.watchdog": "tafel.core.runtime.watchdog",
}


class _MovedFinder(importlib.abc.MetaPathFinder, importlib.abc.Loader):
    """Finds an old name and hands out the module under its new name."""

    def find_spec(self, fullname: str, path: object = None, target: object = None) -> importlib.machinery.ModuleSpec | None:
        if fullname in MOVED:
            return importlib.util.spec_from_loader(fullname, self)
        return None

    def create_module(self, spec: importlib.machinery.ModuleSpec) -> ModuleType:
        return importlib.import_module(MOVED[spec.name])

    def exec_module(self, module: ModuleType) -> None:
        pass  # the module ran under its new name already


def install() -> None:
    if not any(isinstance(finder, _MovedFinder) for finder in sys.meta_path):
        sys.meta_path.insert(0, _MovedFinder())


install()
