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
- Registrability (`--min-matches K`, beyond the paper; `linking.py`): random, greedy and infogain fly
  only candidates sharing >= K verified matches with a view flown (off by default, as before).
- `PolicyPlanner` (`policy.py`): a trained SAC actor from the start view, acting on
  its distribution's mode (`policy:CHECKPOINT`, deterministic) or on seeded
  draws from it (`policy-sample:CHECKPOINT`, the max-entropy policy SAC
  trained, whose action dimensions the reward does not constrain stay spread).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from nbv.planning.base import Planner, check_candidates, sample_viewpoints
from nbv.planning.linking import FlownLinks, first_best, pick_linked
from nbv.sfm.config import LinkSettings
from render.scan import HemispherePlan, hemisphere_scan
from render.viewpoint import TWO_PI, Viewpoint

if TYPE_CHECKING:
    import torch

    from nbv.features.sift import Features
    from nbv.features.source import ViewSource
    from nbv.planning.config import PlanSettings
    from nbv.planning.world import PlanningWorld


class RandomPlanner(Planner):
    """Uniformly random viewpoints in the allowed ranges (seeded). With `links` on (--min-matches K, beyond
    the paper; `nbv.planning.linking`): each view after the first is the first of `candidates` draws
    linked to a view flown (rendered to match them)."""

    name = "random"

    def __init__(self, seed: int = 0, default_views: int = 13, links: LinkSettings = LinkSettings(),
                 candidates: int = 8) -> None:
        self.seed, self.default_views, self.links = seed, default_views, links
        self.candidates = check_candidates("random", candidates)

    def plan(self, world: PlanningWorld, views: int | None) -> list[Viewpoint]:
        """`views` (default 13, the paper's Fig. 1 count) random viewpoints."""
        count = self.view_count(views)
        rng = np.random.default_rng(self.seed)
        if not self.links.on:
            return sample_viewpoints(world.low, world.high, count, rng)
        flown = FlownLinks(self.links, world.camera.K)
        chosen = sample_viewpoints(world.low, world.high, min(count, 1), rng)
        for view in chosen:
            flown.add(view, world.source.features_at(view))
        for _ in range(count - len(chosen)):
            candidates = sample_viewpoints(world.low, world.high, self.candidates, rng)
            looked = [world.source.features_at(view) for view in candidates]
            links = [flown.matches(view, f) for view, f in zip(candidates, looked, strict=True)]
            k = pick_linked([0.0] * len(candidates), links, self.links.min_matches)
            flown.add(candidates[k], looked[k])
            chosen.append(candidates[k])
        return chosen


class CirclePlanner(Planner):
    """Evenly spaced azimuths at the middle of the allowed radius and elevation ranges."""

    name = "circle"

    def __init__(self, default_views: int = 13) -> None:
        self.default_views = default_views

    def plan(self, world: PlanningWorld, views: int | None) -> list[Viewpoint]:
        """`views` (default 13) viewpoints on one ring."""
        count = self.view_count(views)
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

    def __init__(self, candidates: int = 8, seed: int = 0, default_views: int = 13,
                 links: LinkSettings = LinkSettings()) -> None:
        self.candidates = check_candidates("greedy", candidates)
        self.seed, self.default_views, self.links = seed, default_views, links

    def plan(self, world: PlanningWorld, views: int | None) -> list[Viewpoint]:
        """The start view, then `views - 1` greedy moves (default 13 views in all); with `links` on
        (--min-matches K, beyond the paper), each move to the best candidate linked to a flown view
        (`nbv.planning.linking`)."""
        rng = np.random.default_rng(self.seed)
        source, bov, start = world.source, world.bov, world.start
        flown = FlownLinks(self.links, world.camera.K) if self.links.on else None
        descriptors, features = look(source, start, flown)
        bov.update(descriptors, start.azimuth, start.elevation)  # as the env learns its first
        chosen = [start]
        if flown is not None:
            flown.add(start, features)
        for _ in range(self.view_count(views) - 1):
            candidates = sample_viewpoints(world.low, world.high, self.candidates, rng)
            looked = [look(source, view, flown) for view in candidates]
            rewards = [bov.reward(d, view.azimuth, view.elevation, commit=False)
                       for view, (d, _) in zip(candidates, looked, strict=True)]
            if flown is None:
                k = first_best(rewards)
            else:
                links = [flown.matches(view, f) for view, (_, f) in zip(candidates, looked, strict=True)]
                k = pick_linked(rewards, links, self.links.min_matches)
                flown.add(candidates[k], looked[k][1])
            bov.update(looked[k][0], candidates[k].azimuth, candidates[k].elevation)
            chosen.append(candidates[k])
        return chosen


def look(source: ViewSource, view: Viewpoint,
         flown: FlownLinks | None) -> tuple[torch.Tensor, Features | None]:
    """A candidate's descriptors, rendered as `capture` renders them, and its features when views are
    matched (`flown`), else None."""
    if flown is None:
        return source.capture(view)[1], None
    features = source.features_at(view)
    return features.descriptors, features


def random_planner(settings: PlanSettings, seed: int, checkpoint: str | None) -> RandomPlanner:
    """The registry's `random` (with --min-matches: K = `settings.candidates` draws per view)."""
    return RandomPlanner(seed, links=settings.links, candidates=settings.candidates)


def circle_planner(settings: PlanSettings, seed: int, checkpoint: str | None) -> CirclePlanner:
    """The registry's `circle`."""
    return CirclePlanner()


def hemisphere_planner(settings: PlanSettings, seed: int, checkpoint: str | None) -> HemispherePlanner:
    """The registry's `hemisphere`."""
    return HemispherePlanner()


def greedy_planner(settings: PlanSettings, seed: int, checkpoint: str | None) -> GreedyBoVPlanner:
    """The registry's `greedy`: K = `settings.candidates`, registrability `settings.links`."""
    return GreedyBoVPlanner(settings.candidates, seed, links=settings.links)
