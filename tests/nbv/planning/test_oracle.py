"""The coverage oracle: never below another budget planner on `nbv plan`'s coverage; its greedy and swaps."""

from __future__ import annotations

import importlib.util
import json
from pathlib import Path

import numpy as np
import pytest

from nbv.planning.config import PlanSettings
from nbv.planning.oracle import (
    POOL,
    CoverageOraclePlanner,
    covered,
    greedy_cover,
    improve_by_swaps,
    lattice_viewpoints,
    ones,
)
from nbv.planning.world import PlanningWorld
from nbv.recon.config import MetricsConfig
from nbv.recon.fused_coverage import FusedCoverage
from nbv.rl.config import EnvConfig
from render.camera import UAVCamera
from render.renderer import MitsubaRenderer
from render.settings import RenderSettings
from render.viewpoint import Viewpoint
from scenes import load_scene
from scenes.spec import SceneSet

_SPEC = importlib.util.spec_from_file_location("oracle_bound",
                                               Path(__file__).parents[3] / "scripts" / "oracle_bound.py")
SCRIPT = importlib.util.module_from_spec(_SPEC)
_SPEC.loader.exec_module(SCRIPT)

SETTINGS = PlanSettings(camera=UAVCamera(64, 48), render=RenderSettings(spp=1), full_scan=False,
                        metrics=MetricsConfig(n_points=5000))
"""A small case: 64x48 (160x120: the script's default), scored on the ground truth only, 5000 points."""


def test_the_oracle_is_at_least_every_budget_planner_through_nbv_plan(tmp_path):
    # Issue 26's acceptance point, by scripts/oracle_bound.py (160x120 there): each planner planned,
    # captured, fused and scored by `nbv plan` itself.
    rows = SCRIPT.bound_rows("test_building", SETTINGS, [3], [0], tmp_path)
    coverage = rows[0]["coverage"]
    assert {"random", "circle", "greedy", "infogain", "policy", "oracle"} <= set(coverage)
    assert SCRIPT.bounded(rows) and all(coverage["oracle"] >= score for score in coverage.values()), rows
    assert coverage["oracle"] > min(coverage.values()), rows
    plan = json.loads((tmp_path / "oracle-v3-seed0" / "plan.json").read_text())
    assert len(plan["viewpoints"]) == 3
    scene = load_scene("test_building")  # the oracle's in-memory score is nbv plan's number, to the bit
    scorer = FusedCoverage(MitsubaRenderer(scene, SETTINGS.camera, SETTINGS.render), scene, SETTINGS.recon,
                           SETTINGS.metrics, seed=0)
    assert scorer.coverage([Viewpoint(*v) for v in plan["viewpoints"]]) == plan["gt"]["coverage"]
    assert not SCRIPT.bounded([{"coverage": {"oracle": 0.5, "random": 0.6}}])


def test_the_oracle_refuses_a_world_off_the_plans_settings():
    world = PlanningWorld(EnvConfig(scenes=SceneSet(scene=("test_building",)), camera=UAVCamera(64, 48)))
    with pytest.raises(ValueError, match="differ from the plan's, so its scores would not be the report's"):
        CoverageOraclePlanner(PlanSettings()).plan(world, 2)  # the plan's camera: 320x240


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
