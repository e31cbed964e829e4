"""A renderer-free view dataset with exact poses: a textured box on a textured ground, ray-cast in NumPy.

Every face carries its own random multi-scale noise (`synthetic.textured`, its own seed), so nothing
repeats and SIFT finds many distinct features; the box is not a cube, so no view is another's mirror
image. Rays hit axis-aligned rectangles; the nearest hit gives colour (bilinear from the face's texture)
and z-depth. Structure-from-motion on it has a known answer: the cameras' true centres.
"""

from __future__ import annotations

import functools
import math
from pathlib import Path

import numpy as np
from synthetic import textured

from render.camera import UAVCamera, pixel_rays
from render.dataset import DatasetWriter
from render.viewpoint import Viewpoint, viewpoint_to_c2w

CENTER = np.array([0.0, 0.0, 0.35])
"""The point the cameras look at, metres (the box's centre)."""
TEXTURE_PX = 512
"""Side of each face's texture image, pixels."""
SKY = 200
"""Grey level of rays that hit nothing."""


def _rectangles() -> list[tuple[np.ndarray, np.ndarray, np.ndarray]]:
    """(corner, edge u, edge v) of the ground square and the box's four walls and roof."""
    x, y, z = 0.5, 0.35, 0.7
    corners = np.array([[-x, -y], [x, -y], [x, y], [-x, y]])
    walls = [(np.array([*corners[i], 0.0]), np.array([*(corners[(i + 1) % 4] - corners[i]), 0.0]),
              np.array([0.0, 0.0, z])) for i in range(4)]
    ground = (np.array([-1.5, -1.5, 0.0]), np.array([3.0, 0.0, 0.0]), np.array([0.0, 3.0, 0.0]))
    roof = (np.array([-x, -y, z]), np.array([2 * x, 0.0, 0.0]), np.array([0.0, 2 * y, 0.0]))
    return [ground, *walls, roof]


@functools.cache
def _texture(seed: int) -> np.ndarray:
    """A face's grey texture, float64 (made once per seed: every view of a face sees the same one)."""
    return textured(TEXTURE_PX, TEXTURE_PX, seed)[..., 0].astype(np.float64)


def _bilinear(image: np.ndarray, x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """`image` sampled at float pixel coordinates (x right, y down) inside it, bilinearly."""
    x0 = np.minimum(np.floor(x).astype(np.int64), image.shape[1] - 2)
    y0 = np.minimum(np.floor(y).astype(np.int64), image.shape[0] - 2)
    fx, fy = x - x0, y - y0
    top = image[y0, x0] * (1 - fx) + image[y0, x0 + 1] * fx
    bottom = image[y0 + 1, x0] * (1 - fx) + image[y0 + 1, x0 + 1] * fx
    return top * (1 - fy) + bottom * fy


def render_box(camera: UAVCamera, c2w: np.ndarray, seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """RGB (H x W x 3 uint8) and z-depth (H x W float32, 0 for sky) of the box seen from `c2w` (OpenCV)."""
    h, w = camera.height, camera.width
    local = pixel_rays(camera.K, w, h).reshape(-1, 3)
    rays = local @ c2w[:3, :3].T
    origin = c2w[:3, 3]
    best = np.full(len(rays), np.inf)
    gray = np.full(len(rays), float(SKY))
    for k, (corner, eu, ev) in enumerate(_rectangles()):
        normal = np.cross(eu, ev)
        denom = rays @ normal
        with np.errstate(divide="ignore", invalid="ignore"):
            t = ((corner - origin) @ normal) / denom
        point = origin + t[:, None] * rays - corner
        s, r = point @ eu / (eu @ eu), point @ ev / (ev @ ev)
        hit = (t > 0) & (t < best) & (s >= 0) & (s <= 1) & (r >= 0) & (r <= 1)
        texture = _texture(seed + k)
        gray[hit] = _bilinear(texture, s[hit] * (TEXTURE_PX - 1), r[hit] * (TEXTURE_PX - 1))
        best[hit] = t[hit]
    depth = np.where(np.isfinite(best), best * local[:, 2], 0.0).reshape(h, w).astype(np.float32)
    rgb = np.repeat(np.clip(gray, 0, 255).astype(np.uint8).reshape(h, w, 1), 3, axis=2)
    return rgb, depth


def write_box_arc(out: Path, views: int, step_deg: float, size: tuple[int, int] = (320, 240),
                  radius: float = 2.0, elevation_deg: float = 30.0) -> Path:
    """A dataset of `views` views of the box, `step_deg` apart in azimuth on one ring."""
    camera = UAVCamera(*size)
    with DatasetWriter(out, camera, {"scene": "synthetic_box", "center": CENTER.tolist()}) as writer:
        for i in range(views):
            view = Viewpoint(radius, math.radians(20.0 + step_deg * i), math.radians(elevation_deg))
            c2w = viewpoint_to_c2w(view, CENTER)
            rgb, depth = render_box(camera, c2w)
            writer.add(rgb, depth, c2w, view)
    return out
