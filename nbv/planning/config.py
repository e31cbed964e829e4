"""Settings of a planned scan: what every planned scan of a study shares, and `nbv plan`'s own.

Light on purpose (no torch, Mitsuba or Open3D), so the command line and the study drivers build their
parsers and configs without loading a renderer. The planner names come from the registry
(`nbv.planning.registry`), which is light too.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Annotated

from tyro.conf import arg

from common.memory import check_memory
from nbv.bov.config import BoVConfig
from nbv.planning.registry import entries, entry, planner_help
from nbv.recon.config import MetricsConfig, OccupancyConfig, ReconstructionConfig
from nbv.sfm.config import LinkSettings, SfmOption
from render.camera import UAVCamera
from render.scan import check_views
from render.settings import RenderSettings
from scenes.spec import SceneSpec

VIEW_PIXEL_BYTES = 16
"""Bytes per pixel of a planned view held until the plan ends (an estimate: its uint8 RGB and float32
depth, 7 bytes, about doubled for the copies the planner and the fusion make)."""


@dataclass(frozen=True, kw_only=True)
class PlanSettings:
    """What every planned scan of a study shares: camera, rendering, Bag of Views, fusion, scoring."""

    camera: UAVCamera = UAVCamera()
    """The camera of the captured views (a policy plans at its training resolution)."""
    render: RenderSettings = RenderSettings()
    """How views are rendered."""
    bov: BoVConfig = BoVConfig(ranges=8)
    """The Bag of Views of the greedy planner's reward (a policy keeps its training one)."""
    candidates: int = 8
    """Greedy, oracle and infogain planners: candidate viewpoints per step (only greedy renders them)."""
    occupancy: OccupancyConfig = OccupancyConfig()
    """The infogain planner's occupancy grid."""
    links: LinkSettings = LinkSettings()
    """Registrability of the flown set (beyond the paper, off by default): random, greedy and infogain fly
    only candidates sharing >= --min-matches verified matches with a view flown (`nbv.planning.linking`)."""
    blank_images: bool = False
    """A policy's captured images replaced by blank ones before it sees them (an evaluation test, beyond the
    paper: a policy that looks at its images loses coverage; the poses flown and the views scored stay)."""
    reference: Path | None = None
    """Reference mesh (full-scan reconstruction); default: reconstruct the hemisphere scan, cached."""
    full_scan: bool = True
    """Also score against the full scan's reconstruction (`reference`); off: against the ground truth only
    (no hemisphere scan to render)."""
    metrics: MetricsConfig = MetricsConfig()
    """How the reconstruction is scored."""
    recon: ReconstructionConfig = ReconstructionConfig()
    """TSDF fusion of the captured views (and of the reference scan)."""

    def __post_init__(self) -> None:
        if self.candidates < 1:  # refused whichever planner runs, not only by those that sample candidates
            raise ValueError(f"--candidates must be >= 1, got {self.candidates}")


@dataclass(frozen=True, kw_only=True)
class PlanConfig(SfmOption):
    """Settings of `nbv plan` (--sfm: `SfmOption`)."""

    scene: SceneSpec
    """The target."""
    views: int | None = None
    """Number of views; default: the policy's episode, the whole hemisphere, or 13 (paper Fig. 1)."""
    planner: Annotated[str, arg(help=planner_help())] = "random"
    out: Path
    """Output folder: views/, mesh.ply, points.ply, gt.ply, metrics.json, heatmap.*, trajectory.png,
    plan.json."""
    seed: int = 0
    """Seed of the planner, the start view, the renders and the metrics' sampling."""
    overwrite: bool = False
    """Replace a non-empty output folder."""
    settings: Annotated[PlanSettings, arg(name="")] = PlanSettings()
    """What every planned scan of a study shares."""

    def __post_init__(self) -> None:
        if self.views is not None and self.views < 1:
            raise ValueError(f"views must be >= 1 (or left out for the planner's default), got {self.views}")
        if self.views is not None:
            check_views("views", self.views)
            camera = self.settings.camera
            check_memory(f"views {self.views} at {camera.width}x{camera.height}", self.views,
                         camera.width * camera.height * VIEW_PIXEL_BYTES, "plan fewer --views")
        if self.seed < 0:
            raise ValueError(f"seed must be >= 0, got {self.seed}")
        found = entry(self.planner)  # an unknown planner fails here, naming every one
        if self.settings.links.on and "links" not in found.settings:
            takes = ", ".join(e.name for e in entries() if "links" in e.settings)
            raise ValueError(f"--min-matches applies to the planners that choose among candidates ({takes}); "
                             f"{self.planner!r} does not: leave --min-matches at 0 for it")
