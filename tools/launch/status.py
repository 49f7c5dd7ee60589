"""What a run says while it runs and when it ends: the status line, its pace notice, the summary."""

from __future__ import annotations

import sys
from collections.abc import Mapping, Sequence
from typing import Any

from tafel.core.runtime import (
    ContextStats,
    program_fingerprint,
)

#: s behind the wall clock, for s of wall time, before a run is called slower than real time
LAG_S, LAG_FOR_S = 1.0, 2.0


class StatusLine:
    """The status line of a run: rates over the last interval, and what ``[status] show`` names.

    Which representations appear is configuration, not code: each shows its ``status_text()`` where
    it has one, and its scalar fields otherwise.
    """

    def __init__(self, platform: str, config: dict[str, Any]) -> None:
        self.platform = platform
        show = config.get("status", {}).get("show", []) if isinstance(config.get("status"), dict) else []
        self.show = [str(name) for name in show] if isinstance(show, list) else []
        self._last: dict[str, tuple[int, float]] = {}
        self._lagging_since: tuple[float, float] | None = None  # (wall s, platform s) since the loop lags
        self._said_slower = False

    def rates(self, stats: dict[str, ContextStats], now: float) -> dict[str, float]:
        """Frames per second of each context since the previous line (since the start for the first)."""
        rates = {}
        for name, s in stats.items():
            frames, then = self._last.get(name, (0, now - s.wall_s))
            rates[name] = (s.frames - frames) / (now - then) if now > then else 0.0
            self._last[name] = (s.frames, now)
        return rates

    def format(self, elapsed_s: float, stats: dict[str, ContextStats], now: float, runners: dict[str, Any] | None = None,
               notices: Sequence[str] = (), dead: Mapping[str, str] | None = None) -> str:
        parts = [f"[tafel] {self.platform} t={elapsed_s:.1f}s"]
        rates = self.rates(stats, now)
        for name, s in stats.items():
            if dead and name in dead:
                parts.append(f"{name} DEAD ({dead[name]}) after {s.frames} frames")
                continue
            state = " FAILED" if s.failure else ""
            parts.append(f"{name} {rates[name]:.1f} Hz {s.frames} frames{state}")
        parts.append(f"module errors {sum(s.module_errors for s in stats.values())}")
        parts.extend(self.shown(runners or {}))
        parts.extend(notices)
        return " | ".join(parts)

    def event(self, elapsed_s: float, text: str) -> str:
        """A line of its own for something that happened (a goal): it is printed when it happens."""
        return f"[tafel] {self.platform} t={elapsed_s:.1f}s {text}"

    def pace(self, now: float, platform_s: float, behind_s: float, speed: float | None) -> str | None:
        """Once, when the run cannot keep the pace asked for: its real-time factor, which is why the rates
        are low. Said when the loop has been ``LAG_S`` behind the wall clock for ``LAG_FOR_S`` and went
        on losing ground meanwhile; a single stall that the loop makes up again is not slowness."""
        if self._said_slower or speed is None:
            return None
        if behind_s < LAG_S:
            self._lagging_since = None
            return None
        if self._lagging_since is None:
            self._lagging_since = (now, platform_s)
            return None
        wall, platform = now - self._lagging_since[0], platform_s - self._lagging_since[1]
        if wall < LAG_FOR_S:
            return None
        factor = platform / wall
        if factor >= 0.98 * speed:  # keeping the pace again, only late from before
            self._lagging_since = (now, platform_s)
            return None
        self._said_slower = True
        slower = "slower than real time" if speed == 1.0 else f"slower than --speed {speed:g} asks"
        return self.event(platform_s, f"{slower}: {factor:.2f}x real time; a frame's work takes longer than its period, "
                                      "so the rates are below the configured ones (said once)")

    def shown(self, runners: dict[str, Any]) -> list[str]:
        texts = []
        for name in self.show:
            for runner in runners.values():
                blackboard = runner.manager.blackboard
                if name in blackboard.names():
                    texts.append(describe(blackboard.get(name)))
                    break
        return texts


def describe(value: Any) -> str:
    """A representation in a few words: its ``status_text()``, else its scalar fields."""
    if hasattr(value, "status_text"):
        return str(value.status_text())
    scalars = [f"{k}={v:.4g}" if isinstance(v, float) else f"{k}={v}" for k, v in vars(value).items()
               if isinstance(v, (bool, int, float, str))]
    return f"{type(value).__name__} " + " ".join(scalars[:6])


def stop_reason(signals: Sequence[str], end_reason: str) -> str:
    """The summary's words for why a run ended: the signal that stopped it (``stopped by SIGINT``), else
    what the runtime says (``stopped after 500 motion frames``); "" when nothing is known."""
    if signals:
        return f"stopped by {signals[0]}"
    if end_reason in ("", "stopped"):  # "stopped": a stop asked for by other means (a debug client)
        return end_reason
    return f"stopped after {end_reason}"


def print_summary(platform: str, mode: str, stats: dict[str, ContextStats], wall_s: float, ran_s: float, reason: str,
                  *, simulated: bool, notes: Sequence[str] = ()) -> None:
    """The summary of a run, all on standard output: ``ran`` is the run's length (platform time covered
    with a simulated clock, the loops' running time otherwise), never the clock's end value; ``reason`` is
    the whole phrase (``stop_reason``)."""
    out = sys.stdout
    time_text = f"{ran_s:.3f} s of platform time" if simulated else f"{ran_s:.3f} s"
    print(f"platform {platform} ({mode}): ran {time_text}" + (f", {reason}" if reason else ""), file=out)
    for note in notes:
        print(f"  {note}", file=out)
    for name, s in stats.items():
        errors = ", ".join(f"{m} {n}" for m, n in sorted(s.errors_by_module.items())) or "none"
        line = f"  {name}: {s.frames} frames, module errors: {errors}"
        if s.failure:
            line += f", FAILED: {s.failure}"
        print(line, file=out)
        if s.period_errors:
            timing = s.period_error_percentiles()
            print(f"    timing: period error p50 {timing['p50_ms']:.2f} ms, p99 {timing['p99_ms']:.2f} ms, "
                  f"max {timing['max_ms']:.2f} ms, missed_periods={s.missed_periods}"
                  + (f", frames_without_cognition={s.frames_without_cognition}" if name == "motion" else ""), file=out)
    fingerprint = program_fingerprint(stats)
    if fingerprint:
        print(f"fingerprint {fingerprint} (the state of every representation; equal runs and faithful replays print the same)", file=out)
    rates = ", ".join(f"{n} {s.rate_hz:.1f} Hz" for n, s in stats.items())
    print(f"wall time {wall_s:.2f} s ({rates})", file=out, flush=True)



def status_print(text: str) -> None:
    """A status line on stderr; a closed stream (``tafel run 2>&- ``, a gone terminal) never stops the run."""
    try:
        print(text, file=sys.stderr, flush=True)
    except (OSError, ValueError):
        pass

