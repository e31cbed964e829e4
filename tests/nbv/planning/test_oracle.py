"""The coverage oracle: never below another planner in true-surface coverage; its greedy and local search."""

from __future__ import annotations

import numpy as np
import pytest

from nbv.bov.config import BoVConfig
from nbv.features.config import FeatureConfig
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
from nbv.planning.registry import make_planner
from nbv.planning.world import PlanningWorld
from nbv.recon.visibility import scene_visibility
from nbv.rl.config import EnvConfig
from render.camera import UAVCamera
from render.settings import RenderSettings
from render.viewpoint import Viewpoint, viewpoint_to_c2w
from scenes.spec import SceneSet

CONFIG = EnvConfig(scenes=SceneSet(scene=("test_building",)), camera=UAVCamera(64, 48),
                   render=RenderSettings(spp=1),
                   bov=BoVConfig(ranges=8, sift=FeatureConfig(backend="opencv")), obs_size=32)


def coverage(views: list[Viewpoint], seed: int) -> float:
    """The oracle's own measure: the share of the true surface's samples (its seed) the views see."""
    scene = CONFIG.scenes.specs()[0].load()
    visibility = scene_visibility(scene, CONFIG.camera, seed=seed)
    seen = np.zeros(len(visibility.samples), dtype=bool)
    for view in views:
        seen |= visibility.seen(viewpoint_to_c2w(view, scene.center()))
    return float(seen.mean())


@pytest.mark.parametrize("views, seed", [(3, 0), (4, 3), (4, 5)])
def test_the_oracle_is_never_below_another_planner(views, seed):
    # Issue 14's acceptance point, at one budget and seed. At 4 views the circle sees the whole surface:
    # greedy on the random candidates alone (seed 3: 97.3 %) or on the lattice without restarts (seed 3:
    # 99.99 %, seed 5: 99.92 %) fell short of it.
    planners = {name: make_planner(name, PlanSettings(), seed=seed) for name in
                ("random", "circle", "greedy", "infogain", "oracle")}
    scores = {name: coverage(planner.plan(PlanningWorld(CONFIG, seed=seed), views), seed)
              for name, planner in planners.items()}
    assert all(scores["oracle"] >= score for score in scores.values()), str(scores)
    assert scores["oracle"] > min(scores.values())


def test_the_oracle_plans_in_the_ranges_and_is_seeded():
    planner = CoverageOraclePlanner(candidates=2, seed=1)
    world = PlanningWorld(CONFIG, seed=1)
    views = planner.plan(world, 3)
    assert world.source.views_rendered == 0 and world.source.setup_seconds == 0.0  # ray casts only
    low, high = CONFIG.low, CONFIG.high
    assert len(views) == 3 and all(np.all(low - 1e-9 <= v.as_array()) and np.all(v.as_array() <= high)
                                   for v in views)
    assert views == CoverageOraclePlanner(candidates=2, seed=1).plan(PlanningWorld(CONFIG, seed=1), 3)
    assert len(lattice_viewpoints(CONFIG, POOL)) == 756
    assert Viewpoint(2.0, 0.0, np.radians(42.5)) in lattice_viewpoints(CONFIG, POOL)  # the middle ring


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
