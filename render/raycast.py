"""Exact z-depth maps of triangle meshes, ray-cast with Open3D: renderer-free views.

Tests and benches of reconstruction need depth maps whose truth is known
without Mitsuba. Rays leave the camera centre through each pixel centre
(OpenCV intrinsics, pixel centres at integer coordinates); their direction has
unit z in the camera frame, so the hit parameter is the z-depth directly
(docs/conventions.md: depth is z-depth, 0 where nothing is hit).

Example:
    >>> import trimesh
    >>> from render.camera import UAVCamera
    >>> from render.viewpoint import Viewpoint, viewpoint_to_c2w
    >>> camera = UAVCamera(32, 24)
    >>> caster = DepthRaycaster([trimesh.creation.box((1, 1, 1))], camera.K, 32, 24)
    >>> depth = caster.depth(viewpoint_to_c2w(Viewpoint(2.0, 0.0, 0.0), np.zeros(3)))
    >>> depth.shape, round(float(depth[12, 16]), 3)  # the unit box's near face, 1.5 m away
    ((24, 32), 1.5)
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import open3d as o3d
import open3d.core as o3c
import trimesh

from render.camera import pixel_rays
from render.viewpoint import validate_pose


class DepthRaycaster:
    """Casts one ray per pixel into a set of meshes.

    Args:
        meshes: triangle meshes in world coordinates (metres).
        K: 3x3 OpenCV intrinsics.
        width: image width in pixels.
        height: image height in pixels.
    """

    def __init__(self, meshes: Sequence[trimesh.Trimesh], K: np.ndarray,  # noqa: N803
                 width: int, height: int) -> None:
        self.scene = o3d.t.geometry.RaycastingScene()
        for mesh in meshes:
            if len(mesh.faces) == 0:
                raise ValueError("cannot ray-cast an empty mesh")
            self.scene.add_triangles(o3c.Tensor(np.asarray(mesh.vertices, np.float32)),
                                     o3c.Tensor(np.asarray(mesh.faces, np.uint32)))
        self._rays = pixel_rays(K, width, height)

    def depth(self, c2w: np.ndarray) -> np.ndarray:
        """(H, W) float32 z-depth in metres seen from the OpenCV camera-to-world `c2w`."""
        pose = validate_pose(c2w)
        directions = self._rays @ pose[:3, :3].T
        origins = np.broadcast_to(pose[:3, 3], directions.shape)
        rays = np.concatenate([origins, directions], axis=-1).astype(np.float32)
        hit = self.scene.cast_rays(o3c.Tensor(rays))["t_hit"].numpy()
        return np.where(np.isfinite(hit), hit, 0.0).astype(np.float32)
