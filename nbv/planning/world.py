"""What a planner plans in: the target, the allowed ranges, the camera, a view source, a start view.

`PlanningWorld` replaces the RL env as the planners' input: random, circle and
hemisphere read only the ranges and the camera; greedy and infogain render
through the view source (`nbv.features.source.ViewSource`); the oracle reads
the target's true mesh; the policy builds its own env on the same view source
(`nbv.planning.policy`). The start viewpoint and the Bag of Views are those an
`NBVEnv` on the same settings and seed starts its first episode with: the
start drawn by `render.viewpoint.draw_viewpoint` from
`np.random.default_rng(seed)`, as the env draws it, the bag made by the env config's `bov` with the
seed and the elevation bounds, so every planner starts where the env would.
"""

from __future__ import annotations

from functools import cached_property
from typing import TYPE_CHECKING

import numpy as np

from nbv.bov.bag import BagOfViews
from nbv.features.source import ViewSource
from render.viewpoint import Viewpoint, draw_viewpoint

if TYPE_CHECKING:
    from nbv.rl.config import EnvConfig
    from render.camera import UAVCamera
    from scenes.model import Scene
    from scenes.spec import SceneSpec


def start_view(env: EnvConfig, seed: int) -> Viewpoint:
    """The start view of a plan in `env` with `seed`: drawn as `NBVEnv` draws its first episode's start."""
    return draw_viewpoint(env.low, env.high, np.random.default_rng(int(seed)))


class PlanningWorld:
    """One target to plan for under one env config and seed.

    Args:
        env: the env the planner plans in: its first scene is the target; its ranges, camera, render
            settings, frame size and Bag of Views are the plan's.
        seed: seed of the start view, the renders and the Bag of Views.
        source: the view source to render with; default: a new one on `env`'s settings.
    """

    def __init__(self, env: EnvConfig, seed: int = 0, source: ViewSource | None = None) -> None:
        self.env, self.seed = env, int(seed)
        self.scene: SceneSpec = env.scenes.specs()[0]
        self.low, self.high = env.low, env.high
        self.camera: UAVCamera = env.camera
        self.source = source or ViewSource(env.camera, env.render, env.bov.feature_config(), env.obs_size,
                                           self.seed)
        self.source.select(self.scene)
        self.start = start_view(env, self.seed)

    @property
    def target(self) -> Scene:
        """The target scene, loaded (its true mesh included: only the oracle reads it)."""
        return self.source.load(self.scene)

    @cached_property
    def bov(self) -> BagOfViews:
        """A fresh Bag of Views from the env's `bov` settings, seeded as the env seeds its own."""
        bounds = (float(self.low[2]), float(self.high[2]))
        return BagOfViews.from_config(self.env.bov, seed=self.seed, elevation_bounds=bounds)
