"""Units on local worker processes: one warm pool for the whole study (spawned, so each imports afresh).

The pool is started on first use, or early by `start_pool` (the command's
first stage, the caller's own set-up, run while the workers import torch and
Mitsuba), and kept for every later stage and every later call in this process,
until it exits: a study pays the workers' start-up once.

A worker that dies (killed, out of memory, a crash in native code) breaks the
whole `ProcessPoolExecutor`, and every unit in flight fails with it, guilty or
not. The broken pool is dropped, and those units are retried once each, alone
in a fresh one-worker pool, so a second death is the unit's own: it is
reported by name (`WorkerDied`) after its partial files are removed. An
exception a unit raises is not retried: it is re-raised as it is, with a note
naming the unit, once the units already running have finished.
"""

from __future__ import annotations

import atexit
import multiprocessing
from collections.abc import Callable, Sequence
from concurrent.futures import Future, ProcessPoolExecutor, as_completed, wait
from concurrent.futures.process import BrokenProcessPool

from nbv.fanout.task import Task, WorkerDied, discard_partial
from nbv.fanout.worker import caller_context, core_share, run_in_worker, warm_worker

_POOLS: dict[int, ProcessPoolExecutor] = {}
"""This process's warm pools, by worker count."""


def start_pool(workers: int) -> ProcessPoolExecutor:
    """This process's pool of `workers` warm workers: started now if it is not running (each worker starts
    at once and warms up, `warm_worker`, in the background), else the running one."""
    pool = _POOLS.get(workers)
    if pool is None:
        pool = _pool(workers)
        for _ in range(workers):  # the executor spawns a worker per waiting call: all of them, now
            pool.submit(int)
        _POOLS[workers] = pool
    return pool


def close_pools() -> None:
    """Shut this process's warm pools down (at exit, or to start afresh)."""
    while _POOLS:
        _POOLS.popitem()[1].shutdown(cancel_futures=True)


atexit.register(close_pools)


def run_in_processes(stages: Sequence[Sequence[Task]], workers: int, on_done: Callable[[Task], None]) -> None:
    """Run the stages' units on the warm pool of `workers` processes, each capped to its share of the cores;
    `on_done` is called as each finishes. Raises WorkerDied naming a unit whose worker died twice."""
    share = core_share(workers)
    for stage in stages:
        broken = _run_stage(start_pool(workers), stage, share, on_done)
        if broken:
            _POOLS.pop(workers).shutdown()
        for task in broken:
            discard_partial(task)  # after the pool's shutdown: a dead worker not yet reaped looks alive
            with _pool(1, warm=False) as alone:  # one unit: nothing to gain from warming up
                lost = _run_stage(alone, [task], share, on_done)
            if lost:
                discard_partial(task)
                raise WorkerDied(f"task {task.name!r}: its worker process died twice (killed, out of "
                                 "memory or crashed); nothing of it was kept")


def _pool(workers: int, warm: bool = True) -> ProcessPoolExecutor:
    return ProcessPoolExecutor(workers, mp_context=multiprocessing.get_context("spawn"),
                               initializer=warm_worker if warm else None, initargs=(core_share(workers),))


def _run_stage(pool: ProcessPoolExecutor, tasks: Sequence[Task], share: int,
               on_done: Callable[[Task], None]) -> list[Task]:
    """Run `tasks` on `pool`; return those lost to a dying worker. On a unit's exception the units not yet
    started are cancelled and the running ones finish before it propagates."""
    broken: list[Task] = []
    context = caller_context()
    futures: dict[Future, Task] = {pool.submit(run_in_worker, task, share, context): task for task in tasks}
    try:
        for future in as_completed(futures):
            try:
                future.result()
            except BrokenProcessPool:
                broken.append(futures[future])
                continue
            on_done(futures[future])
    except BaseException:
        for future in futures:
            future.cancel()
        wait(futures)
        raise
    return broken
