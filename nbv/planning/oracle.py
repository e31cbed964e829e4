"""The coverage oracle: greedy on the true surface, an upper-bound reference that uses the model.

Candidates (the pool): the start view; the K random viewpoints per step
that the greedy Bag of Views planner is offered (`sample_viewpoints`, the same
seeded stream, all steps' at once); and a fixed lattice over the allowed ranges
(`POOL`, 756 viewpoints, the middle ring among them). The oracle picks `views`
of them that see the most ground-truth surface samples together: the greedy
rule for maximum coverage (Nemhauser, Wolsey and Fisher, "An analysis of
approximations for maximizing submodular set functions", Mathematical
Programming 14, 1978; the classic view-planning heuristic of Scott, Roth and
Rivest, "View planning for automated three-dimensional object reconstruction
and inspection", ACM Computing Surveys 35, 2003), started from the start view
and from each of the `starts - 1` best single views, each run improved by
single swaps while a swap covers more (`improve_by_swaps`); the best run wins.
It is free to leave the start view, so it bounds the planners that start
elsewhere (random, circle) too.

Seen means `nbv.recon.visibility`: the target mesh is sampled once per plan
(area-uniform, the planner's seed) and a sample counts as seen by a view when it
is in frame and no part of the scene (ground included) hides it, by ray casting
the true meshes. Nothing is rendered.

It reads the ground-truth mesh, which no real planner has: it is a reference
for what a planner could reach, labelled as an upper bound in tables and docs.
It is not provably optimal (greedy and local search over a finite pool; greedy
on the random candidates alone, or without the swaps and restarts, was beaten
by the circle's four views on `test_building`); the tests check that the other
planners do not beat it there.
"""

from __future__ import annotations

from dataclasses import replace
from typing import TYPE_CHECKING

import numpy as np

from nbv.planning.base import Planner, check_candidates, sample_viewpoints
from nbv.recon.visibility import scene_visibility
from nbv.rl.config import LatticeConfig
from nbv.rl.lattice import lattice_axes
from render.viewpoint import Viewpoint, viewpoint_to_c2w

if TYPE_CHECKING:
    from nbv.planning.config import PlanSettings
    from nbv.planning.world import PlanningWorld
    from nbv.rl.config import EnvConfig

POOL = LatticeConfig(lattice_radii=3, lattice_azimuths=36, lattice_elevations=7)
"""The oracle's fixed candidates: a lattice over the allowed ranges whose odd counts hold the middle
radius and elevation, 10 degrees apart in azimuth (756 viewpoints)."""


def lattice_viewpoints(config: EnvConfig, lattice: LatticeConfig) -> list[Viewpoint]:
    """Every node of a view lattice over the env's ranges (`nbv.rl.lattice.lattice_axes`)."""
    radii, azimuths, elevations = lattice_axes(replace(config, lattice=lattice))
    return [Viewpoint(float(r), float(a), float(e)) for r in radii for a in azimuths for e in elevations]


class CoverageOraclePlanner(Planner):
    """The pool's views that see the most true surface (greedy, restarts, swaps): an upper bound that uses
    the ground-truth mesh.

    Args:
        candidates: random candidate viewpoints per step (K, the greedy planner's stream).
        seed: seed of the candidates and of the surface samples.
        points: ground-truth surface samples.
        tolerance_m: depth slack of the visibility test, metres.
        pool: the fixed lattice of candidates over the env's ranges.
        starts: greedy runs: from the start view and from the best single views.
        default_views: views when none are asked for (13, the paper's Fig. 1).
    """

    name = "oracle"

    def __init__(self, candidates: int = 8, seed: int = 0, points: int = 20_000, tolerance_m: float = 0.02,
                 pool: LatticeConfig = POOL, starts: int = 8, default_views: int = 13) -> None:
        self.candidates = check_candidates("oracle", candidates)
        if starts < 1:
            raise ValueError(f"oracle planner needs at least 1 greedy start, got {starts}")
        self.seed, self.pool, self.starts, self.default_views = seed, pool, starts, default_views
        self.points, self.tolerance_m = points, tolerance_m

    def plan(self, world: PlanningWorld, views: int | None) -> list[Viewpoint]:
        """`views` viewpoints of the pool that together see the most surface samples, in greedy order."""
        count = self.default_views if views is None else views
        rng = np.random.default_rng(self.seed)
        scene = world.target
        visibility = scene_visibility(scene, world.camera, self.points, self.tolerance_m, self.seed)
        center = scene.center()
        pool = [world.start, *sample_viewpoints(world.low, world.high, self.candidates * (count - 1), rng),
                *lattice_viewpoints(world.env, self.pool)]
        seen = np.packbits([visibility.seen(viewpoint_to_c2w(view, center)) for view in pool], axis=1)
        singles = ones(seen)
        starts = dict.fromkeys([0, *np.argsort(-singles, kind="stable")[:self.starts - 1].tolist()])
        best = max((improve_by_swaps(greedy_cover(seen, count, first), seen) for first in starts),
                   key=lambda chosen: covered(seen, chosen))
        return [pool[i] for i in best]


POPCOUNT = np.array([bin(byte).count("1") for byte in range(256)], dtype=np.int64)
"""Set bits of each byte value (numpy < 2 has no `bitwise_count`)."""


def ones(bits: np.ndarray) -> np.ndarray | int:
    """Set bits along the last axis of a uint8 array."""
    return POPCOUNT[bits].sum(axis=-1)


def covered(seen: np.ndarray, chosen: list[int]) -> int:
    """Samples seen by at least one chosen row of a (pool, bytes) bit-packed visibility matrix."""
    return int(ones(np.bitwise_or.reduce(seen[chosen], axis=0)))


def greedy_cover(seen: np.ndarray, count: int, first: int) -> list[int]:
    """`first`, then `count - 1` rows of the bit-packed (pool, bytes) visibility, each adding the most
    samples not yet seen (ties: the lowest index)."""
    chosen, union = [first], seen[first].copy()
    for _ in range(count - 1):
        best = int(np.argmax(ones(seen & ~union)))
        chosen.append(best)
        union |= seen[best]
    return chosen


def improve_by_swaps(chosen: list[int], seen: np.ndarray, passes: int = 5) -> list[int]:
    """Local search: replace a chosen row by the pool's best while that sees more samples in all.

    Args:
        chosen: rows of `seen`, in order; a swap keeps the order (the replacement takes the row's place).
        seen: (pool, bytes) bit-packed: the samples each pool viewpoint sees.
        passes: most sweeps over the chosen rows (stops earlier when a sweep swaps nothing).
    """
    chosen = list(chosen)
    for _ in range(passes):
        swapped = False
        for i in range(len(chosen)):
            rest = np.bitwise_or.reduce(seen[chosen[:i] + chosen[i + 1:]], axis=0, initial=0)
            totals = ones(seen | rest)
            best = int(np.argmax(totals))
            if totals[best] > totals[chosen[i]]:
                chosen[i], swapped = best, True
        if not swapped:
            break
    return chosen


def oracle_planner(settings: PlanSettings, seed: int, checkpoint: str | None) -> CoverageOraclePlanner:
    """The registry's `oracle`: K = `settings.candidates` random candidates per step in its pool."""
    return CoverageOraclePlanner(settings.candidates, seed)
