"""The thread policy: how many torch intra-op threads a process that renders or extracts features uses.

Torch's intra-op pool defaults to one thread per core. Beside the renderer's
Dr.Jit pool, a ParallelEnv sibling, a learner or any other busy process, those
threads wait on each other at every parallel region and the work slows by an
order of magnitude. Measured on 2 cores (`nbv bench --area threads`, wall
time per view, one view per call, best of 2 passes over 6 renders; "busy" adds
one `while True: pass` process beside it):

| view      | load | Kornia 1 thread | Kornia 2 threads | OpenCV | Kornia 1 t / OpenCV |
| --------- | ---- | --------------- | ---------------- | ------ | ------------------- |
| 160x120   | idle | 25 ms           | 1.6 s            | 5 ms   | 4.8x                |
| 160x120   | busy | 56 ms           | 2.8 s            | 10 ms  | 5.6x                |
| 320x240   | idle | 54 ms           | 4.5 s            | 22 ms  | 2.5x                |
| 320x240   | busy | 146 ms          | 6.8 s            | 43 ms  | 3.4x                |

The machine was not quiet ("idle" began at a 1-minute load average of 3.1:
two training processes ran beside it), which is the normal case for a
training host and is exactly where 2 threads lose 50-80x. The planning step
at 160x120 (Kornia SIFT + Bag of Views reward + actor forward, no render, 1
thread) took 29 ms idle and 65 ms busy (goal <= 50 ms, and <= 100 ms busy).
On 2 truly idle cores 2 threads helped only modestly: 1.3x on Bag of Views
work, 2x on a batch-8 SAC update (docs/conventions.md §9).

Hence one thread, wherever features are extracted in a process that also
renders or plans (`NBVEnv`, `nbv plan`, the learner of `nbv train` by
default). Only intra-op threads are set: `torch.set_num_interop_threads` may
be called once, before any parallel work, and torch's inter-op pool stays idle
in this code.

The choice is per process and remembered (`chosen_threads`): a process that
chose explicitly (`set_torch_threads`, e.g. `nbv train --threads 2`) keeps its
choice, and `apply_thread_policy` only fills in the policy where nobody chose.
`ParallelEnv`'s workers are spawned processes, so each applies it again.

Torch is imported inside the functions: `common` stays light to import.
"""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager

WORKER_THREADS = 1
"""Torch intra-op threads of a process that also renders or extracts features: the measured best under
load, by 50-80x for Kornia SIFT on 2 shared cores."""

_chosen: int | None = None
"""This process's explicit choice (0: torch's default), None if nobody chose yet."""


def worker_threads(requested: int = 0) -> int:
    """Torch intra-op threads for a process that also renders or extracts features.

    Args:
        requested: an explicit thread count; 0 (or less) asks for the policy.

    Returns:
        `requested` if it is positive, else `WORKER_THREADS` (1).

    Example:
        >>> worker_threads(), worker_threads(3)
        (1, 3)
    """
    return requested if requested > 0 else WORKER_THREADS


def chosen_threads() -> int | None:
    """The torch thread count this process chose (0: torch's default), or None if it chose none yet."""
    return _chosen


def set_torch_threads(threads: int) -> int:
    """Choose this process's torch intra-op threads: `threads` if positive, 0 keeps torch's default.

    The choice is remembered, so `apply_thread_policy` leaves it alone. Returns the count torch now uses.
    """
    global _chosen
    if threads < 0:
        raise ValueError(f"threads must be >= 0 (0: torch's default), got {threads}")
    import torch

    if threads > 0:
        torch.set_num_threads(threads)
    _chosen = threads
    return torch.get_num_threads()


def apply_thread_policy() -> int:
    """Set torch to `worker_threads()` unless this process already chose; return torch's thread count.

    Cheap after the first call: call it wherever features are about to be extracted.
    """
    if _chosen is None:
        return set_torch_threads(worker_threads())
    import torch

    return torch.get_num_threads()


@contextmanager
def limit_torch_threads(threads: int) -> Iterator[int]:
    """Torch intra-op threads set to `threads` (0: leave them) for the block, then restored.

    The block counts as this process's choice (`apply_thread_policy` inside it changes nothing); the
    previous count and choice come back on exit. Yields the count torch uses inside.

    Example:
        >>> with limit_torch_threads(1) as n:
        ...     n
        1
    """
    global _chosen
    import torch

    before, chosen = torch.get_num_threads(), _chosen
    try:
        yield set_torch_threads(threads)
    finally:
        if torch.get_num_threads() != before:
            torch.set_num_threads(before)
        _chosen = chosen
