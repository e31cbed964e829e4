"""Fused coverage: the share of the true surface that the TSDF fusion of a set of views keeps, in memory.

`FusedCoverage.coverage(views)` is the number `nbv plan` reports as `gt.coverage`
(`nbv.planning.plan.plan_scan`), computed without writing a dataset: each view's
depth is rendered once (the depth pass is exact and seedless, so the plan's own
render gives the same map) and rounded to whole millimetres as the dataset's
PNG stores it; the views are fused with the plan's `ReconstructionConfig`; the
mesh and the true surface go through PLY as the plan's files do (float32
coordinates); and the coverage is the recall of `nbv.recon.metrics`: the share of
`n_points` seeded samples of the true surface with one of `n_points` seeded
samples of the reconstruction closer than the threshold. Colour is not fused:
it does not move the surface (a test pins equality with `nbv plan`'s number).

`kept(view)` is the cheap single-view version: which of `probe` true-surface
samples the fusion of that one view reconstructs within the threshold (to its
TSDF zero-crossing points). Their union over a set tracks the set's fused
coverage closely (measured on forest_ruin_house, 160x120, 16 random 8-view sets:
0.5 points above it on average, Spearman 0.997), unlike what an ideal sensor
sees (`nbv.recon.visibility`: 21 points above, Spearman 0.43): fusion at the
camera's resolution loses surfaces seen at grazing angles and from afar.
"""

from __future__ import annotations

import io
from collections.abc import Sequence
from dataclasses import replace

import numpy as np
import trimesh
from scipy.spatial import cKDTree

from nbv.recon.config import MetricsConfig, ReconstructionConfig
from nbv.recon.metrics import sample_points
from nbv.recon.tsdf import TSDFFusion
from render.dataset import stored_depth
from render.renderer import MitsubaRenderer
from render.viewpoint import Viewpoint, viewpoint_to_c2w
from scenes.model import Scene


def as_stored(geometry: trimesh.Trimesh) -> trimesh.Trimesh:
    """A mesh as its PLY file reads back (float32 coordinates): what a score of the saved file sees."""
    return trimesh.load(io.BytesIO(geometry.export(file_type="ply")), file_type="ply", process=False)


class FusedCoverage:
    """Scores sets of views of one scene by the coverage of the true surface their TSDF fusion keeps.

    Args:
        renderer: a renderer of the scene with the plan's camera and render settings (their resolution
            scale sets the depth maps' size).
        scene: the target: its true mesh is the reference.
        recon: the plan's TSDF fusion settings.
        metrics: the plan's scoring (sample count and threshold); its seed is replaced by `seed`.
        seed: the plan's seed (the metric samples').
        probe: true-surface samples of `kept`.
    """

    def __init__(self, renderer: MitsubaRenderer, scene: Scene, recon: ReconstructionConfig,
                 metrics: MetricsConfig, seed: int, probe: int = 20_000) -> None:
        self.renderer = renderer
        self.recon = replace(recon, color=False)
        self.metrics = replace(metrics, seed=seed)
        self.gt = as_stored(scene.target_mesh())
        self.probe = sample_points(self.gt, probe, seed, "gt reference")
        self._reference: np.ndarray | None = None
        self._depths: dict[tuple[float, float, float], tuple[np.ndarray, np.ndarray]] = {}

    def depth(self, view: Viewpoint) -> tuple[np.ndarray, np.ndarray]:
        """The stored depth map at `view` and its OpenCV camera-to-world (rendered once per viewpoint)."""
        key = tuple(view.as_array().tolist())
        if key not in self._depths:
            c2w = viewpoint_to_c2w(view, self.renderer.center)
            self._depths[key] = (stored_depth(self.renderer.render_depth(c2w)), c2w)
        return self._depths[key]

    def fuse(self, views: Sequence[Viewpoint]) -> TSDFFusion:
        """The TSDF fusion of `views`, in order."""
        camera = self.renderer.camera
        fusion = TSDFFusion(camera.K, camera.width, camera.height, self.recon)
        blank = np.zeros((camera.height, camera.width, 3), np.uint8)
        for view in views:
            fusion.integrate(blank, *self.depth(view))
        return fusion

    def kept(self, view: Viewpoint) -> np.ndarray:
        """(probe,) True where a probe sample lies within the threshold of the fusion of `view` alone."""
        points = self.fuse([view]).extract_points().vertices
        if len(points) == 0:
            return np.zeros(len(self.probe), dtype=bool)
        return within(self.probe, cKDTree(points), self.metrics.threshold_cm / 100.0, workers=1)

    def coverage(self, views: Sequence[Viewpoint]) -> float:
        """The report's coverage of the true surface by the reconstruction of `views` (0 when nothing is
        reconstructed)."""
        mesh = self.fuse(views).extract_mesh()
        if len(mesh.faces) == 0:
            return 0.0
        n, seed = self.metrics.n_points, self.metrics.seed
        if self._reference is None:
            self._reference = sample_points(self.gt, n, seed, "gt reference")
        prediction = sample_points(as_stored(mesh), n, seed, "reconstruction")
        return float(np.mean(within(self._reference, cKDTree(prediction), self.metrics.threshold_cm / 100.0)))


def within(query: np.ndarray, tree: cKDTree, radius: float, workers: int = -1) -> np.ndarray:
    """(N,) True where a query point has a tree point closer than `radius`: `nearest_distances(query, tree)
    < radius` exactly, searching no farther, on `workers` threads (-1: every core)."""
    distances, _ = tree.query(query, k=1, distance_upper_bound=radius, workers=workers)
    return distances < radius
