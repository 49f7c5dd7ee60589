"""The configured program on a platform, stepped tick by tick in this process.

Tests, the scenario runner and batch replay use it where ``tafel run`` in a process of its own would
be in the way: between ticks the platform object answers where the robot and the ball really are, and
the blackboards can be read. It is the same program as ``tafel run``'s, without the debug server, the
status line and the pacing.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import Any

from tafel.core.framework.config import check_config, edit_modules, load_config
from tafel.core.framework.representation import registered_representations
from tafel.core.runtime import Limits, LockstepRuntime
from tafel.core.runtime.platform import load_platform
from tafel.core.runtime.program import plan_program
from tafel.tools.launch.defaults import DEFAULT_CONFIG
from tafel.tools.launch.program import discover_modules
from tafel.tools.launch.recording import program_recorder


class SteppedProgram:
    """The default configuration (plus ``overrides``) on ``platform`` with its ``options``.

    With ``record`` the run is recorded into that MCAP file as ``tafel run --record`` would: the
    configuration's ``[recording]`` list, or ``record_reps``. ``add_modules`` and ``remove_modules``
    edit the module lists as ``--add-module`` and ``--remove-module`` do (``CONTEXT:MODULE``);
    ``module_paths`` are folders of one's own module files, imported first as ``--module-path`` does.
    """

    def __init__(self, platform: str, options: Mapping[str, Any], overrides: Sequence[str] = (), record: Path | None = None,
                 record_reps: list[str] | None = None, add_modules: Sequence[str] = (), remove_modules: Sequence[str] = (),
                 module_paths: Sequence[str] = ()) -> None:
        discover_modules(module_paths)
        self.platform = load_platform(platform)(dict(options))
        rates = [f"runtime.{context}_hz={hz}" for context, hz in (self.platform.rates() or {}).items()]
        config = load_config(DEFAULT_CONFIG, self.platform.config_layers(), overrides=[*rates, *overrides])
        self.config = edit_modules(config, add_modules, remove_modules)
        check_config(self.config, type(self.platform).config_sections, registered_representations())  # as tafel run does
        self.platform.configure(self.config)
        self.plans = plan_program(self.config, self.platform)
        self.recorder = None
        if record is not None:
            self.recorder = program_recorder(self.plans, self.config, self.platform, record_reps, blocking=True)
        self.runtime = LockstepRuntime(self.plans, self.platform, recorder=self.recorder)
        if self.recorder is not None:
            self.recorder.start(record)
        self.runtime.open()

    def blackboard(self, context: str) -> Any:
        return self.runtime.runners[context].manager.blackboard

    @property
    def time(self) -> float:
        """Platform seconds of the last tick."""
        return self.runtime.time_ns * 1e-9

    @property
    def tick_s(self) -> float:
        return 1.0 / self.plans[self.runtime.main].rate_hz

    def run(self, seconds: float, every_tick: Callable[[Any], None] | None = None) -> None:
        """``seconds`` of ticks, ``every_tick(self)`` after each."""
        for _ in range(int(round(seconds / self.tick_s))):
            self.runtime.tick()
            if every_tick is not None:
                every_tick(self)

    def run_to_end(self) -> str:
        """As fast as possible until the platform ends (a log's end); returns why it ended."""
        self.runtime.run(Limits(speed=None))
        return self.runtime.end_reason

    def close(self) -> None:
        """Stop the platform and finish the recording."""
        self.runtime.close()
