"""The model-selection score: the visible coverage of a planner's exact-render views, counted directly."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import torch

from nbv.planning.planners import CirclePlanner, RandomPlanner
from nbv.planning.selection import episode_coverage, validation_score
from nbv.recon.visibility import scene_visibility
from nbv.rl.agent import make_actor
from nbv.rl.config import LatticeConfig
from nbv.rl.env import NBVEnv
from nbv.rl.rollout import policy_views
from render.viewpoint import Viewpoint, viewpoint_to_c2w
from scenes.catalog import load_scene
from tests.nbv.rl.test_train import tiny

LATTICE = LatticeConfig(enabled=True, lattice_radii=1, lattice_azimuths=4, lattice_elevations=2)


class Mode:
    """An untrained actor's mode as a planner, flying its own env on the world's view source."""

    def __init__(self, config) -> None:
        torch.manual_seed(0)
        self.actor = make_actor(config.env.history, config.env.obs_size, config.network)
        self.envs: list[NBVEnv] = []

    def plan(self, world, views: int | None) -> list[Viewpoint]:
        env = NBVEnv(world.env, seed=world.seed, source=world.source)
        self.envs.append(env)
        return policy_views(self.actor, env, views)


def test_the_score_is_the_visible_coverage_of_the_planned_views(tmp_path, monkeypatch):
    import nbv.rl.env

    monkeypatch.setenv("NBV_CACHE_DIR", str(tmp_path))
    config = tiny(None, 2)
    trained = replace(config.env, lattice=LATTICE)  # trained on a lattice: scored on exact renders
    scene = load_scene("test_building")
    mid_r = (trained.radius_min + trained.radius_max) / 2
    mid_el = math.radians((trained.elevation_min_deg + trained.elevation_max_deg) / 2)
    ring = [Viewpoint(mid_r, 2 * math.pi * k / 3, mid_el) for k in range(3)]  # the circle, by hand
    expected = [scene_visibility(scene, trained.camera, seed=seed).coverage(
        [viewpoint_to_c2w(v, scene.center()) for v in ring]) for seed in (0, 1)]
    monkeypatch.setattr(nbv.rl.env, "scene_visibility", None)  # the scoring env itself ray-casts nothing
    circle = [episode_coverage(CirclePlanner(), trained, "test_building", 3, seed) for seed in (0, 1)]
    assert circle == expected and 0 < min(circle) <= 1
    mode = Mode(config)
    for planner in (mode, RandomPlanner(seed=3)):
        scores = [episode_coverage(planner, trained, "test_building", 3, seed) for seed in (0, 1)]
        assert validation_score(planner, trained, ("test_building",), 3, 2) == 100.0 * float(np.mean(scores))
    assert all(not env.config.lattice.enabled and env.source.views_rendered > 0 for env in mode.envs)
