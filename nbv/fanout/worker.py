"""What a worker process does before and around a unit: cap its threads to its share, then run it.

Torch's intra-op pool and Dr.Jit's pool each default to one thread per core;
several workers on one machine would then oversubscribe the cores 2 x workers
over (docs/conventions.md §9, `common.threads`). A worker given `share` cores
runs Dr.Jit on `share` threads and torch on the thread policy's count (1, or
`share` if that is smaller). The Mitsuba variant is chosen inside the worker by
the unit itself (`render.variant.select_variant`, from its render settings or
`$NBV_VARIANT`, which workers inherit).
"""

from __future__ import annotations

import os

from common.threads import set_torch_threads, worker_threads
from nbv.fanout.task import Task, run_task
from render.variant import configure_libllvm


def usable_cores() -> int:
    """Cores this process may run on (its CPU affinity, which a container or `taskset` may narrow)."""
    return len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count() or 1


def core_share(workers: int, cores: int | None = None) -> int:
    """Cores per worker when `workers` share `cores` (default: `usable_cores()`); at least 1.

    Example:
        >>> core_share(2, cores=16), core_share(4, cores=2)
        (8, 1)
    """
    return max(1, (cores or usable_cores()) // workers)


def cap_threads(share: int) -> tuple[int, int]:
    """Cap this process's Dr.Jit threads to `share` and torch's to the policy's (at most `share`);
    return (Dr.Jit threads, torch threads)."""
    configure_libllvm()  # before Dr.Jit's first import (render/variant.py)
    import drjit as dr

    dr.set_thread_count(share)
    torch_threads = set_torch_threads(min(worker_threads(), share))
    return dr.thread_count(), torch_threads


def run_in_worker(task: Task, share: int) -> None:
    """A worker's entry point: cap threads to `share` cores, then run `task` (`run_task`)."""
    cap_threads(share)
    run_task(task)
