"""Check that the surface metric's KD-tree (`nbv.recon.metrics.nearest_distances`) gives SciPy's default
tree's distances bit for bit, and time both, on the surfaces of real `nbv plan` runs (issue 28).

Each PLAN folder holds `mesh.ply` (the reconstruction) and `gt.ply` (the true surface). Both are sampled
as `evaluate_surfaces` samples them (n points, seed 0) at each size, and both directed distances are
compared with `np.array_equal`; the default tree answers at most `--old-queries` queries of a direction
(it takes minutes per 100k from the true surface to a small reconstruction).

    PYTHONPATH=. python scripts/metric_identity.py PLAN [PLAN ...] --sizes 10000 100000 1000000
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np
from scipy.spatial import cKDTree

from nbv.recon.metrics import load_geometry, nearest_distances, sample_points


def compare(query: np.ndarray, reference: np.ndarray, old_queries: int) -> tuple[bool, int, float, float]:
    """(equal, queries compared, default tree s, ours s) for the distances from `query` to `reference`."""
    rng = np.random.default_rng(0)
    some = query if len(query) <= old_queries else query[np.sort(rng.choice(len(query), old_queries, False))]
    start = time.perf_counter()
    ours = nearest_distances(some, reference)
    new_s = time.perf_counter() - start
    start = time.perf_counter()
    default = cKDTree(reference).query(some, k=1, workers=-1)[0]
    return np.array_equal(ours, default), len(some), time.perf_counter() - start, new_s


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("plans", nargs="+", type=Path)
    parser.add_argument("--sizes", nargs="+", type=int, default=[10_000, 100_000, 1_000_000])
    parser.add_argument("--old-queries", type=int, default=100_000)
    args = parser.parse_args()
    print("| plan | points | direction | queries | equal | SciPy default s | ours s |")
    print("|---|---|---|---|---|---|---|")
    for plan in args.plans:
        mesh, gt = load_geometry(plan / "mesh.ply", "mesh"), load_geometry(plan / "gt.ply", "gt")
        for n in args.sizes:
            pred, ref = sample_points(mesh, n, 0, "reconstruction"), sample_points(gt, n, 0, "gt")
            for direction, query, reference in (("gt -> recon", ref, pred), ("recon -> gt", pred, ref)):
                equal, count, old_s, new_s = compare(query, reference, args.old_queries)
                print(f"| {plan.name} | {n} | {direction} | {count} | {equal} | {old_s:.2f} | {new_s:.2f} |",
                      flush=True)


if __name__ == "__main__":
    main()
