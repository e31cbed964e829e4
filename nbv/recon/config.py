"""Reconstruction, metrics and heat-map configs, declared once (light: no Open3D, no plotting).

`docs/reconstruction.md` states the definitions these settings feed.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Annotated, Literal

from tyro.conf import Suppress, arg

from common.memory import check_memory

MAX_BLOCK_RESOLUTION = 64
"""Most voxels per block side."""
MAX_INITIAL_VOXELS = 2**28
"""Most voxels allocated up front (initial_blocks x block_resolution^3): about 5 GB with colour."""
MIN_VOXEL_SIZE_M = 1e-4
"""Smallest voxel edge, metres (0.1 mm: 10^4 voxels across the normalised 1 m target). Finer grids fuse
garbage (neighbouring depth samples land many voxels apart, so no surface closes) and their hash map
outgrows memory."""
METRIC_POINT_BYTES = 256
"""Peak bytes per sampled metric point: 236 measured for a 2 * 10^6-point comparison of two meshes (the
samples, the k-d tree and the distances), rounded up."""
GRID_VOXEL_BYTES = 4
"""Bytes per occupancy voxel: its uint8 state, the carve's bool mask, and room for one copy."""


@dataclass(frozen=True)
class ReconstructionConfig:
    """TSDF fusion settings; the defaults suit a normalised 1 m target (docs/reconstruction.md)."""

    voxel_size_m: float = 0.004
    """Voxel edge length in metres (4 mm: 250 voxels across a 1 m target). Keep it above about a
    third of a pixel's footprint on the target (at 2 m: 6.4 mm at 320 px wide, 13 mm at 160 px)."""
    truncation_m: float = 0.016
    """TSDF truncation distance in metres (4 voxels): the band fused around each depth sample."""
    depth_max_m: float = 10.0
    """Depth samples farther than this (metres) are ignored."""
    min_observations: int = 1
    """Voxels fused from fewer views than this are left out of the mesh and the point cloud."""
    color: bool = True
    """Fuse colours into the mesh and points (about a third of the fusion time); off: geometry only."""
    crop_ground: bool = True
    """Remove the ground plane z = 0 (depth points and reconstructed surface below the crop height)."""
    ground_crop_voxels: float = 1.0
    """Crop height above z = 0, in voxels: mesh vertices and points lower than this are removed."""
    block_resolution: int = 8
    """Voxels per side of one hashed block (8: 3.2 cm blocks, half the work of 16 on thin bands)."""
    initial_blocks: int = 4000
    """Voxel blocks allocated up front; the hash map grows beyond this when needed."""
    device: Annotated[Literal["auto", "CPU:0", "CUDA:0"], arg(name="tsdf-device")] = "auto"
    """Open3D device: 'auto' takes CUDA:0 where Open3D sees a CUDA GPU, else the CPU."""

    def __post_init__(self) -> None:
        for name in ("voxel_size_m", "truncation_m", "depth_max_m"):
            value = getattr(self, name)
            if not math.isfinite(value) or value <= 0:
                raise ValueError(f"reconstruction {name} must be positive and finite, got {value!r}")
        if self.voxel_size_m < MIN_VOXEL_SIZE_M:
            raise ValueError(f"reconstruction voxel_size_m must be at least {MIN_VOXEL_SIZE_M} m, got "
                             f"{self.voxel_size_m!r}: finer voxels fuse no closed surface (default 0.004)")
        if self.truncation_m < self.voxel_size_m:
            raise ValueError(f"reconstruction truncation_m ({self.truncation_m}) must be at least "
                             f"one voxel ({self.voxel_size_m})")
        if self.min_observations < 1:
            raise ValueError(f"reconstruction min_observations must be >= 1, got {self.min_observations}")
        if not math.isfinite(self.ground_crop_voxels) or self.ground_crop_voxels < 0:
            raise ValueError(f"reconstruction ground_crop_voxels must be >= 0, got {self.ground_crop_voxels}")
        if not 2 <= self.block_resolution <= MAX_BLOCK_RESOLUTION:
            raise ValueError(f"reconstruction block_resolution must lie in [2, {MAX_BLOCK_RESOLUTION}], "
                             f"got {self.block_resolution}")
        if not 1 <= self.initial_blocks * self.block_resolution**3 <= MAX_INITIAL_VOXELS:
            raise ValueError(f"reconstruction initial_blocks must lie in [1, "
                             f"{MAX_INITIAL_VOXELS // self.block_resolution**3}] at block_resolution "
                             f"{self.block_resolution}, got {self.initial_blocks}")

    @property
    def ground_crop_m(self) -> float:
        """Crop height above the ground in metres (0 when the ground is kept)."""
        return self.ground_crop_voxels * self.voxel_size_m if self.crop_ground else 0.0


@dataclass(frozen=True)
class MetricsConfig:
    """How surfaces are sampled and compared."""

    n_points: Annotated[int, arg(name="metric-points")] = 1_000_000
    """Points sampled from each surface (point clouds holding fewer are used whole)."""
    threshold_cm: float = 1.0
    """Distance threshold of coverage, precision, recall and F-score, in centimetres."""
    seed: Suppress[int] = 0
    """Seed of the surface sampling (the same for both surfaces); set from each command's --seed."""

    def __post_init__(self) -> None:
        if self.n_points < 1:
            raise ValueError(f"--metric-points must be >= 1, got {self.n_points}")
        check_memory(f"metrics n_points (--metric-points) {self.n_points}", self.n_points, METRIC_POINT_BYTES,
                     "use fewer points (default 1000000)")
        if not math.isfinite(self.threshold_cm) or self.threshold_cm <= 0:
            raise ValueError(f"metrics threshold_cm must be positive, got {self.threshold_cm}")


@dataclass(frozen=True)
class HeatmapConfig:
    """Colour scale and views of a heat map."""

    max_cm: float = 2.0
    """Distance at the top of the colour scale, cm (larger distances get the top colour)."""
    colormap: str = "jet"
    """Matplotlib colour map (CloudCompare's default scale is blue-green-yellow-red)."""
    views: tuple[float, ...] = (45.0, 135.0, 225.0, 315.0)
    """Azimuths (degrees, counter-clockwise from +x) of the views in the PNG."""
    elevation_deg: float = 30.0
    """Elevation of every view above the horizon, degrees."""
    max_faces: int = 30_000
    """Meshes with more faces are simplified (vertex clustering) for the PNG only."""

    def __post_init__(self) -> None:
        if not math.isfinite(self.max_cm) or self.max_cm <= 0:
            raise ValueError(f"heat map max_cm must be positive, got {self.max_cm}")
        if not self.views:
            raise ValueError("heat map needs at least one view")


@dataclass(frozen=True)
class OccupancyConfig:
    """The information-gain planner's occupancy grid over the target's bounds (`nbv.recon.occupancy`)."""

    grid_resolution: int = 64
    """Voxels along the longest side of the padded target bounds (cubic voxels; 64: about 1.7 cm)."""
    grid_margin_m: float = 0.05
    """Padding of the target's bounding box on its four sides and its top, metres (the base stays on the
    ground, z = 0)."""
    gain_ray_stride: int = 4
    """A candidate's gain casts a ray through every n-th pixel along both image axes (4: 80 x 60 rays at
    320 x 240)."""
    integrate_ray_stride: int = 2
    """A captured depth image carves free space along every n-th pixel's ray along both axes (every
    pixel's hit is marked occupied)."""
    votes: bool = False
    """Weigh each image's hits against its rays' passes, one vote an image, instead of occupied winning
    (`nbv.recon.occupancy`; for stereo depth's false matches)."""

    def __post_init__(self) -> None:
        for name in ("grid_resolution", "gain_ray_stride", "integrate_ray_stride"):
            if getattr(self, name) < 1:
                raise ValueError(f"occupancy {name} must be >= 1, got {getattr(self, name)}")
        check_memory(f"occupancy grid_resolution {self.grid_resolution} (a grid of up to "
                     f"{self.grid_resolution}^3 voxels)", float(self.grid_resolution) ** 3, GRID_VOXEL_BYTES,
                     "use a coarser --grid-resolution (default 64)")
        if not math.isfinite(self.grid_margin_m) or self.grid_margin_m < 0:
            raise ValueError(f"occupancy grid_margin_m must be >= 0, got {self.grid_margin_m!r}")
