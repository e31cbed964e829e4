"""`schedule_wall_s` against a brute-force optimal schedule of small random stages."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from nbv.bench.capacity import schedule_wall_s


def optimal_wall(costs: list[float], slots: int) -> float:
    """The best makespan over every assignment of units to slots."""
    best = float("inf")
    for assignment in itertools.product(range(slots), repeat=len(costs)):
        loads = [0.0] * slots
        for cost, slot in zip(costs, assignment):
            loads[slot] += cost
        best = min(best, max(loads))
    return best


def test_lpt_is_within_four_thirds_of_the_optimum():
    rng = np.random.default_rng(0)
    for _ in range(40):
        slots = int(rng.integers(1, 4))
        costs = rng.uniform(1.0, 100.0, size=int(rng.integers(1, 8))).tolist()
        best = optimal_wall(costs, slots)
        wall = schedule_wall_s([costs], slots)
        assert best - 1e-9 <= wall <= (4 / 3) * best + 1e-9
        assert wall >= max(max(costs), sum(costs) / slots) - 1e-9


def test_stages_add_up_and_start_up_is_paid_once():
    assert schedule_wall_s([[10.0, 10.0], [4.0]], slots=2, startup_s=3.0) == 17.0
    assert schedule_wall_s([[1.0] * 8], slots=100) == 1.0
    with pytest.raises(ValueError, match="slots must be >= 1"):
        schedule_wall_s([[1.0]], slots=0)
