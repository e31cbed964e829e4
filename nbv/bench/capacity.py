"""Predicted wall time of units of work on a cluster: list scheduling of single-core units (docs/capacity.md).

Every unit runs on one core (`nbv.fanout` caps its threads to its share), so a
cluster of N nodes of M cores is N x M slots. A stage's units are handed out
longest first, each to the slot free soonest (LPT), and stages run one after
another (a building's full-scan reference before the runs scored against it).
LPT is within 4/3 of the best possible schedule, and never below the larger of
the longest unit and the work divided by the slots.
"""

from __future__ import annotations

import heapq
from collections.abc import Sequence


def schedule_wall_s(stages: Sequence[Sequence[float]], slots: int, startup_s: float = 0.0) -> float:
    """Wall seconds of `stages` (each a list of unit costs in core seconds) on `slots` cores, plus
    `startup_s` once (starting Ray and the workers' imports).

    Example:
        >>> schedule_wall_s([[3, 3, 2, 2, 2]], slots=2)
        7.0
        >>> schedule_wall_s([[5], [1, 1, 1, 1]], slots=4, startup_s=0.5)
        6.5
    """
    if slots < 1:
        raise ValueError(f"slots must be >= 1, got {slots}")
    wall = float(startup_s)
    for stage in stages:
        free = [0.0] * min(slots, max(1, len(stage)))
        for cost in sorted(stage, reverse=True):
            heapq.heappush(free, heapq.heappop(free) + float(cost))
        wall += max(free)
    return wall
