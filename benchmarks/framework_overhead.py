"""Framework overhead per module: ``ModuleManager.execute()`` against a bare loop.

A chain of 100 trivial modules, each requiring the previous one's representation and providing its own,
runs under the manager (timing, read-only views and access recording on). The baseline calls the same
``execute`` functions on instances wired to plain representation objects, with no manager and no views.
Both are measured alternately in one run; the medians of several repetitions are reported.
Prints one JSON line.
"""

from __future__ import annotations

import json
import statistics
import time

from tafel.core import Module, ModuleManager, provides, representation, requires
from tafel.core.framework.manager import make_module
from tafel.core.framework.naming import snake_case

CHAIN = 100
FRAMES = 2000
REPEATS = 7


def build_chain(n: int) -> tuple[list[type], list[type]]:
    """Representations Value0..Value{n} and modules Step1..Step{n}; Step{i} reads Value{i-1}."""
    reps = [representation(type(f"BenchValue{i}", (), {"__annotations__": {"value": int}})) for i in range(n + 1)]
    modules = []
    for i in range(1, n + 1):
        source, target = snake_case(reps[i - 1].__name__), snake_case(reps[i].__name__)
        namespace = {"execute": _make_execute(source, target)}
        cls = type(f"BenchStep{i}", (Module,), namespace)
        modules.append(provides(reps[i])(requires(reps[i - 1])(cls)))
    return reps, modules


def _make_execute(source: str, target: str):
    """``execute`` as a module author writes it (plain attribute access), for generated names."""
    code = f"def execute(self):\n    self.{target}.value = self.{source}.value + 1\n"
    namespace: dict = {}
    exec(code, namespace)  # noqa: S102 - generated benchmark code
    return namespace["execute"]


def main() -> None:
    reps, modules = build_chain(CHAIN)
    manager = ModuleManager(modules, name="bench", external=[reps[0]])

    plain = [r() for r in reps]
    bare_modules = [
        make_module(m, **{snake_case(reps[i].__name__): plain[i], snake_case(reps[i + 1].__name__): plain[i + 1]})
        for i, m in enumerate(modules)
    ]
    bare_calls = [m.execute for m in bare_modules]

    def bare_frame() -> None:
        for call in bare_calls:
            call()

    for _ in range(200):  # warm up both paths
        manager.execute()
        bare_frame()

    framework, bare = [], []
    for _ in range(REPEATS):
        start = time.perf_counter()
        for _ in range(FRAMES):
            manager.execute()
        framework.append((time.perf_counter() - start) / FRAMES / CHAIN * 1e6)
        start = time.perf_counter()
        for _ in range(FRAMES):
            bare_frame()
        bare.append((time.perf_counter() - start) / FRAMES / CHAIN * 1e6)

    assert manager.blackboard[reps[-1]].value == manager.blackboard[reps[0]].value + CHAIN
    framework_us, bare_us = statistics.median(framework), statistics.median(bare)
    print(json.dumps({
        "modules": CHAIN,
        "framework_us_per_module": round(framework_us, 3),
        "bare_us_per_module": round(bare_us, 3),
        "overhead_us_per_module": round(framework_us - bare_us, 3),
    }))


if __name__ == "__main__":
    main()
