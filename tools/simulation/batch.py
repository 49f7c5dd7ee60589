"""Where many independent runs go: worker processes on this machine, or Ray tasks on a cluster.

Scenario runs and batch replays both hand a module-level function and a list of jobs to ``run_jobs``.
Locally the standard library's process pool runs them, ``workers`` at a time; with ``ray`` each job
is one Ray task on a local Ray instance (``ray="local"``) or on the cluster at that address. There is
no scheduler of our own: a job's result depends on the job alone, so both give the same results.

A worker process that dies (killed, out of memory, a crash in native code) takes its job with it; the
job runs again, up to ``RETRIES`` times, and is reported once. An exception inside a job is the job's
own business: the functions given here return a row that says what went wrong instead of raising.
"""

from __future__ import annotations

import multiprocessing
import os
import time
from collections.abc import Callable, Iterator, Sequence
from concurrent.futures import FIRST_COMPLETED, Future, ProcessPoolExecutor, wait
from concurrent.futures.process import BrokenProcessPool
from contextlib import contextmanager
from dataclasses import dataclass
from typing import Any

from tafel.core.runtime import end_with_parent

#: times a job whose worker died runs again before it is reported as lost
RETRIES = 2
#: each run is single-threaded: numerical libraries must not start threads of their own in every worker
SINGLE_THREADED = {"OMP_NUM_THREADS": "1", "OPENBLAS_NUM_THREADS": "1", "MKL_NUM_THREADS": "1", "MUJOCO_GL": "egl"}


class BatchError(RuntimeError):
    """The batch cannot run at all (Ray missing or unreachable); the message says what to do."""


@dataclass
class BatchInfo:
    """How a batch ran: where, how many workers, and how long start-up and the runs took (s)."""

    where: str = "local"
    workers: int = 1
    startup_s: float = 0.0
    wall_s: float = 0.0
    retried: int = 0


def default_workers() -> int:
    return len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else (os.cpu_count() or 1)


def worker_environment() -> dict[str, str]:
    """What every worker's environment gets, unless the caller's environment says otherwise."""
    return {key: os.environ.get(key, value) for key, value in SINGLE_THREADED.items()}


def lost_row(job: Any, reason: str) -> dict[str, Any]:
    """The row of a job that never finished: its worker died on every try."""
    return {"job": repr(job)[:200], "success": False, "reason": reason}


def run_jobs(function: Callable[[Any], dict[str, Any]], jobs: Sequence[Any], workers: int | None = None,
             ray: str | None = None, on_result: Callable[[int, dict[str, Any]], None] | None = None,
             warm_up: Callable[[], Any] | None = None, info: BatchInfo | None = None) -> list[dict[str, Any]]:
    """``function(job)`` for every job, rows in the order of ``jobs``.

    ``on_result(index, row)`` is called as each finishes (for progress). ``warm_up`` runs once in
    every worker before the clock of ``info.wall_s`` starts (imports, first renders): start-up is
    reported apart from the runs' own time.
    """
    info = info if info is not None else BatchInfo()
    workers = max(1, workers or default_workers())
    if ray is not None:
        return _run_on_ray(function, jobs, workers, ray, on_result, warm_up, info)
    return _run_locally(function, jobs, workers, on_result, warm_up, info)


# ----------------------------------------------------------------------------------------- local
#: in a worker process: where it says which job it starts (so that a dead pool tells which jobs died with it)
_started: Any = None


def _set_up_worker(started: Any, parent: int) -> None:
    global _started
    _started = started
    end_with_parent(parent)  # a SIGTERM or SIGKILL of the batch must not leave its workers running


@contextmanager
def _environment(values: dict[str, str]) -> Iterator[None]:
    """``values`` in this process's environment meanwhile: the workers it starts inherit them from the
    start (a worker imports numpy before any initializer could set its thread count)."""
    saved = {key: os.environ.get(key) for key in values}
    os.environ.update(values)
    try:
        yield
    finally:
        for key, value in saved.items():
            if value is None:
                os.environ.pop(key, None)
            else:
                os.environ[key] = value


def _run_indexed(function: Callable[[Any], dict[str, Any]], index: int, job: Any) -> dict[str, Any]:
    _started.put(index)
    return function(job)


def _run_locally(function: Callable[[Any], dict[str, Any]], jobs: Sequence[Any], workers: int,
                 on_result: Callable[[int, dict[str, Any]], None] | None, warm_up: Callable[[], Any] | None,
                 info: BatchInfo) -> list[dict[str, Any]]:
    info.where, info.workers = "local", workers
    rows: dict[int, dict[str, Any]] = {}
    tries = dict.fromkeys(range(len(jobs)), 0)
    start = time.perf_counter()
    # spawn, not fork: the caller may hold threads, sockets and a GL context that a fork would copy
    context = multiprocessing.get_context("spawn")
    started = context.SimpleQueue()

    def finish(index: int, row: dict[str, Any]) -> None:
        rows[index] = row
        if on_result is not None:
            on_result(index, row)

    while len(rows) < len(jobs):
        pending = [i for i in range(len(jobs)) if i not in rows]
        with _environment(worker_environment()), ProcessPoolExecutor(
                max_workers=min(workers, len(pending)), mp_context=context, initializer=_set_up_worker, initargs=(started, os.getpid())) as pool:
            if warm_up is not None and not info.startup_s:
                for done in [pool.submit(warm_up) for _ in range(min(workers, len(pending)))]:
                    done.result()
                info.startup_s = time.perf_counter() - start
                start = time.perf_counter()
            futures: dict[Future[dict[str, Any]], int] = {pool.submit(_run_indexed, function, i, jobs[i]): i for i in pending}
            while futures:
                done, _ = wait(futures, return_when=FIRST_COMPLETED)
                broken = False
                for future in done:
                    index, error = futures.pop(future), future.exception()
                    if isinstance(error, BrokenProcessPool):
                        broken = True  # a worker died: every unfinished job of this pool is lost with it
                    elif error is not None:
                        finish(index, lost_row(jobs[index], f"error: {type(error).__name__}: {error}"))
                    else:
                        finish(index, future.result())
                if broken:
                    break
        # Jobs that had started and not finished died with the pool: they count a try. The others run again freely.
        while not started.empty():
            index = started.get()
            if index not in rows:
                tries[index] += 1
                info.retried += 1
                if tries[index] > RETRIES:
                    finish(index, lost_row(jobs[index], f"its worker process died {tries[index]} times"))
    info.wall_s = time.perf_counter() - start
    return [rows[i] for i in range(len(jobs))]


# ------------------------------------------------------------------------------------------- Ray
def _import_ray() -> Any:
    try:
        import ray
    except ImportError:
        raise BatchError("--ray needs Ray: pip install -e '.[ray]' (or pip install 'tafel[ray]')") from None
    return ray


def _call(function: Callable[[], Any]) -> Any:
    """``function()``: Ray's tasks must be plain functions, and a warm-up may be a ``functools.partial``."""
    return function()


def _run_on_ray(function: Callable[[Any], dict[str, Any]], jobs: Sequence[Any], workers: int, address: str,
                on_result: Callable[[int, dict[str, Any]], None] | None, warm_up: Callable[[], Any] | None,
                info: BatchInfo) -> list[dict[str, Any]]:
    ray = _import_ray()
    start = time.perf_counter()
    local = address in ("", "local")
    try:
        if local:  # a Ray instance of this program's own, with as many CPUs as workers asked for
            ray.init(num_cpus=workers, include_dashboard=False, runtime_env={"env_vars": worker_environment()},
                     logging_level="ERROR", log_to_driver=False)
        else:
            ray.init(address=address, runtime_env={"env_vars": worker_environment()}, logging_level="ERROR", log_to_driver=False)
    except (ConnectionError, RuntimeError, ValueError) as exc:
        raise BatchError(f"cannot reach a Ray cluster at {address!r} ({exc}); start one with 'ray start --head' and "
                         "pass its address as --ray HOST:6379, or --ray alone for a local instance") from None
    try:
        cpus = int(ray.cluster_resources().get("CPU", workers))
        info.where, info.workers = ("ray (local)" if local else f"ray at {address}"), cpus
        task = ray.remote(num_cpus=1, max_retries=RETRIES)(function)
        if warm_up is not None:
            ray.get([ray.remote(num_cpus=1)(_call).remote(warm_up) for _ in range(cpus)])
        info.startup_s = time.perf_counter() - start
        start = time.perf_counter()
        refs = {task.remote(job): index for index, job in enumerate(jobs)}
        rows: dict[int, dict[str, Any]] = {}
        while refs:
            done, _ = ray.wait(list(refs), num_returns=1)
            index = refs.pop(done[0])
            try:
                rows[index] = ray.get(done[0])
            except ray.exceptions.RayError as exc:  # the worker died on every try, or the task could not run
                rows[index] = lost_row(jobs[index], f"Ray: {type(exc).__name__}: {str(exc).splitlines()[0][:200]}")
            if on_result is not None:
                on_result(index, rows[index])
        info.wall_s = time.perf_counter() - start
        return [rows[i] for i in range(len(jobs))]
    finally:
        ray.shutdown()
