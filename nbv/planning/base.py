"""The planner interface and the candidate scheme that the greedy planners share (docs/rl.md §10)."""

from __future__ import annotations

from abc import ABC, abstractmethod

import numpy as np

from nbv.rl.config import EnvConfig
from nbv.rl.env import NBVEnv
from render.viewpoint import Viewpoint


class Planner(ABC):
    """Chooses the viewpoints of one scan."""

    name: str = ""
    """Short name used on the command line and in tables."""

    @abstractmethod
    def plan(self, env: NBVEnv, views: int | None) -> list[Viewpoint]:
        """The viewpoints to capture, in order.

        Args:
            env: a one-worker env on the target scene, freshly seeded.
            views: how many viewpoints; None for the planner's own count.
        """


def sample_viewpoints(config: EnvConfig, count: int, rng: np.random.Generator) -> list[Viewpoint]:
    """`count` viewpoints drawn uniformly in the config's ranges of R, azimuth and elevation."""
    low, high = config.low, config.high
    return [Viewpoint(*map(float, low + rng.random(3) * (high - low))) for _ in range(count)]


def check_candidates(planner: str, candidates: int) -> int:
    """`candidates` itself, or a ValueError naming the planner if it is below 1."""
    if candidates < 1:
        raise ValueError(f"{planner} planner needs at least 1 candidate, got {candidates}")
    return candidates
