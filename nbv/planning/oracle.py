"""The coverage oracle: the best set it finds on the reported measure, never below a budget planner on it.

The measure is the one `nbv plan` reports: coverage of the true surface by the
TSDF reconstruction of the captured views (`gt.coverage`), computed in memory
exactly as the report computes it (`nbv.recon.fused_coverage.FusedCoverage`:
the plan's camera, depth as stored, fusion and metric settings, seed).

1. Baselines: every other planner of the budget study (the registry's `budget`
   entries that do not read the true mesh: random, circle, greedy, infogain,
   the shipped policy, and any registered later, such as an orbit) plans the
   same count of views in its own fresh world on the same settings and seed,
   as `nbv plan` would run it.
2. Pool: the start view, every baseline's views, and the set that sees the most
   true surface by ray casting (the ideal-sensor search: greedy's random
   candidates and a 756-view lattice, `POOL`, greedy from `starts` starts,
   then single swaps; `visible_set`).
3. Its own set: each pool view is fused alone once and the true-surface samples
   its fusion keeps within the threshold are marked (`FusedCoverage.kept`); the
   greedy rule for maximum coverage (Nemhauser, Wolsey and Fisher, Mathematical
   Programming 14, 1978; Scott, Roth and Rivest, ACM Computing Surveys 35, 2003)
   over those marks, started from the start view and from the best single views,
   improved by swaps.
4. Best of: its own set and every baseline's set are scored on the exact
   measure, and the best is returned (its own on a tie). So on the reported
   coverage the oracle is at least every baseline, at any resolution and budget,
   by construction (the baselines are seeded, so each plans here what it plans
   alone); its own search can only lift it above them.

What it bounds: the planners in its baseline list, on `nbv plan`'s coverage
with the plan's settings; not a policy from another checkpoint (the baseline is
the shipped one), not the hemisphere scan (a fixed 288-view scan), not the
ideal-sensor measure of `nbv.recon.visibility` (it maximises what fusion keeps).
It is not provably optimal (greedy over a finite pool, on single-view marks).

Cost: every baseline's planning, one depth render and one single-view fusion per
pool view (about `(baselines + 2) x views` of them), and `baselines + 1` exact
scores (each a fusion and the report's metric sampling): several times one
`nbv plan` of the slowest baseline. Measured (2 cores, load average near 10):
8 views of alpine_chalet at 160x120, 1M metric points, 352 s (the ray-cast
search alone: 17 s).
"""

from __future__ import annotations

from dataclasses import replace
from typing import TYPE_CHECKING

import numpy as np

from nbv.planning.base import Planner, check_candidates, sample_viewpoints
from nbv.planning.registry import entries, make_planner
from nbv.planning.world import PlanningWorld
from nbv.recon.fused_coverage import FusedCoverage
from nbv.recon.visibility import scene_visibility
from nbv.rl.config import LatticeConfig
from nbv.rl.lattice import lattice_axes
from render.viewpoint import Viewpoint, viewpoint_to_c2w

if TYPE_CHECKING:
    from nbv.planning.config import PlanSettings
    from nbv.rl.config import EnvConfig

POOL = LatticeConfig(lattice_radii=3, lattice_azimuths=36, lattice_elevations=7)
"""The ideal-sensor search's fixed candidates: a lattice over the allowed ranges whose odd counts hold the
middle radius and elevation, 10 degrees apart in azimuth (756 viewpoints)."""


def lattice_viewpoints(config: EnvConfig, lattice: LatticeConfig) -> list[Viewpoint]:
    """Every node of a view lattice over the env's ranges (`nbv.rl.lattice.lattice_axes`)."""
    radii, azimuths, elevations = lattice_axes(replace(config, lattice=lattice))
    return [Viewpoint(float(r), float(a), float(e)) for r in radii for a in azimuths for e in elevations]


def baseline_names() -> tuple[str, ...]:
    """The planners the oracle bounds: the registry's budget planners that do not read the true mesh."""
    return tuple(e.name for e in entries() if e.budget and not e.reads_truth)


class CoverageOraclePlanner(Planner):
    """The best of its own greedy set and every baseline's set on the reported TSDF coverage of the true
    surface: an upper bound of the baselines that uses the ground-truth mesh.

    Args:
        settings: the plan's settings (camera, rendering, fusion and scoring; the baselines' own).
        seed: the plan's seed (the baselines', the metric samples', the candidates').
        baselines: planner specs to bound; default: `baseline_names()`.
        pool: the lattice of the ideal-sensor search.
        starts: greedy runs, in both searches: from the start view and from the best single views.
        points: true-surface samples of the ideal-sensor search (and of the single-view marks).
        tolerance_m: depth slack of the ray-cast visibility test, metres.
        default_views: views when none are asked for (13, the paper's Fig. 1).
    """

    name = "oracle"

    def __init__(self, settings: PlanSettings, seed: int = 0, baselines: tuple[str, ...] | None = None,
                 pool: LatticeConfig = POOL, starts: int = 8, points: int = 20_000, tolerance_m: float = 0.02,
                 default_views: int = 13) -> None:
        self.candidates = check_candidates("oracle", settings.candidates)
        if starts < 1:
            raise ValueError(f"oracle planner needs at least 1 greedy start, got {starts}")
        self.settings, self.seed, self.pool, self.starts = settings, seed, pool, starts
        self.baselines = baseline_names() if baselines is None else baselines
        self.points, self.tolerance_m, self.default_views = points, tolerance_m, default_views
        self.scores: dict[str, float] = {}  # the last plan's exact coverage of its set and each baseline's

    def plan(self, world: PlanningWorld, views: int | None) -> list[Viewpoint]:
        """`views` viewpoints: the best, on the reported coverage, of its own set and the baselines'."""
        count = self.view_count(views)
        if (world.env.camera, world.env.render) != (self.settings.camera, self.settings.render):
            raise ValueError("oracle: the world's camera or render settings differ from the plan's, so its "
                             "scores would not be the report's; plan in the plan's own env "
                             "(nbv.planning.plan.scan_env_config)")
        sets = {spec: baseline_views(spec, self.settings, self.seed, world, count) for spec in self.baselines}
        scorer = FusedCoverage(world.source.renderer(world.scene), world.target, self.settings.recon,
                               self.settings.metrics, self.seed, self.points)
        pool = list(dict.fromkeys([world.start, *(v for s in sets.values() for v in s),
                                   *self.visible_set(world, count)]))
        kept = np.packbits([scorer.kept(view) for view in pool], axis=1)
        own = [pool[i] for i in best_cover(kept, count, self.starts)]
        candidates = {"oracle": own, **sets}
        self.scores = {name: scorer.coverage(chosen) for name, chosen in candidates.items()}
        return candidates[max(self.scores, key=self.scores.__getitem__)]  # the first best: its own on a tie

    def visible_set(self, world: PlanningWorld, count: int) -> list[Viewpoint]:
        """The `count` views that see the most true surface by ray casting (an ideal sensor), among the start
        view, K random candidates per step (greedy's stream) and the lattice."""
        rng = np.random.default_rng(self.seed)
        scene = world.target
        visibility = scene_visibility(scene, world.camera, self.points, self.tolerance_m, self.seed)
        center = scene.center()
        pool = [world.start, *sample_viewpoints(world.low, world.high, self.candidates * (count - 1), rng),
                *lattice_viewpoints(world.env, self.pool)]
        seen = np.packbits([visibility.seen(viewpoint_to_c2w(view, center)) for view in pool], axis=1)
        return [pool[i] for i in best_cover(seen, count, self.starts)]


def baseline_views(spec: str, settings: PlanSettings, seed: int, world: PlanningWorld,
                   count: int) -> list[Viewpoint]:
    """The `count` views planner `spec` plans as `nbv plan` runs it: in its own world (its env given the
    plan's, a fresh Bag of Views, renders seeded afresh), sharing `world`'s renderer when the env is the
    same."""
    planner = make_planner(spec, settings, seed)
    env = planner.planning_env(world.env)
    source = None
    if env == world.env:
        source = world.source
        source.reseed(world.seed)
    return planner.plan(PlanningWorld(env, seed=world.seed, source=source), count)


def best_cover(bits: np.ndarray, count: int, starts: int) -> list[int]:
    """`count` rows of a (pool, bytes) bit-packed cover whose union holds the most bits: greedy from row 0
    (the start view) and from the `starts - 1` best single rows, each improved by swaps; the best run."""
    singles = ones(bits)
    firsts = dict.fromkeys([0, *np.argsort(-singles, kind="stable")[:starts - 1].tolist()])
    return max((improve_by_swaps(greedy_cover(bits, count, first), bits) for first in firsts),
               key=lambda chosen: covered(bits, chosen))


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
    """The registry's `oracle`: bounds `baseline_names()` under the plan's settings and seed."""
    return CoverageOraclePlanner(settings, seed)
