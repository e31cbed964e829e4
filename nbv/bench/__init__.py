"""`make bench`: one module per area, each measuring its own figures.

Each module in `AREAS` exposes `run(quick: bool) -> list[BenchResult]`.
Ratios that a goal compares are measured side by side in the same run.
"""

from __future__ import annotations

import os
import tempfile
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import asdict, dataclass

AREAS = (
    "cli",
    "render",
    "scenes",
    "bov",
    "recon",
    "threads",
    "rl",
    "lookahead",
    "fanout",
)
"""Bench modules under `nbv.bench`, run in this order."""


@dataclass(frozen=True)
class BenchResult:
    """One measured figure."""

    area: str
    """The bench module that measured it (cli, render, scenes, bov, recon, threads, rl, lookahead,
    fanout)."""
    name: str
    """What was measured, with its settings (e.g. 'RGB-D views/s llvm_ad_rgb 320x240 steady')."""
    value: float
    """The measured value."""
    unit: str
    """Unit of `value` (views/s, ms/view, s, x)."""
    goal: str = ""
    """The issue's goal for this figure, if any (e.g. '>= 6'), and whether it is met."""

    def as_dict(self) -> dict:
        """Plain dict for JSON."""
        return asdict(self)


@contextmanager
def temporary_cache() -> Iterator[str]:
    """An empty `NBV_CACHE_DIR` for the block (cold-cache figures), restored afterwards."""
    previous = os.environ.get("NBV_CACHE_DIR")
    with tempfile.TemporaryDirectory() as cache:
        os.environ["NBV_CACHE_DIR"] = cache
        try:
            yield cache
        finally:
            if previous is None:
                os.environ.pop("NBV_CACHE_DIR")
            else:
                os.environ["NBV_CACHE_DIR"] = previous
