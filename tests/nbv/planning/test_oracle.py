"""The coverage oracle: never below another budget planner on `nbv plan`'s coverage; its greedy and swaps."""

from __future__ import annotations

import json

import numpy as np
import pytest

from nbv.planning.config import PlanConfig, PlanSettings
from nbv.planning.oracle import (
    POOL,
    baseline_names,
    covered,
    greedy_cover,
    improve_by_swaps,
    lattice_viewpoints,
    ones,
)
from nbv.planning.plan import plan_scan
from nbv.recon.config import MetricsConfig
from nbv.rl.config import EnvConfig
from render.camera import UAVCamera
from render.settings import RenderSettings
from render.viewpoint import Viewpoint
from scenes.spec import SceneSet, SceneSpec

SETTINGS = PlanSettings(camera=UAVCamera(160, 120), render=RenderSettings(spp=1), full_scan=False,
                        metrics=MetricsConfig(n_points=5000))
"""The acceptance's small case: 160x120, scored on the ground truth only, 5000 metric points."""


@pytest.mark.parametrize("views, seed", [(3, 0)])
def test_the_oracle_is_at_least_every_budget_planner_through_nbv_plan(views, seed, tmp_path):
    # Issue 26's acceptance point: each planner planned, captured, fused and scored by `nbv plan` itself.
    scores = {}
    for planner in (*baseline_names(), "oracle"):
        config = PlanConfig(scene=SceneSpec(scene="test_building"), views=views, planner=planner, seed=seed,
                            out=tmp_path / planner, settings=SETTINGS)
        scores[planner] = plan_scan(config)["gt"]["coverage"]
    assert {"random", "circle", "greedy", "infogain", "policy"} <= set(scores)
    assert all(scores["oracle"] >= score for score in scores.values()), str(scores)
    assert scores["oracle"] > min(scores.values()), str(scores)
    plan = json.loads((tmp_path / "oracle" / "plan.json").read_text())
    assert len(plan["viewpoints"]) == views


def test_the_lattice_holds_the_middle_ring():
    config = EnvConfig(scenes=SceneSet(scene=("test_building",)))
    assert len(lattice_viewpoints(config, POOL)) == 756
    assert Viewpoint(2.0, 0.0, np.radians(42.5)) in lattice_viewpoints(config, POOL)


def test_greedy_then_swaps_on_a_toy_pool():
    # Rows: the samples (0-5) each pool view sees. Greedy from row 0 takes row 1 (2 new samples) and reaches
    # 5 of 6; swapping row 0 for row 2 sees all 6. From row 2 greedy finds that at once.
    rows = [[1, 1, 1, 0, 0, 0], [0, 0, 1, 1, 1, 0], [1, 1, 0, 0, 0, 1], [1, 0, 0, 0, 0, 0]]
    seen = np.packbits(np.array(rows, dtype=bool), axis=1)
    assert ones(seen).tolist() == [3, 3, 3, 1]
    assert greedy_cover(seen, 2, first=0) == [0, 1] and covered(seen, [0, 1]) == 5
    assert improve_by_swaps([0, 1], seen) == [2, 1] and covered(seen, [2, 1]) == 6  # the order is kept
    assert greedy_cover(seen, 2, first=2) == [2, 1] and improve_by_swaps([2, 1], seen) == [2, 1]
    assert greedy_cover(seen, 1, first=3) == [3] and improve_by_swaps([3], seen) in ([0], [1], [2])
