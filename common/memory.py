"""Memory-sized values bounded before they are allocated: a named error instead of a MemoryError.

A setting whose arrays grow with its value (points sampled per surface, voxels of a grid, views of a
dataset) is checked against this machine's physical memory before anything is allocated: what it would
need, estimated from the bytes each unit takes, may use at most `MEMORY_SHARE` of it.
"""

from __future__ import annotations

import os

MEMORY_SHARE = 0.5
"""Largest share of the physical memory one memory-sized setting may claim (the rest: the process, the
renderer, the other arrays and the other processes)."""
FALLBACK_BYTES = 16 * 2**30
"""The physical memory assumed where the system does not say (16 GiB)."""


class MemoryBoundError(ValueError):
    """A setting would need more memory than this machine has; the message names it and the fix."""


def physical_memory() -> int:
    """Bytes of physical memory of this machine (`FALLBACK_BYTES` where the system does not say)."""
    try:
        return os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")
    except (ValueError, OSError, AttributeError):
        return FALLBACK_BYTES


def check_memory(what: str, units: float, bytes_per_unit: float, fix: str) -> None:
    """Raise `MemoryBoundError` when `units` of `bytes_per_unit` exceed `MEMORY_SHARE` of the memory.

    Example:
        >>> check_memory("metric_points 1000", 1000, 100, "use fewer")
    """
    need, have = float(units) * bytes_per_unit, physical_memory()
    if need > MEMORY_SHARE * have:
        raise MemoryBoundError(f"{what} would need about {need / 2**30:.3g} GiB, more than "
                               f"{MEMORY_SHARE:.0%} of this machine's {have / 2**30:.3g} GiB; {fix}")
