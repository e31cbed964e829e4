"""Volumetric information gain: greedy on unknown voxels, model-free, from the depth of the views flown to.

From the start view, each step draws K candidate viewpoints exactly as the
greedy Bag of Views planner does (`sample_viewpoints`, the same seeded stream)
and moves to the one of highest gain in an occupancy grid
(`nbv.recon.occupancy`): the number of unknown voxels its rays would reach, each
ray stopping at the first occupied voxel. That is the view gain of Isler et al.
("An Information Gain Formulation for Active Volumetric 3D Reconstruction",
ICRA 2016), G(v) = sum over the voxels x that v's rays traverse of I(x), with
their "unobserved voxel" information I(x) = 1 for an unknown voxel and 0
otherwise, as compared by Delmerico et al. ("A comparison of volumetric
information gain metrics for active 3D object reconstruction", Autonomous
Robots 42, 2018); here with a ternary grid and hard visibility in place of
their occupancy probabilities, and each voxel counted once per view. The grid covers the target's bounding box
padded by a margin (the region of interest these methods are given; the env
already aims every view at its centre) and is updated with the z-depth image the
camera returns at each view flown to (`ViewSource.render_depth`). Candidates are
not rendered: their gain is ray cast through the grid, and no RGB image is
rendered at all. No appearance, no model. With `--min-matches K` (beyond the paper;
`nbv.planning.linking`) candidates are also rendered and matched, and only those linked to a flown view
may be flown.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from nbv.planning.base import Planner, check_candidates, sample_viewpoints
from nbv.planning.linking import FlownLinks, pick_linked
from nbv.recon.config import OccupancyConfig
from nbv.recon.occupancy import FREE, OccupancyGrid
from nbv.sfm.config import LinkSettings
from render.viewpoint import Viewpoint, viewpoint_to_c2w
from scenes.model import Scene

if TYPE_CHECKING:
    from nbv.planning.config import PlanSettings
    from nbv.planning.world import PlanningWorld


def target_grid(scene: Scene, config: OccupancyConfig, steep_deg: float = 0.0,
                sectors: int = 4, padding_free: bool = False) -> OccupancyGrid:
    """An all-unknown grid over the scene's target bounds, padded by the margin on the sides and the top
    (`steep_deg` and `sectors`: the grid's sight directions, which only the look-ahead's sides use); with
    `padding_free` the voxels wholly outside the bounds start free: no target surface can be there."""
    if not scene.parts:
        raise ValueError(f"scene {scene.name!r} is a Mitsuba XML file: the infogain planner needs the "
                         "target's bounds, which it does not give")
    lower, upper = scene.bounds()
    margin = config.grid_margin_m
    grid = OccupancyGrid(lower - [margin, margin, 0.0], upper + margin, config.grid_resolution, config.votes,
                         steep_deg, sectors)
    if padding_free:
        grid.state[outside(grid, lower, upper)] = FREE
    return grid


def outside(grid: OccupancyGrid, lower: np.ndarray, upper: np.ndarray) -> np.ndarray:
    """Which of the grid's voxels (bool, the grid's shape) lie wholly outside the box `lower` to `upper`."""
    corner = grid.lower + np.moveaxis(np.indices(grid.state.shape), 0, -1) * grid.voxel_size
    return np.any((corner >= upper - 1e-9) | (corner + grid.voxel_size <= lower + 1e-9), axis=-1)


class InfoGainPlanner(Planner):
    """Greedy on the unknown voxels a candidate would see, in a grid built from the depth flown to.

    Args:
        candidates: candidate viewpoints per step (K, as the greedy planner's).
        seed: seed of the candidates.
        grid: the occupancy grid and ray strides.
        default_views: views when none are asked for (13, the paper's Fig. 1).
    """

    name = "infogain"

    def __init__(self, candidates: int = 8, seed: int = 0, grid: OccupancyConfig = OccupancyConfig(),
                 default_views: int = 13, links: LinkSettings = LinkSettings()) -> None:
        self.candidates = check_candidates("infogain", candidates)
        self.seed, self.grid, self.default_views, self.links = seed, grid, default_views, links

    def plan(self, world: PlanningWorld, views: int | None) -> list[Viewpoint]:
        """The start view, then `views - 1` moves, each to the candidate of highest gain; with `links` on
        (--min-matches K, beyond the paper), of highest gain among those linked to a flown view (the
        candidates' RGB images rendered to match them; `nbv.planning.linking`)."""
        rng = np.random.default_rng(self.seed)
        scene, camera = world.target, world.camera
        grid, center = target_grid(scene, self.grid), scene.center()
        view = world.start
        chosen = [view]
        flown = FlownLinks(self.links, camera.K) if self.links.on else None
        if flown is not None:
            flown.add(view, world.source.features_at(view))
        for _ in range(self.view_count(views) - 1):
            grid.integrate(world.source.render_depth(view), camera.K, viewpoint_to_c2w(view, center),
                           self.grid.integrate_ray_stride)
            candidates = sample_viewpoints(world.low, world.high, self.candidates, rng)
            gains = [grid.gain(camera.K, viewpoint_to_c2w(c, center), camera.width, camera.height,
                               self.grid.gain_ray_stride) for c in candidates]
            if flown is None:
                view = candidates[int(np.argmax(gains))]
            else:
                looked = [world.source.features_at(c) for c in candidates]
                links = [flown.matches(c, f) for c, f in zip(candidates, looked, strict=True)]
                k = pick_linked(gains, links, self.links.min_matches)
                view = candidates[k]
                flown.add(view, looked[k])
            chosen.append(view)
        return chosen


def infogain_planner(settings: PlanSettings, seed: int, checkpoint: str | None) -> InfoGainPlanner:
    """The registry's `infogain`: K = `settings.candidates`, the grid of `settings.occupancy`, registrability
    `settings.links`."""
    return InfoGainPlanner(settings.candidates, seed, settings.occupancy, links=settings.links)
