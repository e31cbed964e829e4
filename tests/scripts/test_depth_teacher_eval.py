"""`scripts/depth_teacher_eval.py`'s diagnostic planner (round 51): stereo's frames, each fused with the depth
camera's exact depth at exactly the pixels where stereo measures one."""

from __future__ import annotations

import numpy as np

from nbv.planning.infogain import target_grid
from nbv.planning.lookahead import LookaheadPlanner, stereo_partner
from nbv.planning.world import PlanningWorld
from nbv.recon.config import OccupancyConfig
from nbv.recon.occupancy import UNKNOWN
from render.camera import UAVCamera
from render.settings import RenderSettings
from scripts.depth_teacher_eval import StereoMaskedPlanner
from tests.nbv.rl.test_bov_observation import config


def test_the_masked_planner_keeps_stereos_pixels_with_the_exact_depth(monkeypatch):
    world = PlanningWorld(config(camera=UAVCamera(160, 120), render=RenderSettings(spp=4)), seed=3)
    grid = target_grid(world.target, OccupancyConfig(grid_resolution=16))
    stereo = LookaheadPlanner(grid=16, rays=8, depth="stereo").measured(world, grid, world.start)
    assert [at for _, at in stereo] == [world.start, stereo_partner(world.start)]  # the view, its 2nd frame
    assert all(0.2 < np.isfinite(depth).mean() < 1.0 for depth, _ in stereo)  # some of each frame, not all
    camera = LookaheadPlanner(grid=16, rays=8).measured(world, grid, world.start)
    assert len(camera) == 1 and camera[0][1] == world.start and np.isfinite(camera[0][0]).all()

    # Stereo replaced by a hand-set measurement: the left half of each frame measured, at a wrong 9 m.
    half = np.full((120, 160), np.nan, np.float32)
    half[:, :80] = 9.0
    monkeypatch.setattr(LookaheadPlanner, "measured", lambda self, w, g, v: [(half, at) for _, at in stereo])
    masked = StereoMaskedPlanner(grid=16, rays=8, depth="stereo").measured(world, grid, world.start)
    assert [at for _, at in masked] == [at for _, at in stereo]
    for exact, at in masked:
        truth = world.source.render_depth(at)
        assert np.array_equal(exact[:, :80], truth[:, :80]) and np.isnan(exact[:, 80:]).all()
    StereoMaskedPlanner(grid=16, rays=8, depth="stereo").measure(world, grid, world.start)
    assert 0 < (grid.state != UNKNOWN).mean() < 1
