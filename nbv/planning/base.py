"""The planner interface and the candidate scheme that the greedy planners share (docs/rl.md §10)."""

from __future__ import annotations

from abc import ABC, abstractmethod
from typing import TYPE_CHECKING

import numpy as np

from render.viewpoint import Viewpoint, draw_viewpoint

if TYPE_CHECKING:
    from nbv.planning.world import PlanningWorld
    from nbv.rl.config import EnvConfig


class Planner(ABC):
    """Chooses the viewpoints of one scan."""

    name: str = ""
    """Short name used on the command line and in tables."""
    default_views: int
    """How many viewpoints it plans when `plan` is given None (set by the planners that count their own)."""

    @abstractmethod
    def plan(self, world: PlanningWorld, views: int | None) -> list[Viewpoint]:
        """The viewpoints to capture, in order.

        Args:
            world: the target, the allowed ranges, the camera, the view source and the start view.
            views: how many viewpoints; None for the planner's own count.
        """

    def view_count(self, views: int | None) -> int:
        """`views`, or the planner's own count (`default_views`) where it is None."""
        return self.default_views if views is None else views

    def planning_env(self, own: EnvConfig) -> EnvConfig:
        """The env settings it plans in, given the plan's own (`nbv.planning.plan.scan_env_config`): those
        by default; a policy plans in its training settings."""
        return own


def sample_viewpoints(low: np.ndarray, high: np.ndarray, count: int,
                      rng: np.random.Generator) -> list[Viewpoint]:
    """`count` viewpoints drawn uniformly between `low` and `high` (R, azimuth, elevation)."""
    return [draw_viewpoint(low, high, rng) for _ in range(count)]


def check_candidates(planner: str, candidates: int) -> int:
    """`candidates` itself, or a ValueError naming the planner if it is below 1."""
    if candidates < 1:
        raise ValueError(f"{planner} planner needs at least 1 candidate, got {candidates}")
    return candidates
