"""Units on local worker processes (spawned, so each imports Mitsuba and torch afresh).

A worker that dies (killed, out of memory, a crash in native code) breaks the
whole `ProcessPoolExecutor`, and every unit in flight fails with it, guilty or
not. Those units are retried once each, alone in a fresh one-worker pool, so a
second death is the unit's own: it is reported by name (`WorkerDied`) after
its partial files are removed. An exception a unit raises is not retried: it
is re-raised as it is, with a note naming the unit.
"""

from __future__ import annotations

import multiprocessing
from collections.abc import Callable, Sequence
from concurrent.futures import Future, ProcessPoolExecutor, as_completed
from concurrent.futures.process import BrokenProcessPool

from nbv.fanout.task import Task, WorkerDied, discard_partial
from nbv.fanout.worker import core_share, run_in_worker


def run_in_processes(stages: Sequence[Sequence[Task]], workers: int, on_done: Callable[[Task], None]) -> None:
    """Run the stages' units on `workers` spawned processes (one pool while none dies), each capped to its
    share of the cores; `on_done` is called as each finishes. Raises WorkerDied naming a unit whose
    worker died twice."""
    share = core_share(workers)
    pool: ProcessPoolExecutor | None = None
    try:
        for stage in stages:
            pool = pool or _pool(workers)
            broken = _run_stage(pool, stage, share, on_done)
            if broken:
                pool.shutdown()
                pool = None
            for task in broken:
                discard_partial(task)  # after the pool's shutdown: a dead worker not yet reaped looks alive
                with _pool(1) as alone:
                    lost = _run_stage(alone, [task], share, on_done)
                if lost:
                    discard_partial(task)
                    raise WorkerDied(f"task {task.name!r}: its worker process died twice (killed, out of "
                                     "memory or crashed); nothing of it was kept")
    finally:
        if pool is not None:
            pool.shutdown(cancel_futures=True)


def _pool(workers: int) -> ProcessPoolExecutor:
    return ProcessPoolExecutor(workers, mp_context=multiprocessing.get_context("spawn"))


def _run_stage(pool: ProcessPoolExecutor, tasks: Sequence[Task], share: int,
               on_done: Callable[[Task], None]) -> list[Task]:
    """Run `tasks` on `pool`; return those lost to a dying worker."""
    broken: list[Task] = []
    futures: dict[Future, Task] = {pool.submit(run_in_worker, task, share): task for task in tasks}
    for future in as_completed(futures):
        try:
            future.result()
        except BrokenProcessPool:
            broken.append(futures[future])
            continue
        on_done(futures[future])
    return broken
