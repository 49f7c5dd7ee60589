"""``tafel run``: the program on its platform, in lockstep or in processes of its own, with what watches it."""

from __future__ import annotations

import argparse
import logging
import sys
import threading
import time
from collections.abc import Callable, Sequence
from typing import Any

from tafel.core.logs.recording import Recorder
from tafel.core.runtime import (
    ConcurrentRuntime,
    ContextStats,
    Limits,
    LockstepRuntime,
    clock,
    install_signal_handlers,
    recorder_hook,
)
from tafel.core.runtime.platform import Platform
from tafel.core.runtime.program import ContextPlan
from tafel.core.runtime.watchdog import STUCK_TIMEOUT_S
from tafel.debug.executors import (
    LocalExecutor,
    RemoteExecutor,
    concurrent_pipes,
    context_debug,
    worker_debug_setup,
    worker_setups,
)
from tafel.debug.values import frame_number
from tafel.tools.launch.errors import fail
from tafel.tools.launch.program import prepare, report_pruned
from tafel.tools.launch.readiness import Readiness
from tafel.tools.launch.recording import (
    add_blackbox_commands,
    blackbox_triggers,
    debug_recorded,
    make_blackbox,
    make_recorder,
    recording_notices,
    report_recording,
)
from tafel.tools.launch.servers import (
    concurrent_feed,
    foxglove_address,
    listen,
    start_debug,
    start_foxglove,
    start_web,
    watch_sources,
    web_representations,
)
from tafel.tools.launch.status import StatusLine, print_summary, status_print, stop_reason
from tafel.tools.viewers.live_feed import forward


def command_run(args: argparse.Namespace, extra: Sequence[str]) -> int:
    Readiness(args.ready_file).clear()
    logging.basicConfig(level=logging.INFO if args.verbose else logging.WARNING, format="%(name)s %(levelname)s: %(message)s")
    if args.foxglove is not None:
        foxglove_address(args.foxglove)  # a wrong address fails before anything starts
    if args.watch and args.no_debug:
        fail("--watch reloads modules through the debug server; leave out --no-debug (--no-web is fine)")
    if args.record_dir.exists() and not args.record_dir.is_dir():
        fail(f"--record-dir {args.record_dir} is a file; it takes a folder (created when a client records)")
    platform, options, plans, config = prepare(args, extra)
    report_pruned(plans)
    recorder = make_recorder(args, plans, config, platform)
    limits = Limits(frames=args.frames, seconds=args.seconds, speed=args.speed)
    if args.concurrent or type(platform).clock == "own":
        return run_concurrent(args, platform, options, plans, config, recorder, limits)
    return run_lockstep(args, platform, plans, recorder, limits, config)



def shutdown_grace(config: dict[str, Any]) -> float:
    return float(config.get("runtime", {}).get("shutdown_grace_s", 15.0))


def stuck_timeout(config: dict[str, Any]) -> float:
    """``[runtime] stuck_timeout_s``: s one module may run without returning before its context ends."""
    return float(config.get("runtime", {}).get("stuck_timeout_s", STUCK_TIMEOUT_S))


def stop_servers(debug: Any, *viewers: Any) -> None:
    """What a run started around its runtime ends with it: viewers, the source watcher, the debug server."""
    for viewer in viewers:
        if viewer is not None:
            viewer.stop()
    if debug is not None:
        debug.server.stop()


def end_run(recorder: Recorder | None, box: Any, stats: dict[str, ContextStats]) -> int:
    """After either runtime: what was recorded, the black box's last saves, and the exit status
    (1 when a context failed)."""
    report_recording(recorder)
    if box is not None:
        box[0].finish()
        print(box[0].status(), flush=True)
    return 1 if any(s.failure for s in stats.values()) else 0


def run_lockstep(args: argparse.Namespace, platform: Platform, plans: dict[str, ContextPlan], recorder: Recorder | None,
                 limits: Limits, config: dict[str, Any]) -> int:
    # The loops share the interpreter with the debug server's network thread: hand the lock over within
    # 1 ms instead of the default 5 ms, so a busy server delays a frame by a millisecond at the most.
    sys.setswitchinterval(0.001)
    runtime = LockstepRuntime(plans, platform, strict=args.strict, recorder=recorder, stuck_timeout_s=stuck_timeout(config))
    box = make_blackbox(args, plans, config, platform)
    if box is not None:
        for runner in runtime.runners.values():
            runner.after_step.append(recorder_hook(box[1]))
        trigger = blackbox_triggers(box[0])
        runtime.after_tick.append(lambda rt: trigger(rt.time_ns, {n: r.stats(0.0) for n, r in rt.runners.items()}
                                                     if rt.ticks % 10 == 0 else None))
    debug = start_debug(args, recorder, plans, config)
    add_blackbox_commands(debug, box)
    if debug is not None:
        recorded = debug_recorded(recorder, [] if args.no_web else list(plans))
        for name, runner in runtime.runners.items():
            debug.add_context(name, LocalExecutor(context_debug(name, runner.manager, recorded.get(name, ()))), plans[name])
        debug.add_platform_commands(platform)
        # between ticks half a millisecond of commands; while the loop is behind, one (no client starves)
        runtime.after_tick.append(lambda rt: debug.server.process_pending(budget_s=0.0005 if rt.behind_s < 0.001 else 0.0,
                                                                         chunk=8 if rt.behind_s < 0.001 else 1))
        runtime.idle = debug.server.serve_while_idle
    elif recorder is not None:  # no server, but recorded debug data (drawings, module times) is still filled in
        recorded = debug_recorded(recorder)
        for name, runner in runtime.runners.items():
            context_debug(name, runner.manager, recorded.get(name, ()))
    signals = install_signal_handlers(runtime.stop, grace_s=shutdown_grace(config))
    listen(args, debug)
    watcher = watch_sources(args, debug, plans)
    web = start_web(args, debug, plans, config)
    live = start_foxglove(args, debug, config)
    for viewer in (web, live):
        if viewer is not None:
            for runner in runtime.runners.values():
                runner.after_step.append(lambda r, feed=viewer.feed: feed.after_frame(r.name, r.manager.blackboard, r.time_ns, frame_number(r.manager)))
    started = time.monotonic()
    last = [started]
    line = StatusLine(type(platform).name, config)

    def status(rt: LockstepRuntime) -> None:
        now = time.monotonic()
        for event in platform.take_events():
            status_print(line.event(rt.time_ns * 1e-9, event))
        slower = line.pace(now, rt.time_ns * 1e-9, rt.behind_s, limits.speed)
        if slower:
            status_print(slower)
        if now - last[0] >= args.status_interval:
            last[0] = now
            stats = {name: r.stats(now - started) for name, r in rt.runners.items()}
            status_print(line.format(rt.time_ns * 1e-9, stats, now, rt.runners, recording_notices(recorder)))

    runtime.after_tick.append(status)
    readiness = Readiness(args.ready_file)
    if readiness.wanted:
        runtime.after_tick.append(lambda rt: readiness.reported or readiness.check({n: r.frames for n, r in rt.runners.items()}))
    try:
        stats = runtime.run(limits)
    finally:
        stop_servers(debug, live, web, watcher)
    print_summary(type(platform).name, "lockstep", stats, runtime.wall_s, runtime.time_ns * 1e-9, stop_reason(signals, runtime.end_reason),
                  simulated=True)
    return end_run(recorder, box, stats)


def run_concurrent(args: argparse.Namespace, platform: Platform, options: dict[str, Any], plans: dict[str, ContextPlan],
                   config: dict[str, Any], recorder: Recorder | None, limits: Limits) -> int:
    platform.stop()  # each context process makes its own
    platform_class = type(platform)
    debug = start_debug(args, recorder, plans, config)
    setups: list[tuple[Callable[..., None], dict[str, Any]]] = []
    if debug is not None:
        running = [name for name, plan in plans.items() if plan.runs]
        ours, theirs = concurrent_pipes(running)
        setups.append((worker_debug_setup, {"connections": theirs, "recorded": debug_recorded(recorder, [] if args.no_web else list(plans))}))
        for name in running:
            debug.add_context(name, RemoteExecutor(name, ours[name]), plans[name])
    from tafel.tools.viewers.foxglove_live import FED

    flags, feed = concurrent_feed(args.foxglove is not None, FED, setups)
    from tafel.tools.viewers.web import web_topics

    web_flags, web_feed = concurrent_feed(debug is not None and not args.no_web, web_topics(web_representations(plans)), setups)
    setup = (worker_setups, setups) if setups else None
    stall = float(config.get("runtime", {}).get("stall_timeout_s", 1.0))
    box = make_blackbox(args, plans, config, platform)
    add_blackbox_commands(debug, box)
    runtime = ConcurrentRuntime(plans, platform_class, options, strict=args.strict, stall_timeout_s=stall,
                                recorder=recorder, worker_setup=setup, grace_s=shutdown_grace(config),
                                stuck_timeout_s=stuck_timeout(config), blackbox=box[0] if box else None,
                                blackbox_record=box[1].by_context if box else None)
    if box is not None:
        trigger = blackbox_triggers(box[0])
        runtime.on_report.append(lambda rt: trigger(clock.now_ns(), rt.stats))
    started = time.monotonic()
    last = [started]
    line = StatusLine(platform_class.name, config)
    shown_dead: set[str] = set()
    if debug is not None:
        for name, executor in debug.executors.items():
            executor.alive = lambda name=name: runtime.dead.get(name)

    def on_report(rt: ConcurrentRuntime) -> None:
        now = time.monotonic()
        if now - last[0] >= args.status_interval or set(rt.dead) != shown_dead:
            last[0] = now
            shown_dead.update(rt.dead)
            status_print(line.format(now - started, rt.stats, now, None, [*rt.notices, *recording_notices(recorder)], rt.dead))

    runtime.on_report.append(on_report)
    readiness = Readiness(args.ready_file)
    if readiness.wanted:
        runtime.on_report.append(lambda rt: readiness.check({name: rt.stats[name].frames if name in rt.stats and name not in rt.dead else 0
                                                             for name, plan in plans.items() if plan.runs}))
    signals = install_signal_handlers(runtime.stop, on_force=lambda: [p.kill() for p in runtime.processes.values()],
                                      grace_s=shutdown_grace(config))
    if debug is not None:
        listen(args, debug)
        threading.Thread(target=debug.server.dispatch_forever, args=(runtime.stop,), name="tafel-debug-dispatch", daemon=True).start()
    watcher = watch_sources(args, debug, plans)
    web = start_web(args, debug, plans, config, web_flags)
    live = start_foxglove(args, debug, config, flags)
    for viewer, source in ((web, web_feed), (live, feed)):
        if viewer is not None:
            threading.Thread(target=forward, args=(source, viewer.feed, runtime.stop), name="tafel-viewer-forward", daemon=True).start()
    try:
        stats = runtime.run(limits)
    finally:
        stop_servers(debug, live, web, watcher)
    realtime = stats.get("motion", ContextStats("motion")).realtime
    notes = ([f"motion: {realtime}"] if realtime else []) + [f"notice: {notice}" for notice in runtime.notices]
    ran = max((s.wall_s for s in stats.values()), default=0.0)
    print_summary(platform_class.name, "concurrent", stats, time.monotonic() - started, ran, stop_reason(signals, ""), simulated=False,
                  notes=notes)
    return end_run(recorder, box, stats)


