"""The information-gain planner: greedy on its grid's gain, from the depth of the views flown to only."""

from __future__ import annotations

import numpy as np

from nbv.bov.config import BoVConfig
from nbv.features.config import FeatureConfig
from nbv.planning.config import PlanSettings
from nbv.planning.infogain import InfoGainPlanner, outside, target_grid
from nbv.planning.registry import make_planner
from nbv.planning.world import PlanningWorld
from nbv.recon.config import OccupancyConfig
from nbv.recon.occupancy import FREE, UNKNOWN, OccupancyGrid
from nbv.rl.config import EnvConfig
from render.camera import UAVCamera
from render.settings import RenderSettings
from scenes import load_scene
from scenes.spec import SceneSet

CONFIG = EnvConfig(scenes=SceneSet(scene=("test_building",)), camera=UAVCamera(64, 48),
                   render=RenderSettings(spp=1),
                   bov=BoVConfig(ranges=8, sift=FeatureConfig(backend="opencv")), obs_size=32)


def test_infogain_moves_to_the_candidate_of_highest_gain(monkeypatch):
    gains = iter([3, 9, 1, 4, 0, 2, 8, 5])  # step 1: candidate 1; step 2: candidate 2 (of 4 each)
    monkeypatch.setattr(OccupancyGrid, "gain", lambda self, *args: next(gains))
    world = PlanningWorld(CONFIG, seed=0)
    views = InfoGainPlanner(candidates=4, seed=0).plan(world, 3)
    rng = np.random.default_rng(0)
    steps = [[tuple(CONFIG.low + rng.random(3) * (CONFIG.high - CONFIG.low)) for _ in range(4)]
             for _ in range(2)]
    assert [tuple(v.as_array()) for v in views[1:]] == [steps[0][1], steps[1][2]]
    # Candidates are ray cast, not rendered: no RGB image, and the depth of the views flown to before the
    # last, whose depth no decision needs.
    assert world.source.views_rendered == 0 and world.source.depths_rendered == 2


def test_infogain_is_seeded_starts_at_the_start_view_and_plans_in_the_ranges():
    world = PlanningWorld(CONFIG, seed=2)
    views = make_planner("infogain", PlanSettings(candidates=3), seed=2).plan(world, 4)
    low, high = CONFIG.low, CONFIG.high
    assert len(views) == 4 and views[0] == world.start
    assert all(np.all(low - 1e-9 <= v.as_array()) and np.all(v.as_array() <= high) for v in views)
    three = PlanSettings(candidates=3)
    assert views == make_planner("infogain", three, seed=2).plan(PlanningWorld(CONFIG, seed=2), 4)
    assert views[0] == make_planner("greedy", three, seed=2).plan(PlanningWorld(CONFIG, seed=2), 1)[0]


def test_the_grid_covers_the_padded_target_bounds_and_starts_unknown():
    scene = load_scene("test_building")
    grid = target_grid(scene, OccupancyConfig(grid_resolution=32, grid_margin_m=0.05))
    lower, upper = scene.bounds()
    assert np.allclose(grid.lower, lower - [0.05, 0.05, 0.0])  # the base stays on the ground
    assert np.all(grid.upper >= upper + 0.05 - 1e-9) and max(grid.state.shape) == 32
    assert np.all(grid.state == UNKNOWN)


def test_the_padding_outside_the_targets_bounds_starts_free_only_when_asked():
    grid = OccupancyGrid(np.zeros(3), np.array([4.0, 4.0, 2.0]), resolution=4)  # 1 m voxels, 4 x 4 x 2
    out = outside(grid, np.array([1.0, 1.0, 0.0]), np.array([3.0, 3.0, 1.0]))
    assert out.shape == (4, 4, 2) and (~out).sum() == 4 and not out[1:3, 1:3, 0].any()
    assert outside(grid, np.array([0.5, 0.5, 0.0]), np.array([3.0, 3.0, 1.0]))[0:3, 0:3, 0].sum() == 0
    scene = load_scene("test_building")
    plain = target_grid(scene, OccupancyConfig(grid_resolution=16))
    padded = target_grid(scene, OccupancyConfig(grid_resolution=16), padding_free=True)
    assert (plain.state == UNKNOWN).all()
    lower, upper = scene.bounds()
    assert (padded.state == FREE).sum() == outside(padded, lower, upper).sum() > 0
    assert (padded.state[~outside(padded, lower, upper)] == UNKNOWN).all()
