"""View planners behind one interface: the trained policy and the baselines (docs/rl.md).

`Planner.plan(world, views)` returns the viewpoints to capture, in order. The
world (`world.py`) supplies the allowed ranges, the camera, the start
viewpoint, the view source (rendering, features) and a Bag of Views; the
planners that need no images (random, circle, hemisphere) use only the ranges
and the camera. The
interface and the candidate scheme of the greedy planners are in `base.py`; the
planners by name in `registry.py`.

- `RandomPlanner`: viewpoints drawn uniformly in the allowed ranges.
- `CirclePlanner`: evenly spaced azimuths at the middle radius and elevation.
- `GreedyBoVPlanner`: from the start view, at each step render K
  candidate viewpoints drawn uniformly in the ranges and move to the one of
  highest Bag of Views reward (Sec. IV's reward under the plan's `bov` config, no learning).
- `HemispherePlanner`: the full-coverage hemisphere scan (Sec. V-B), the
  paper's reference.
- `OrbitPlanner` (`orbit.py`): one or two fixed rings from the start view's
  azimuth (`orbit`, `orbit2`), the rings chosen on the training buildings.
- `InfoGainPlanner` (`infogain.py`): greedy on volumetric information gain,
  the unknown voxels a candidate would see in an occupancy grid built from the
  depth of the views flown to (model-free, geometric, no appearance).
- `CoverageOraclePlanner` (`oracle.py`): the best, on the reported TSDF
  coverage of the true surface, of every other budget planner's views and its
  own greedy pick; it uses the ground-truth mesh, so it is an upper-bound
  reference of those planners, not a planner a real UAV could run.
- `PolicyPlanner` (`policy.py`): a trained SAC actor from the start view, acting on
  its distribution's mode (`policy:CHECKPOINT`, deterministic) or on seeded
  draws from it (`policy-sample:CHECKPOINT`, the max-entropy policy SAC
  trained, whose action dimensions the reward does not constrain stay spread).
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

from nbv.planning.base import Planner, check_candidates, sample_viewpoints
from render.scan import HemispherePlan, hemisphere_scan
from render.viewpoint import TWO_PI, Viewpoint

if TYPE_CHECKING:
    from nbv.planning.config import PlanSettings
    from nbv.planning.world import PlanningWorld


class RandomPlanner(Planner):
    """Uniformly random viewpoints in the allowed ranges (seeded)."""

    name = "random"

    def __init__(self, seed: int = 0, default_views: int = 13) -> None:
        self.seed, self.default_views = seed, default_views

    def plan(self, world: PlanningWorld, views: int | None) -> list[Viewpoint]:
        """`views` (default 13, the paper's Fig. 1 count) random viewpoints."""
        count = self.default_views if views is None else views
        return sample_viewpoints(world.low, world.high, count, np.random.default_rng(self.seed))


class CirclePlanner(Planner):
    """Evenly spaced azimuths at the middle of the allowed radius and elevation ranges."""

    name = "circle"

    def __init__(self, default_views: int = 13) -> None:
        self.default_views = default_views

    def plan(self, world: PlanningWorld, views: int | None) -> list[Viewpoint]:
        """`views` (default 13) viewpoints on one ring."""
        count = self.default_views if views is None else views
        mid = (world.low + world.high) / 2.0
        return [Viewpoint(float(mid[0]), TWO_PI * k / count, float(mid[2])) for k in range(count)]


class HemispherePlanner(Planner):
    """The full hemisphere scan at the middle radius (288 views with the default camera)."""

    name = "hemisphere"

    def plan(self, world: PlanningWorld, views: int | None) -> list[Viewpoint]:
        """Every viewpoint of the scan (`views`, if given, must not be smaller than it)."""
        radius = (world.env.radius_min + world.env.radius_max) / 2.0
        scan = hemisphere_scan(world.camera, HemispherePlan(radius=radius))
        if views is not None and views < len(scan):
            raise ValueError(f"the hemisphere scan has {len(scan)} views; --views {views} would cut it")
        return scan


class GreedyBoVPlanner(Planner):
    """Greedy Bag of Views: move to the best of K rendered random candidates at each step."""

    name = "greedy"

    def __init__(self, candidates: int = 8, seed: int = 0, default_views: int = 13) -> None:
        self.candidates = check_candidates("greedy", candidates)
        self.seed, self.default_views = seed, default_views

    def plan(self, world: PlanningWorld, views: int | None) -> list[Viewpoint]:
        """The start view, then `views - 1` greedy moves (default 13 views in all)."""
        rng = np.random.default_rng(self.seed)
        source, bov, start = world.source, world.bov, world.start
        bov.update(source.capture(start)[1], start.azimuth, start.elevation)  # as the env learns its first
        chosen = [start]
        for _ in range((self.default_views if views is None else views) - 1):
            best, best_reward, best_descriptors = None, -math.inf, None
            for view in sample_viewpoints(world.low, world.high, self.candidates, rng):
                _, descriptors = source.capture(view)
                reward = bov.reward(descriptors, view.azimuth, view.elevation, commit=False)
                if reward > best_reward:
                    best, best_reward, best_descriptors = view, reward, descriptors
            bov.update(best_descriptors, best.azimuth, best.elevation)
            chosen.append(best)
        return chosen


def random_planner(settings: PlanSettings, seed: int, checkpoint: str | None) -> RandomPlanner:
    """The registry's `random`."""
    return RandomPlanner(seed)


def circle_planner(settings: PlanSettings, seed: int, checkpoint: str | None) -> CirclePlanner:
    """The registry's `circle`."""
    return CirclePlanner()


def hemisphere_planner(settings: PlanSettings, seed: int, checkpoint: str | None) -> HemispherePlanner:
    """The registry's `hemisphere`."""
    return HemispherePlanner()


def greedy_planner(settings: PlanSettings, seed: int, checkpoint: str | None) -> GreedyBoVPlanner:
    """The registry's `greedy`: K = `settings.candidates`."""
    return GreedyBoVPlanner(settings.candidates, seed)
