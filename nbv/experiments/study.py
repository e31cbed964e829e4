"""What every full-scan experiment shares: how the 288-view reference scan is rendered and scored.

`nbv demo` and `nbv tables` both start from the full hemisphere scan of a
building (paper Sec. V-B), reconstruct with TSDF fusion and compare surfaces;
their configs extend `FullScanStudy`, so those settings are declared once and
the scan is set up in one place.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from pathlib import Path

from nbv.recon.config import MetricsConfig, ReconstructionConfig
from render.camera import UAVCamera
from render.dataset import ViewDataset
from render.scan import HemispherePlan
from render.settings import RenderSettings
from scenes.model import Scene
from scenes.spec import MeshOrientation


@dataclass(frozen=True, kw_only=True)
class FullScanStudy(MeshOrientation):
    """The scan, fusion and metric settings of a full-scan experiment, with its one seed."""

    camera: UAVCamera = UAVCamera()
    """The camera of the scans."""
    render: RenderSettings = RenderSettings()
    """How views are rendered."""
    plan: HemispherePlan = HemispherePlan()
    """The full hemisphere scan (the defaults give the paper's 288 views)."""
    recon: ReconstructionConfig = ReconstructionConfig()
    """TSDF fusion of the full scan and of every refined set."""
    metrics: MetricsConfig = MetricsConfig(n_points=200_000)
    """How reconstructions are compared."""
    seed: int = 0
    """Seed of the renders, the Bag of Views and the metric samples."""

    @property
    def seeded_metrics(self) -> MetricsConfig:
        """The metric settings with the study's seed."""
        return replace(self.metrics, seed=self.seed)

    def load(self, name: str) -> Scene:
        """The scene `name` (a mesh file read with the study's up axis)."""
        from scenes.catalog import load_scene

        return load_scene(name, self.up_axis)

    def full_scan(self, scene: Scene, folder: Path | None = None, fresh: bool = False) -> ViewDataset:
        """The full hemisphere scan of `scene`, rendered with the study's seed unless already cached."""
        from render.scan_cache import full_scan

        return full_scan(scene, self.camera, folder, replace(self.render, seed=self.seed), self.plan, fresh)
