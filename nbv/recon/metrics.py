"""Surface metrics between a reconstruction and a reference, in centimetres (docs/reconstruction.md).

Both surfaces are turned into point sets of a fixed size: meshes are sampled
uniformly by area (seeded), point clouds are sub-sampled without replacement
(seeded) when they hold more points. With P the reconstruction's points, R the
reference's and d(x, S) the distance from x to its nearest neighbour in S:

- Chamfer discrepancy = (mean_{p in P} d(p, R) + mean_{r in R} d(r, P)) / 2,
  the *mean* of the two directed means, as in docs/reconstruction.md. Open3D's
  `compute_metrics` (and some papers) report the *sum* of the two means, twice
  this value.
- Hausdorff distance = max(max_{p in P} d(p, R), max_{r in R} d(r, P)).
- Precision = share of P within the threshold of R; recall = share of R
  within the threshold of P ("within": strictly closer). Surface coverage is
  the recall against the ground truth: the share of the true surface that was
  reconstructed. F-score = 2 precision recall / (precision + recall).

Sampling sets a floor: two independent samplings of the same surface of area
A with n points each lie about 0.5 sqrt(A / n) apart on average (0.08 cm for a
1 m building of 2.75 m^2 at the default million points), so only compare
Chamfer figures computed with the same point count.

Example:
    A grid of points 5 mm above the same grid (point clouds smaller than
    `n_points` are used whole):

    >>> grid = np.stack(np.meshgrid(np.linspace(0, 1, 11), np.linspace(0, 1, 11), [0.0]), -1).reshape(-1, 3)
    >>> lifted = trimesh.PointCloud(grid + [0, 0, 0.005])
    >>> m = evaluate_surfaces(lifted, {"gt": trimesh.PointCloud(grid)})["gt"]
    >>> round(m.chamfer_cm, 6), m.coverage
    (0.5, 1.0)
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np
import trimesh
from scipy.spatial import cKDTree

from nbv.recon.config import MetricsConfig

Geometry = trimesh.Trimesh | trimesh.PointCloud | np.ndarray
"""A surface: a triangle mesh, a point cloud, or an (N, 3) array of points."""


@dataclass(frozen=True)
class SurfaceMetrics:
    """A reconstruction compared with one reference surface."""

    chamfer_cm: float
    """Chamfer discrepancy: mean of the two directed mean nearest-neighbour distances, cm."""
    hausdorff_cm: float
    """Hausdorff distance: the larger of the two directed maximum distances, cm."""
    coverage: float
    """Share of reference points with a reconstructed point within the threshold (= recall)."""
    fscore: float
    """Harmonic mean of precision and recall."""
    precision: float
    """Share of reconstructed points with a reference point within the threshold."""
    recall: float
    """Share of reference points with a reconstructed point within the threshold."""
    threshold_cm: float
    """The threshold, cm."""
    n_points: int
    """Points compared per surface (the smaller side's count)."""

    def as_dict(self) -> dict:
        """Plain dict for JSON."""
        return asdict(self)


def as_points(geometry: Geometry, name: str = "surface") -> np.ndarray:
    """The vertices (or points) of a geometry as (N, 3) float64, rejecting empty or non-finite input."""
    if isinstance(geometry, trimesh.Trimesh):
        if len(geometry.faces) == 0:
            raise ValueError(f"{name} is an empty mesh (no faces)")
        points = np.asarray(geometry.vertices, dtype=np.float64)
    else:
        points = np.asarray(geometry.vertices if isinstance(geometry, trimesh.PointCloud) else geometry,
                            dtype=np.float64)
    if points.ndim != 2 or points.shape[1] != 3:
        raise ValueError(f"{name} points must be (N, 3), got shape {points.shape}")
    if len(points) == 0:
        raise ValueError(f"{name} is empty (no points)")
    if not np.all(np.isfinite(points)):
        raise ValueError(f"{name} contains NaN or infinite coordinates")
    return points


def sample_points(geometry: Geometry, n_points: int, seed: int, name: str = "surface") -> np.ndarray:
    """`n_points` points spread uniformly over a mesh's area, or a seeded subset of a point cloud.

    Raises:
        ValueError: naming `name`, for an empty mesh or cloud, a mesh of zero area, or NaN coordinates.
    """
    points = as_points(geometry, name)
    if isinstance(geometry, trimesh.Trimesh):
        if not geometry.area > 0:
            raise ValueError(f"{name} is a degenerate mesh (zero surface area)")
        samples, _ = trimesh.sample.sample_surface(geometry, n_points, seed=seed)
        return np.asarray(samples, dtype=np.float64)
    if len(points) <= n_points:
        return points
    rng = np.random.default_rng(seed)
    return points[np.sort(rng.choice(len(points), n_points, replace=False))]


def point_tree(points: np.ndarray) -> cKDTree:
    """A KD-tree of `points` split at the middle of each cell (sliding midpoint), not at the data's median.

    Why: a reconstruction of flat walls is a set of thin, nearly planar slabs (float noise ~1e-8 m off
    each plane). SciPy's default tree (median splits inside the data's shrunk bounds) never cuts a
    slab across its thickness, so a query far from the slab cannot prune it: 1M points of a 3-view
    reconstruction took 37 s per 100k queries from the true surface. Cutting cells at their middle
    bounds every slab: about 50x faster there. The distances are the same bits, since the search is
    exact whatever the tree's shape and each one is computed from the same pair of points.
    """
    return cKDTree(points, balanced_tree=False, compact_nodes=False)


def nearest_distances(query: np.ndarray, reference: np.ndarray | cKDTree) -> np.ndarray:
    """Distance from each query point to its nearest reference point (SciPy KD-tree, all cores).

    The queries are asked in the order of their own tree's leaves, so neighbouring queries walk the same
    branches while they are in the CPU's cache (3x faster on a million random surface samples); each
    distance is the same whatever the order.
    """
    tree = reference if isinstance(reference, cKDTree) else point_tree(reference)
    order = point_tree(query).indices
    distances = np.empty(len(query))
    distances[order] = tree.query(query[order], k=1, workers=-1)[0]
    return distances


def metrics_from_distances(to_reference: np.ndarray, to_prediction: np.ndarray,
                           threshold_cm: float) -> SurfaceMetrics:
    """Metrics from directed nearest-neighbour distances in metres.

    Args:
        to_reference: for each reconstructed point, the distance to the reference.
        to_prediction: for each reference point, the distance to the reconstruction.
        threshold_cm: threshold of precision, recall, coverage and F-score.
    """
    threshold = threshold_cm / 100.0
    precision = float(np.mean(to_reference < threshold))
    recall = float(np.mean(to_prediction < threshold))
    fscore = 2 * precision * recall / (precision + recall) if precision + recall > 0 else 0.0
    return SurfaceMetrics(
        chamfer_cm=float(100.0 * (to_reference.mean() + to_prediction.mean()) / 2.0),
        hausdorff_cm=float(100.0 * max(to_reference.max(), to_prediction.max())),
        coverage=recall, fscore=float(fscore), precision=precision, recall=recall,
        threshold_cm=float(threshold_cm), n_points=int(min(len(to_reference), len(to_prediction))))


def compare_points(prediction: np.ndarray, reference: np.ndarray,
                   threshold_cm: float = 1.0) -> SurfaceMetrics:
    """Metrics between two point sets (metres); see the module docstring for the definitions."""
    prediction = as_points(prediction, "reconstruction")
    reference = as_points(reference, "reference")
    return metrics_from_distances(nearest_distances(prediction, reference),
                                  nearest_distances(reference, prediction), threshold_cm)


def evaluate_surfaces(prediction: Geometry, references: Mapping[str, Geometry],
                      config: MetricsConfig = MetricsConfig()) -> dict[str, SurfaceMetrics]:
    """Compare a reconstruction with each named reference (e.g. 'gt', 'reference').

    The reconstruction is sampled and indexed once for all references.

    Args:
        prediction: the reconstructed mesh or point cloud.
        references: named reference meshes or point clouds.
        config: sampling and threshold.

    Returns:
        The metrics per reference name.
    """
    pred = sample_points(prediction, config.n_points, config.seed, "reconstruction")
    pred_tree = point_tree(pred)
    results = {}
    for name, geometry in references.items():
        ref = sample_points(geometry, config.n_points, config.seed, f"{name} reference")
        results[name] = metrics_from_distances(nearest_distances(pred, ref),
                                               nearest_distances(ref, pred_tree), config.threshold_cm)
    return results


def load_geometry(path: str | Path, name: str = "surface") -> trimesh.Trimesh | trimesh.PointCloud:
    """Load a mesh or point cloud file (PLY, OBJ, STL, OFF, GLB...), rejecting empty files.

    A scene file holding several meshes is merged into one mesh.

    Raises:
        FileNotFoundError: the file does not exist.
        ValueError: naming the file, when it cannot be parsed or holds no geometry.
    """
    file = Path(path)
    if not file.is_file():
        raise FileNotFoundError(f"{name} file {file} not found")
    try:
        loaded = trimesh.load(file, process=False)
    except Exception as err:  # noqa: BLE001 - trimesh raises many types on corrupt files
        raise ValueError(f"{name} file {file} cannot be read: {err}") from err
    if isinstance(loaded, trimesh.Scene):
        meshes = [g for g in loaded.geometry.values() if isinstance(g, trimesh.Trimesh)]
        loaded = trimesh.util.concatenate(meshes) if meshes else trimesh.PointCloud(np.zeros((0, 3)))
    if isinstance(loaded, trimesh.Trimesh) and len(loaded.faces) == 0 and len(loaded.vertices) > 0:
        loaded = trimesh.PointCloud(loaded.vertices)
    if not isinstance(loaded, (trimesh.Trimesh, trimesh.PointCloud)):
        raise ValueError(f"{name} file {file} holds no mesh or point cloud ({type(loaded).__name__})")
    as_points(loaded, f"{name} file {file}")
    return loaded
