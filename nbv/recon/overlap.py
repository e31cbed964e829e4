"""Refusing to compare surfaces that cannot be the same object: disjoint bounds or sizes far apart.

A raw mesh file given where the normalised target was meant (a building modelled
22 m tall against a 1 m reconstruction) gives a Chamfer of metres and coverage 0
that look like a result; `nbv evaluate` refuses it instead (issue 27).
"""

from __future__ import annotations

import numpy as np

from nbv.recon.metrics import Geometry

MAX_SIZE_RATIO = 5.0
"""Largest ratio of the two surfaces' sizes (largest bounding-box side) still compared."""


class DisjointSurfaces(ValueError):
    """A reconstruction and a reference whose bounding boxes do not overlap, or whose sizes differ more
    than `MAX_SIZE_RATIO` times."""


def surface_bounds(geometry: Geometry) -> tuple[np.ndarray, np.ndarray]:
    """Axis-aligned (min, max) corners of a mesh, point cloud or (N, 3) array."""
    points = geometry if isinstance(geometry, np.ndarray) else np.asarray(geometry.vertices)
    points = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    return points.min(axis=0), points.max(axis=0)


def check_overlap(prediction: Geometry, reference: Geometry, name: str, fix: str) -> None:
    """Raise `DisjointSurfaces` naming `name` (the reference's flag and file) and `fix` when `prediction`
    and `reference` cannot be one object: disjoint bounding boxes, or sizes over 5x apart."""
    lo_p, hi_p = surface_bounds(prediction)
    lo_r, hi_r = surface_bounds(reference)
    size_p, size_r = float(np.max(hi_p - lo_p)), float(np.max(hi_r - lo_r))
    ratio = max(size_p, size_r) / max(min(size_p, size_r), 1e-12)
    disjoint = bool(np.any(lo_p > hi_r) or np.any(lo_r > hi_p))
    if not disjoint and ratio <= MAX_SIZE_RATIO:
        return
    reasons = (["bounding boxes do not overlap"] if disjoint else [])
    reasons += [f"sizes {ratio:.1f}x apart (over {MAX_SIZE_RATIO:g}x)"] if ratio > MAX_SIZE_RATIO else []
    why = " and ".join(reasons)
    raise DisjointSurfaces(
        f"{name} spans {size_r:.3g} m from {_corner(lo_r)} to {_corner(hi_r)}, the reconstruction "
        f"{size_p:.3g} m from {_corner(lo_p)} to {_corner(hi_p)}: {why}, so they are not one surface "
        f"to compare. {fix}")


def _corner(point: np.ndarray) -> str:
    return "(" + ", ".join(f"{v:.3g}" for v in point) + ")"
