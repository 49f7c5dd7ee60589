"""Cognition modules that misbehave on purpose, for the runtime's crash and stall tests.

Configuration names them as ``tests.support.runtime_faults:ClassName``.
"""

from __future__ import annotations

import os
import time
from dataclasses import dataclass

from tafel.core import Module, requires
from tafel.representations.infrastructure import FrameInfo


@requires(FrameInfo)
class CrashCognitionProcess(Module):
    """Ends its process abruptly (as a segfault would) after ``after_frames`` frames."""

    @dataclass
    class Parameters:
        after_frames: int = 10

    def execute(self) -> None:
        if self.frame_info.frame_number >= self.parameters.after_frames:
            os._exit(3)


@requires(FrameInfo)
class StallCognition(Module):
    """Blocks for ``stall`` seconds once, after ``after_frames`` frames."""

    @dataclass
    class Parameters:
        after_frames: int = 10
        stall: float = 2.5

    def __init__(self) -> None:
        self.stalled = False

    def execute(self) -> None:
        if not self.stalled and self.frame_info.frame_number >= self.parameters.after_frames:
            self.stalled = True
            time.sleep(self.parameters.stall)


@requires(FrameInfo)
class RaiseEveryFrame(Module):
    """Raises in every frame: the loop must go on and count the errors."""

    def execute(self) -> None:
        raise RuntimeError(f"deliberate failure in frame {self.frame_info.frame_number}")


@requires(FrameInfo)
class StuckForever(Module):
    """Never returns from its first frame (ignores stop requests): the shutdown watchdog's case."""

    def execute(self) -> None:
        while True:
            time.sleep(0.1)


@requires(FrameInfo)
class CrashMotionProcess(CrashCognitionProcess):
    """The same abrupt end, placed in motion: the program must end and say why."""


@requires(FrameInfo)
class SlowEveryFrame(Module):
    """Takes ``seconds`` every frame: a program too slow for real time (the pacing notice's case)."""

    @dataclass
    class Parameters:
        seconds: float = 0.06

    def execute(self) -> None:
        time.sleep(self.parameters.seconds)


@requires(FrameInfo)
class StuckAfter(Module):
    """Busy forever in pure Python after ``after_frames`` frames (an endless loop in a module's code),
    in whichever context configuration puts it: the watchdog's case."""

    @dataclass
    class Parameters:
        after_frames: int = 20

    def execute(self) -> None:
        if self.frame_info.frame_number >= self.parameters.after_frames:
            spins = 0
            while True:
                spins += 1
