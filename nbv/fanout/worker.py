"""What a worker process does before and around a unit: start warm, take the caller's settings, cap threads.

A worker lives for the whole study (`nbv.fanout.processes`, `nbv.fanout.ray_pool`):
it starts once, imports the heavy libraries and selects the Mitsuba variant
(`warm_worker`), and keeps what it loads (a scene built once per process,
`scenes.catalog.load_scene`; Mitsuba's kernels are cached on disk anyway).
Since it outlives the call that started it, each unit brings the caller's
working folder and `NBV_*` environment (the cache folder, the variant) with it
(`caller_context`), so a unit runs as it would in the caller's process.

Torch's intra-op pool and Dr.Jit's pool each default to one thread per core;
several workers on one machine would then oversubscribe the cores 2 x workers
over (docs/conventions.md §9, `common.threads`). A worker given `share` cores
runs Dr.Jit on `share` threads and torch on the thread policy's count (1, or
`share` if that is smaller). The Mitsuba variant is chosen inside the worker by
the unit itself (`render.variant.select_variant`, from its render settings or
`$NBV_VARIANT`).
"""

from __future__ import annotations

import importlib
import os

from common.threads import set_torch_threads, worker_threads
from nbv.fanout.task import Task, run_task
from render.variant import configure_libllvm

WARM_IMPORTS = ("torch", "tensordict", "torchrl", "kornia", "open3d", "trimesh", "matplotlib.pyplot",
                "mitsuba")
"""What a worker imports as it starts, before its first unit: the heavy libraries of the planning and
scoring pipeline (seconds each on a busy machine)."""
ENV_PREFIX = "NBV_"
"""The caller's environment variables a unit sees in a long-lived worker (cache folder, variant)."""


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


def warm_worker(share: int) -> None:
    """Start a worker: cap its threads to `share` cores, import `WARM_IMPORTS` and select the Mitsuba
    variant (`$NBV_VARIANT` or the default), so that its first unit pays for none of it."""
    cap_threads(share)
    for name in WARM_IMPORTS:
        importlib.import_module(name)
    from render.variant import select_variant

    select_variant()


def caller_context() -> tuple[str, dict[str, str]]:
    """What a unit takes along from the caller: its working folder and its `NBV_*` environment variables."""
    return os.getcwd(), {k: v for k, v in os.environ.items() if k.startswith(ENV_PREFIX)}


def enter_context(context: tuple[str, dict[str, str]] | None, chdir: bool = True) -> None:
    """Take on the caller's `NBV_*` environment (dropping ones it has not set) and, with `chdir`, its
    working folder; None leaves this process as it is."""
    if context is None:
        return
    folder, env = context
    for name in [k for k in os.environ if k.startswith(ENV_PREFIX) and k not in env]:
        del os.environ[name]
    os.environ.update(env)
    if chdir and os.getcwd() != folder:
        os.chdir(folder)


def run_in_worker(task: Task, share: int, context: tuple[str, dict[str, str]] | None = None,
                  chdir: bool = True) -> None:
    """A worker's entry point: take on the caller's `context`, cap threads to `share` cores, run `task`."""
    enter_context(context, chdir)
    cap_threads(share)
    run_task(task)
