"""Synthetic module loads for benchmarks (named in configuration as ``loads:ClassName``)."""

from __future__ import annotations

import time
from dataclasses import dataclass

from tafel.core import Module, requires
from tafel.representations.infrastructure import FrameInfo


@requires(FrameInfo)
class PythonHeavyLoad(Module):
    """Pure-Python work holding the interpreter lock for about ``milliseconds`` per frame."""

    @dataclass
    class Parameters:
        milliseconds: float = 20.0

    def execute(self) -> None:
        end = time.perf_counter() + self.parameters.milliseconds / 1000.0
        total = 0
        while time.perf_counter() < end:
            for i in range(200):
                total += i * i
