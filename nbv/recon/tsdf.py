"""TSDF fusion of RGB-D views into a mesh and a point cloud (paper Sec. V-C).

The paper's View Planning Toolbox fuses RGB, depth and poses with a dense
NumPy/CUDA TSDF (3DMatch's tsdf-fusion) and extracts a mesh by marching cubes.
We use Open3D 0.20's tensor `VoxelBlockGrid`, a sparse hash of small voxel
blocks, on the CPU or on a CUDA device where one is present. (Open3D's legacy
`ScalableTSDFVolume` integrated nothing in our tests: docs/rendering.md.)

Conventions (docs/conventions.md): metres, z up, camera-to-world poses in the
OpenCV convention; depth is z-depth in metres, 0 where nothing was hit. Open3D
wants world-to-camera extrinsics, so poses are inverted at the border here.

The target stands on the ground plane z = 0. By default the ground is cropped:
depth pixels whose world point lies below half the crop height are dropped
before fusion (the ground's truncation band would otherwise reach into the
target's base, and a 6 x 6 m ground would cost far more voxel blocks than the
target), and mesh vertices and points below the crop height (one voxel) are
removed after extraction, which also removes the open skirt that marching cubes
leaves where the fused surface ends.

`reconstruct_dataset(read_dataset(DIR), config)` fuses a dataset on disk and
`save_reconstruction(recon, OUT)` writes OUT/mesh.ply and OUT/points.ply.

Example:
    One camera 1.5 m up looking straight down at a flat surface 1 m away:

    >>> K = np.array([[40.0, 0, 15.5], [0, 40.0, 11.5], [0, 0, 1]])
    >>> c2w = np.array([[1.0, 0, 0, 0], [0, -1, 0, 0], [0, 0, -1, 1.5], [0, 0, 0, 1]])
    >>> view = (np.full((24, 32, 3), 128, np.uint8), np.ones((24, 32), np.float32), c2w)
    >>> recon = reconstruct_views([view], K, ReconstructionConfig(voxel_size_m=0.01, truncation_m=0.04))
    >>> bool(np.ptp(recon.mesh.vertices[:, 2]) < 1e-6), float(recon.mesh.vertices[0, 2])
    (True, 0.5)
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import open3d as o3d
import open3d.core as o3c
import trimesh

from common.io import atomic_path
from nbv.recon.config import ReconstructionConfig
from render.dataset import ViewDataset
from render.viewpoint import validate_pose


@dataclass(frozen=True)
class Reconstruction:
    """The surface fused from a set of views."""

    mesh: trimesh.Trimesh
    """Marching-cubes triangle mesh with per-vertex sRGB colours (uint8 RGBA)."""
    points: trimesh.PointCloud
    """Zero-crossing points of the TSDF with colours: a denser sampling than the mesh vertices."""
    n_views: int
    """Number of views fused."""
    config: ReconstructionConfig
    """The settings it was fused with."""


def select_device(name: str) -> o3c.Device:
    """The Open3D device for a config's `device` field ('auto' prefers CUDA:0)."""
    if name == "auto":
        name = "CUDA:0" if o3c.cuda.is_available() else "CPU:0"
    if name.startswith("CUDA") and not o3c.cuda.is_available():
        raise ValueError(f"reconstruction device {name} requested but Open3D sees no CUDA device")
    return o3c.Device(name)


def validate_intrinsics(K: np.ndarray) -> np.ndarray:  # noqa: N803 - the standard name
    """Check a 3x3 pinhole matrix; return it as float64 or raise naming the fault."""
    k = np.asarray(K, dtype=np.float64)
    if k.shape != (3, 3):
        raise ValueError(f"intrinsics K must be 3x3, got shape {k.shape}")
    if not np.all(np.isfinite(k)):
        raise ValueError("intrinsics K contains NaN or infinite values")
    if k[0, 0] <= 0 or k[1, 1] <= 0 or not np.allclose(k[2], [0, 0, 1]):
        raise ValueError(f"intrinsics K must have positive focal lengths and last row [0, 0, 1], "
                         f"got {k.tolist()}")
    return k


class TSDFFusion:
    """An Open3D voxel block grid fed one view at a time (usable online by a planner).

    Args:
        K: 3x3 OpenCV intrinsics shared by all views.
        width: image width in pixels.
        height: image height in pixels.
        config: fusion settings.
    """

    def __init__(self, K: np.ndarray, width: int, height: int,  # noqa: N803
                 config: ReconstructionConfig = ReconstructionConfig()) -> None:
        self.config = config
        self.width, self.height = int(width), int(height)
        self.device = select_device(config.device)
        k = validate_intrinsics(K)
        self._intrinsic = o3c.Tensor(k, o3c.float64)
        u, v = np.meshgrid(np.arange(self.width), np.arange(self.height))
        # Per-pixel camera ray with unit z: a z-depth d puts the point at d * ray.
        self._rays = np.stack([(u - k[0, 2]) / k[0, 0], (v - k[1, 2]) / k[1, 1],
                               np.ones(u.shape)], axis=-1)
        self._trunc_voxels = config.truncation_m / config.voxel_size_m
        attrs = (("tsdf", 1), ("weight", 1)) + ((("color", 3),) if config.color else ())
        self.grid = o3d.t.geometry.VoxelBlockGrid(
            tuple(a for a, _ in attrs), (o3c.float32,) * len(attrs), tuple((c,) for _, c in attrs),
            config.voxel_size_m, config.block_resolution, config.initial_blocks, self.device)
        self.n_views = 0

    def integrate(self, rgb: np.ndarray, depth: np.ndarray, c2w: np.ndarray) -> None:
        """Fuse one view: sRGB uint8 (H, W, 3), z-depth float metres (H, W), OpenCV camera-to-world."""
        name = f"view {self.n_views}"
        rgb, depth = np.asarray(rgb), np.asarray(depth)
        expected = (self.height, self.width)
        if depth.shape != expected:
            raise ValueError(f"{name}: depth map is {depth.shape[1::-1]} (w, h) but the camera is "
                             f"{self.width}x{self.height}")
        if rgb.shape != (*expected, 3) or rgb.dtype != np.uint8:
            raise ValueError(f"{name}: rgb must be ({self.height}, {self.width}, 3) uint8 to match the "
                             f"depth map, got {rgb.shape} {rgb.dtype}")
        if not np.all(np.isfinite(depth)) or np.any(depth < 0):
            raise ValueError(f"{name}: depth contains NaN, infinite or negative values")
        pose = validate_pose(c2w, f"{name} pose")
        depth = np.asarray(depth, dtype=np.float32)
        if self.config.crop_ground:
            z_world = depth * (self._rays @ pose[2, :3]) + pose[2, 3]
            depth = np.where(z_world < 0.5 * self.config.ground_crop_m, np.float32(0), depth)
        self.n_views += 1
        if not np.any((depth > 0) & (depth < self.config.depth_max_m)):
            return  # nothing to fuse; Open3D would abort on a view that touches no block
        extrinsic = o3c.Tensor(np.linalg.inv(pose), o3c.float64)
        depth_img = o3d.t.geometry.Image(o3c.Tensor(np.ascontiguousarray(depth)).to(self.device))
        args = (1.0, self.config.depth_max_m, self._trunc_voxels)
        blocks = self.grid.compute_unique_block_coordinates(depth_img, self._intrinsic, extrinsic, *args)
        if self.config.color:
            color_img = o3d.t.geometry.Image(
                o3c.Tensor(np.ascontiguousarray(rgb, dtype=np.float32) / np.float32(255)).to(self.device))
            self.grid.integrate(blocks, depth_img, color_img, self._intrinsic, extrinsic, *args)
        else:
            self.grid.integrate(blocks, depth_img, self._intrinsic, extrinsic, *args)

    def _weight_threshold(self) -> float:
        # Open3D keeps voxels whose weight is strictly above the threshold; each view adds 1.
        return self.config.min_observations - 0.5

    def extract_mesh(self) -> trimesh.Trimesh:
        """Marching cubes over the fused TSDF, ground cropped as configured (may be empty)."""
        if self.grid.hashmap().size() == 0:
            return trimesh.Trimesh(np.zeros((0, 3)), np.zeros((0, 3), np.int64), process=False)
        mesh = self.grid.extract_triangle_mesh(self._weight_threshold()).cpu()
        vertices = mesh.vertex.positions.numpy().astype(np.float64).reshape(-1, 3)
        if len(vertices) == 0:
            return trimesh.Trimesh(np.zeros((0, 3)), np.zeros((0, 3), np.int64), process=False)
        faces = mesh.triangle.indices.numpy().astype(np.int64)
        colors = _to_uint8(mesh.vertex.colors.numpy()) if self.config.color else _grey(len(vertices))
        keep = vertices[:, 2] >= self.config.ground_crop_m
        faces = faces[keep[faces].all(axis=1)]
        used = np.zeros(len(vertices), bool)
        used[faces] = True
        # Open3D's parallel hash map orders blocks differently from run to run; sorting the
        # vertices (and faces) by position makes the output identical for identical input.
        order = np.lexsort(vertices[used].T[::-1])
        remap = np.full(len(vertices), -1, np.int64)
        remap[np.flatnonzero(used)[order]] = np.arange(len(order))
        faces = _canonical_faces(remap[faces])
        return trimesh.Trimesh(vertices[used][order], faces, vertex_colors=colors[used][order],
                               process=False)

    def extract_points(self) -> trimesh.PointCloud:
        """TSDF zero-crossing points with colours, ground cropped as configured (may be empty)."""
        if self.grid.hashmap().size() == 0:
            return trimesh.PointCloud(np.zeros((0, 3)))
        cloud = self.grid.extract_point_cloud(self._weight_threshold()).cpu()
        points = cloud.point.positions.numpy().astype(np.float64).reshape(-1, 3)
        colors = (_to_uint8(cloud.point.colors.numpy().reshape(-1, 3)) if self.config.color
                  else _grey(len(points)))
        keep = points[:, 2] >= self.config.ground_crop_m
        order = np.lexsort(points[keep].T[::-1])
        return trimesh.PointCloud(points[keep][order], colors=colors[keep][order])


def _canonical_faces(faces: np.ndarray) -> np.ndarray:
    """Faces rolled to start at their smallest index (winding kept), rows sorted."""
    if len(faces) == 0:
        return faces
    rows = np.arange(len(faces))[:, None]
    start = np.argmin(faces, axis=1)[:, None]
    rolled = faces[rows, (start + np.arange(3)) % 3]
    return rolled[np.lexsort(rolled.T[::-1])]


def _to_uint8(colors: np.ndarray) -> np.ndarray:
    return np.clip(np.round(colors * 255.0), 0, 255).astype(np.uint8)


def _grey(count: int) -> np.ndarray:
    return np.full((count, 3), 180, np.uint8)


def reconstruct_views(views: Iterable[tuple[np.ndarray, np.ndarray, np.ndarray]], K: np.ndarray,  # noqa: N803
                      config: ReconstructionConfig = ReconstructionConfig()) -> Reconstruction:
    """Fuse (rgb, depth, c2w) views sharing intrinsics `K` into a mesh and a point cloud.

    Args:
        views: (rgb uint8 (H, W, 3), z-depth float32 metres (H, W), 4x4 OpenCV camera-to-world).
        K: 3x3 OpenCV intrinsics.
        config: fusion settings.

    Returns:
        The reconstruction.

    Raises:
        ValueError: on a malformed view (named by index) or when no surface was reconstructed.
    """
    fusion: TSDFFusion | None = None
    for rgb, depth, c2w in views:
        if fusion is None:
            height, width = np.shape(depth)[:2]
            fusion = TSDFFusion(K, width, height, config)
        fusion.integrate(rgb, depth, c2w)
    if fusion is None:
        raise ValueError("no views to reconstruct from")
    mesh = fusion.extract_mesh()
    if len(mesh.faces) == 0:
        raise ValueError(f"no surface reconstructed from {fusion.n_views} views: every depth map is "
                         f"empty, beyond depth_max_m, below the ground crop, or seen by fewer than "
                         f"min_observations={config.min_observations} views")
    return Reconstruction(mesh, fusion.extract_points(), fusion.n_views, config)


def reconstruct_dataset(dataset: ViewDataset, config: ReconstructionConfig = ReconstructionConfig(),
                        indices: Iterable[int] | None = None) -> Reconstruction:
    """Fuse a view dataset (all frames, or the frames `indices`) into a mesh and a point cloud.

    Raises:
        render.dataset.DatasetError: a frame's image or depth map is unreadable or the wrong size.
        ValueError: as `reconstruct_views`.
    """
    chosen = range(len(dataset)) if indices is None else list(indices)
    views = ((dataset.rgb(i), dataset.depth(i), dataset.frames[i].c2w) for i in chosen)
    return reconstruct_views(views, dataset.camera.K, config)


def save_reconstruction(recon: Reconstruction, out: str | Path) -> tuple[Path, Path]:
    """Write `out/mesh.ply` and `out/points.ply` (binary PLY with colours); return their paths."""
    folder = Path(out)
    folder.mkdir(parents=True, exist_ok=True)
    mesh_path, points_path = folder / "mesh.ply", folder / "points.ply"
    for geometry, path in ((recon.mesh, mesh_path), (recon.points, points_path)):
        with atomic_path(path) as tmp:
            geometry.export(tmp, file_type="ply")
    return mesh_path, points_path
