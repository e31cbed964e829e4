"""`test_building`: a small textured house used by the foundation tests.

A 1.0 x 0.6 m box with a gable roof (apex at 0.8 m), noisy brick walls, a tiled
roof and a textured ground. Built already normalised: it stands on z = 0, is
centred on the z axis, and its largest side is 1 m.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from PIL import Image

from scenes.cache import cache_dir
from scenes.model import Lighting, Material, Part, Scene

_SIZE_X, _SIZE_Y, _WALL_H, _APEX_H = 1.0, 0.6, 0.55, 0.8


def _texture(kind: str, seed: int, size: int = 512) -> Path:
    """A seeded high-frequency texture (brick, tile or grass) written once to the cache."""
    path = cache_dir() / "textures" / f"test_building_{kind}_{seed}_{size}.png"
    if path.exists():
        return path
    rng = np.random.default_rng(seed)
    noise = rng.random((size, size))
    yy, xx = np.mgrid[0:size, 0:size]
    if kind == "brick":
        row = yy // 32
        mortar = (yy % 32 < 3) | (((xx + 32 * (row % 2)) % 64) < 3)
        tint = rng.random((size // 32 + 1, size // 64 + 2))[row, (xx + 32 * (row % 2)) // 64]
        base = np.stack([0.55 + 0.25 * tint, 0.25 + 0.1 * tint, 0.18 + 0.05 * tint], -1)
        base[mortar] = (0.8, 0.78, 0.72)
    elif kind == "tile":
        row = yy // 24
        edge = (yy % 24 < 4) | (((xx + 16 * (row % 2)) % 32) < 2)
        base = np.stack([0.45 + 0.1 * noise, 0.2 + 0.05 * noise, 0.15 + 0.05 * noise], -1)
        base[edge] *= 0.4
    else:
        base = np.stack([0.25 + 0.2 * noise, 0.45 + 0.25 * noise, 0.15 + 0.1 * noise], -1)
    image = np.clip(base * (0.8 + 0.4 * noise[..., None]), 0.0, 1.0)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_suffix(".tmp.png")
    Image.fromarray((image * 255).astype(np.uint8)).save(tmp)
    tmp.replace(path)
    return path


def _polygon_part(name: str, polygons: list[np.ndarray], material: Material, tile: float,
                  target: bool = True) -> Part:
    """Fan-triangulated planar polygons, each with planar UVs in units of `tile` metres."""
    verts, faces, uvs = [], [], []
    for poly in polygons:
        normal = np.cross(poly[1] - poly[0], poly[2] - poly[0])
        normal /= np.linalg.norm(normal)
        u_axis = poly[1] - poly[0]
        u_axis /= np.linalg.norm(u_axis)
        v_axis = np.cross(normal, u_axis)
        base = len(verts)
        verts.extend(poly)
        uvs.extend(np.stack([(poly - poly[0]) @ u_axis, (poly - poly[0]) @ v_axis], 1) / tile)
        faces.extend([base, base + i, base + i + 1] for i in range(1, len(poly) - 1))
    return Part(name, np.asarray(verts, float), np.asarray(faces, np.int64), material,
                np.asarray(uvs, float), target)


def build_test_building(seed: int = 0) -> Scene:
    """The test building scene (textures seeded by `seed`)."""
    x, y, h, a = _SIZE_X / 2, _SIZE_Y / 2, _WALL_H, _APEX_H
    c = np.array
    walls = [
        c([[-x, -y, 0], [x, -y, 0], [x, -y, h], [-x, -y, h]]),
        c([[x, y, 0], [-x, y, 0], [-x, y, h], [x, y, h]]),
        c([[x, -y, 0], [x, y, 0], [x, y, h], [0.0 + x, 0, a], [x, -y, h]]),
        c([[-x, y, 0], [-x, -y, 0], [-x, -y, h], [-x, 0, a], [-x, y, h]]),
    ]
    roof = [
        c([[-x, -y, h], [x, -y, h], [x, 0, a], [-x, 0, a]]),
        c([[x, y, h], [-x, y, h], [-x, 0, a], [x, 0, a]]),
    ]
    g = 3.0
    ground = [c([[-g, -g, 0], [g, -g, 0], [g, g, 0], [-g, g, 0]])]
    return Scene(
        name="test_building",
        parts=(
            _polygon_part("walls", walls, Material("brick", texture=_texture("brick", seed)), 0.25),
            _polygon_part("roof", roof, Material("tile", texture=_texture("tile", seed + 1)), 0.2),
            _polygon_part("ground", ground, Material("grass", texture=_texture("grass", seed + 2)),
                          0.5, target=False),
        ),
        lighting=Lighting(),
    )
