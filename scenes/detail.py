"""Surface detail that does not repeat across a building: one texture atlas baked per part.

A tileable material (`scenes.textures`) repeats every tile, and the near-symmetric
sides of a building then look alike: structure from motion matches a wall with the
one opposite and the model folds (docs/sfm.md). Real walls are weathered, stained,
signed and overgrown differently everywhere. `detail_part` turns a part textured
by tiled UVs into one whose UVs span each planar face (a chart) once, in an atlas
baked for that part: the tiled material sampled where the face lies, at
`DENSITY_PX_PER_M`, times detail seeded by building and part (large-scale
weathering, stains, rain streaks, flecks, a tint per face, dirt and moss at the
base of walls, posters and signs on large walls). Each face gets its own block
of freshly drawn detail, so no two faces carry the same one. Baked, because
Mitsuba 3 has no procedural noise texture and no product of two textures (its
`blendbsdf` blends two BSDFs, and every texture of a shape reads the same UVs).
"""

from __future__ import annotations

import hashlib
import math
import zlib
from dataclasses import replace
from pathlib import Path

import cv2
import numpy as np
from PIL import Image
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components

from common.io import atomic_path, cache_dir
from scenes.model import Part
from scenes.surface import make_part
from scenes.weathering import Chart, weather

DETAIL_VERSION = 1
"""Bumped whenever the baking changes, so stale atlases are never reused."""
DENSITY_PX_PER_M = 48.0
"""Atlas texels per metre of real (not yet normalised) surface, where the atlas budget allows."""
MAX_ATLAS_PX = 2048 * 2048
"""Most texels of one part's atlas: larger parts (the ground) are baked coarser."""
MIN_FILL = 0.3
"""Least share of its bounding box a chart's faces must cover to be baked as one block."""
PAD_PX = 2
"""Texels of the tiled material around each chart, so bilinear lookups at its edge stay on it."""


def detail_part(part: Part, seed: int) -> Part:
    """`part` (UVs in tiles of its material's tileable texture) with a unique baked atlas, seeded by
    `seed`; a part of one colour is returned as it is. The atlas and the part's new arrays are cached,
    named by a hash of the part and the seed, so a warm build only reads them back."""
    if part.material.texture is None or part.uv is None:
        return part
    corners, uvs = part.vertices[part.faces], part.uv[part.faces]
    key = hashlib.sha1(b"%d %d " % (DETAIL_VERSION, seed))
    for array in (corners, uvs):
        key.update(np.ascontiguousarray(array, dtype=np.float64).tobytes())
    key.update(repr((replace(part.material, texture=Path(part.material.texture.name)), part.target)).encode())
    stem = cache_dir() / "atlases" / f"{part.material.texture.stem}_{key.hexdigest()[:16]}_v{DETAIL_VERSION}"
    image, arrays = stem.with_name(stem.name + ".png"), stem.with_name(stem.name + ".npz")
    material = replace(part.material, texture=image)
    if image.exists() and arrays.exists():
        with np.load(arrays) as stored:
            return Part(part.name, stored["vertices"], stored["faces"], material, stored["uv"], part.target)
    atlas = _Atlas(corners, uvs, part.material.texture)
    made = make_part(part.name, corners, atlas.uv, material, part.target)
    image.parent.mkdir(parents=True, exist_ok=True)
    with atomic_path(image) as tmp:
        Image.fromarray(atlas.bake(np.random.default_rng(seed))).save(tmp, format="PNG", compress_level=1)
    with atomic_path(arrays) as tmp, open(tmp, "wb") as file:
        np.savez(file, vertices=made.vertices, faces=made.faces, uv=made.uv)
    return made


def detailed(parts: list[Part], building: str) -> list[Part]:
    """Every part of a building through `detail_part`, seeded by `building` (its name and seed) and the
    part's name."""
    return [detail_part(p, zlib.crc32(f"{building} {p.name}".encode())) for p in parts]


def chart_labels(corners: np.ndarray) -> np.ndarray:
    """(F,) chart index of each of (F, 3, 3) triangles: triangles in one plane (normal to 1e-3, offset to
    1 cm) joined by shared corners share a chart."""
    normal = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    normal /= np.linalg.norm(normal, axis=1, keepdims=True) + 1e-300
    offset = np.einsum("fk,fk->f", normal, corners[:, 0])
    rows = np.concatenate([np.round(normal * 1e3), np.round(offset * 1e2)[:, None]], 1)
    plane = np.unique(rows, axis=0, return_inverse=True)[1].reshape(-1)
    keys = np.concatenate([np.repeat(plane, 3)[:, None], np.round(corners.reshape(-1, 3) * 1e6)], 1)
    corner = np.unique(keys, axis=0, return_inverse=True)[1].reshape(-1, 3)
    edges = np.concatenate([corner[:, [0, 1]], corner[:, [1, 2]]])
    count = int(corner.max()) + 1
    graph = coo_matrix((np.ones(len(edges)), (edges[:, 0], edges[:, 1])), shape=(count, count))
    labels = connected_components(graph, directed=False)[1][corner[:, 0]]
    return _split_sparse(corners, labels)


def _split_sparse(corners: np.ndarray, labels: np.ndarray) -> np.ndarray:
    """`labels` with each chart that fills under `MIN_FILL` of its bounding box (a ring of trim round a
    building) split into one chart per triangle, so the atlas holds no large empty blocks."""
    cross = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    area = 0.5 * np.linalg.norm(cross, axis=1)
    count = int(labels.max()) + 1
    lo, hi = np.full((count, 3), np.inf), np.full((count, 3), -np.inf)
    np.minimum.at(lo, labels, corners.min(1))
    np.maximum.at(hi, labels, corners.max(1))
    extent = np.sort(hi - lo, axis=1)
    box = extent[:, 1] * extent[:, 2]
    sparse = np.bincount(labels, area, count) < MIN_FILL * box
    return np.unique(np.where(sparse[labels], count + np.arange(len(labels)), labels), return_inverse=True)[1]


class _Atlas:
    """A part's charts packed in shelves (`uv`: every corner's atlas UV), baked on demand."""

    def __init__(self, corners: np.ndarray, uvs: np.ndarray, tile_path: Path) -> None:
        self.corners, self.uvs, self.tile_path = corners, uvs, tile_path
        self.labels = chart_labels(corners)
        count = int(self.labels.max()) + 1
        lo, hi = np.full((count, 2), np.inf), np.full((count, 2), -np.inf)
        np.minimum.at(lo, self.labels, uvs.min(1))
        np.maximum.at(hi, self.labels, uvs.max(1))
        self.tile_m = _tile_metres(corners, uvs)
        area_m2 = float(np.prod(hi - lo, axis=1).sum()) * self.tile_m**2
        density = min(DENSITY_PX_PER_M, math.sqrt(MAX_ATLAS_PX / 1.3 / max(area_m2, 1e-9)))
        self.s = max(4, min(Image.open(tile_path).size[0], int(round(density * self.tile_m))))
        self.origin = np.floor(lo * self.s).astype(int) - PAD_PX
        self.size = np.ceil(hi * self.s).astype(int) + PAD_PX - self.origin
        width = max(int(self.size[:, 0].max()), int(math.sqrt(float(np.prod(self.size, 1).sum())) * 1.1))
        self.place = _shelves(self.size, width)
        extent = (self.place + self.size).max(0)
        texel = uvs * self.s - self.origin[self.labels][:, None, :] + self.place[self.labels][:, None, :]
        self.uv = texel / extent

    def bake(self, rng: np.random.Generator) -> np.ndarray:
        """The atlas as a uint8 sRGB image: the tiled material under each chart, weathered."""
        tile = np.asarray(Image.open(self.tile_path).convert("RGB"), dtype=np.float32) / 255.0
        if self.s != tile.shape[0]:
            tile = cv2.resize(tile, (self.s, self.s), interpolation=cv2.INTER_AREA)
        width, height = (self.place + self.size).max(0)
        image = np.zeros((height, width, 3), np.float32)
        frames = _chart_frames(self.corners, self.uvs, self.labels, len(self.size))
        charts = [Chart(*(int(k) for k in (*o, *p, *z)), frame=f)
                  for o, p, z, f in zip(self.origin, self.place, self.size, frames)]
        for b in charts:
            rows, cols = (b.ov + np.arange(b.h)) % self.s, (b.ou + np.arange(b.w)) % self.s
            image[b.y:b.y + b.h, b.x:b.x + b.w] = tile[np.ix_(rows, cols)]
        weather(image, charts, self.s, self.s / self.tile_m, rng)
        return np.round(np.clip(image, 0.0, 1.0) * 255.0).astype(np.uint8)


def _tile_metres(corners: np.ndarray, uvs: np.ndarray) -> float:
    """Metres of surface per UV unit, from the largest triangle (planar UVs keep lengths)."""
    edges = corners[:, 1] - corners[:, 0]
    k = int(np.argmax(np.linalg.norm(edges, axis=1)))
    return float(np.linalg.norm(edges[k]) / max(np.linalg.norm(uvs[k, 1] - uvs[k, 0]), 1e-12))


def _chart_frames(corners: np.ndarray, uvs: np.ndarray, labels: np.ndarray, count: int) -> np.ndarray:
    """(C, 3, 3) affine map of each chart from (u, v, 1) in tiles to world position (least squares)."""
    design = np.concatenate([uvs, np.ones(uvs.shape[:2] + (1,))], 2).reshape(-1, 3)
    which = np.repeat(labels, 3)
    normal = np.zeros((count, 3, 3))
    moment = np.zeros((count, 3, 3))
    np.add.at(normal, which, design[:, :, None] * design[:, None, :])
    np.add.at(moment, which, design[:, :, None] * corners.reshape(-1, 3)[:, None, :])
    return np.linalg.solve(normal + 1e-9 * np.eye(3), moment).transpose(0, 2, 1)


def _shelves(size: np.ndarray, width: int) -> np.ndarray:
    """(C, 2) top-left texel of each of (C, 2) block sizes, packed in rows at most `width` wide, tallest
    first."""
    place = np.zeros_like(size)
    x = y = shelf = 0
    for c in np.argsort(-size[:, 1], kind="stable"):
        if x + size[c, 0] > width:
            x, y, shelf = 0, y + shelf, 0
        place[c] = (x, y)
        x, shelf = x + size[c, 0], max(shelf, int(size[c, 1]))
    return place
