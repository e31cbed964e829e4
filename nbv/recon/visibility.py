"""Visible-surface coverage: the share of the true surface that a set of views sees, without fusion.

An ideal depth sensor's upper bound on a scan's coverage, computed by ray casting
(`render.raycast`) in well under a second per view: surface point p counts as seen
by a view when it projects inside the image in front of the camera and no surface
lies before it on its pixel's ray (its z-depth is within `tolerance_m` of the
ray-cast depth there). Used to score planners cheaply where the TSDF pipeline
would cost minutes (choosing `nbv train`'s defaults on validation buildings,
`scripts/select_defaults.py`), and the search that proposes candidates to the
coverage oracle planner (`nbv.planning.oracle`, which scores by fusion);
reported figures use the fused reconstruction (`nbv.recon.evaluate`).

Example: a unit cube seen from +x shows one face of six.
    >>> import trimesh
    >>> from render.camera import UAVCamera
    >>> from render.viewpoint import Viewpoint, viewpoint_to_c2w
    >>> cube = trimesh.creation.box((1, 1, 1))
    >>> pose = viewpoint_to_c2w(Viewpoint(3.0, 0.0, 0.0), np.zeros(3))
    >>> seen = visible_coverage([cube], cube, UAVCamera(64, 48, focal_mm=20.0), [pose], points=6000)
    >>> round(seen, 1)
    0.2
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import trimesh

from render.camera import UAVCamera
from render.raycast import DepthRaycaster
from scenes.model import Scene


def seen_mask(points: np.ndarray, depth: np.ndarray, K: np.ndarray, c2w: np.ndarray,  # noqa: N803
              tolerance_m: float) -> np.ndarray:
    """(N,) True where a world point is in view of the camera and not occluded (depth test)."""
    w2c = np.linalg.inv(c2w)
    cam = points @ w2c[:3, :3].T + w2c[:3, 3]
    z = cam[:, 2]
    front = z > 1e-6
    uv = cam[:, :2] / np.where(front, z, 1.0)[:, None] * [K[0, 0], K[1, 1]] + [K[0, 2], K[1, 2]]
    u, v = np.round(uv[:, 0]).astype(np.int64), np.round(uv[:, 1]).astype(np.int64)
    height, width = depth.shape
    inside = front & (u >= 0) & (u < width) & (v >= 0) & (v < height)
    hit = np.zeros(len(points))
    hit[inside] = depth[v[inside], u[inside]]
    return inside & (hit > 0) & (z <= hit + tolerance_m)


class SurfaceVisibility:
    """Seeded samples of a target surface, and which of them a camera pose sees past the occluders.

    Args:
        occluders: every mesh that can hide the target (the target's own parts included).
        target: the surface whose samples are tested.
        camera: intrinsics and resolution of the views.
        points: surface samples (area-uniform, seeded).
        tolerance_m: depth slack of the occlusion test, metres.
        seed: seed of the sampling.
    """

    def __init__(self, occluders: Sequence[trimesh.Trimesh], target: trimesh.Trimesh, camera: UAVCamera,
                 points: int = 20_000, tolerance_m: float = 0.02, seed: int = 0) -> None:
        samples, faces = trimesh.sample.sample_surface(target, points, seed=seed)
        self.samples, self.faces = np.asarray(samples), np.asarray(faces)
        self.caster = DepthRaycaster(occluders, camera.K, camera.width, camera.height)
        self.K, self.tolerance_m = camera.K, tolerance_m

    def seen(self, c2w: np.ndarray) -> np.ndarray:
        """(points,) True where a sample is seen from the OpenCV camera-to-world `c2w`."""
        return seen_mask(self.samples, self.caster.depth(c2w), self.K, c2w, self.tolerance_m)

    def seen_by(self, poses: Sequence[np.ndarray]) -> np.ndarray:
        """(points,) True where a sample is seen from at least one of the OpenCV camera-to-world `poses`."""
        seen = np.zeros(len(self.samples), dtype=bool)
        for pose in poses:
            seen |= self.seen(pose)
        return seen

    def coverage(self, poses: Sequence[np.ndarray]) -> float:
        """The share of the samples seen from at least one of the OpenCV camera-to-world `poses`."""
        return float(self.seen_by(poses).mean())


def scene_visibility(scene: Scene, camera: UAVCamera, points: int = 20_000, tolerance_m: float = 0.02,
                     seed: int = 0) -> SurfaceVisibility:
    """`SurfaceVisibility` of a scene's target mesh, hidden by all its parts (the ground included)."""
    occluders = [trimesh.Trimesh(p.vertices, p.faces, process=False) for p in scene.parts]
    return SurfaceVisibility(occluders, scene.target_mesh(), camera, points, tolerance_m, seed)


def visible_coverage(occluders: Sequence[trimesh.Trimesh], target: trimesh.Trimesh, camera: UAVCamera,
                     poses: Sequence[np.ndarray], points: int = 20_000, tolerance_m: float = 0.02,
                     seed: int = 0) -> float:
    """The share of `points` samples of the target surface seen by at least one OpenCV c2w pose.

    Arguments as `SurfaceVisibility`'s; `poses` are camera-to-world matrices.
    """
    return SurfaceVisibility(occluders, target, camera, points, tolerance_m, seed).coverage(poses)
