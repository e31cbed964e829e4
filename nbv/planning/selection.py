"""The model-selection score (`scripts/select_defaults.py`): what a planner's views see of the true surface.

A run's kept actor and the baselines are scored the way evaluation plans: exact renders, in the env of
`nbv.rl.validate.evaluation_env_config` (no lattice, no training-only reward term), from the start view
of each seed, and the score is the share of the true surface the chosen viewpoints see
(`nbv.recon.visibility`, surface samples seeded by the episode's seed).
"""

from __future__ import annotations

import numpy as np

from nbv.planning.base import Planner
from nbv.planning.world import PlanningWorld
from nbv.recon.visibility import scene_visibility
from nbv.rl.config import EnvConfig
from nbv.rl.validate import evaluation_env_config
from render.viewpoint import viewpoint_to_c2w
from scenes.spec import SceneSet


def episode_coverage(planner: Planner, trained: EnvConfig, scene: str, views: int, seed: int) -> float:
    """Visible-surface coverage of the true mesh by the planner's `views` viewpoints on `scene` from the
    start view of `seed` (exact renders, `evaluation_env_config`; surface samples seeded `seed`)."""
    config = evaluation_env_config(trained, SceneSet(scene=(scene,)))
    world = PlanningWorld(config, seed=seed)
    chosen = planner.plan(world, views)
    loaded = world.target
    poses = [viewpoint_to_c2w(v, loaded.center()) for v in chosen]
    return scene_visibility(loaded, config.camera, seed=seed).coverage(poses)


def validation_score(planner: Planner, trained: EnvConfig, scenes: tuple[str, ...], views: int,
                     episodes: int) -> float:
    """The model-selection score: mean `episode_coverage` (%) over `scenes` x start views 0 .. episodes-1."""
    return 100.0 * float(np.mean([episode_coverage(planner, trained, scene, views, seed)
                                  for scene in scenes for seed in range(episodes)]))
