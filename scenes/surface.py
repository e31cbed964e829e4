"""From triangles to textured `Part`s: planar UV mapping and materials by role.

UVs are projected per face in world metres: on walls and slopes u runs
horizontally along the face and the image's up points up the slope; on
horizontal faces the image's x and up follow x and y. Coplanar faces therefore
share one continuous texture, roof tiles run in horizontal courses and bricks
lie level on every wall. UVs follow Mitsuba's bitmap convention (v grows down
the image, see `scenes.model.Part.uv`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from scenes.model import Material, Part
from scenes.textures import TEXTURES, texture_path


@dataclass(frozen=True)
class Finish:
    """How one role of a building (walls, roof, trim, ...) looks."""

    texture: str | None
    """A name in `scenes.textures.TEXTURES`, or None for a plain colour."""
    color: tuple[float, float, float] = (0.7, 0.7, 0.7)
    """sRGB colour where `texture` is None."""
    rotate: bool = False
    """Turn the texture by 90 degrees (boards running horizontally, grain along a lintel)."""
    roughness: float | None = None
    """GGX roughness of a glossy coat (glazed tiles, glass), None for matte."""

    def material(self, name: str, seed: int) -> Material:
        """The `Material` of role `name`, its texture generated (or found in the cache) for `seed`."""
        path = texture_path(self.texture, seed) if self.texture is not None else None
        return Material(name, self.color, path, self.roughness)


def planar_uv(corners: np.ndarray, tile_m: float, rotate: bool = False) -> np.ndarray:
    """(F, 3, 2) texture coordinates of (F, 3, 3) triangle corners, one tile per `tile_m` metres."""
    normal = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    normal /= np.linalg.norm(normal, axis=1, keepdims=True) + 1e-300
    u = np.cross(np.array([0.0, 0.0, 1.0]), normal)
    flat = (np.abs(normal[:, 2]) > 0.9) | ~(np.linalg.norm(u, axis=1) > 1e-9)  # or zero-area faces
    u[flat] = (1.0, 0.0, 0.0)
    u /= np.linalg.norm(u, axis=1, keepdims=True)
    v = np.cross(normal, u)
    v[flat] = (0.0, 1.0, 0.0)
    uv = np.stack([np.einsum("fck,fk->fc", corners, u), -np.einsum("fck,fk->fc", corners, v)], -1) / tile_m
    return np.stack([uv[..., 1], -uv[..., 0]], -1) if rotate else uv


def make_part(
    name: str,
    corners: np.ndarray,
    uv: np.ndarray | None,
    material: Material,
    target: bool = True,
    merge: bool = True,
) -> Part:
    """A `Part` from (F, 3, 3) corners and (F, 3, 2) UVs; corners sharing position and UV are
    merged unless `merge` is False (faster for meshes of millions of triangles)."""
    flat_uv = uv.reshape(-1, 2) if uv is not None else np.zeros((corners.size // 3, 2))
    if not merge:
        faces = np.arange(len(flat_uv), dtype=np.int64).reshape(-1, 3)
        return Part(
            name,
            corners.reshape(-1, 3).copy(),
            faces,
            material,
            flat_uv.copy() if uv is not None else None,
            target,
        )
    rows = np.round(np.concatenate([corners.reshape(-1, 3), flat_uv], 1), 9)
    unique, inverse = np.unique(rows, axis=0, return_inverse=True)
    return Part(
        name,
        unique[:, :3].copy(),
        inverse.reshape(-1, 3).astype(np.int64),
        material,
        unique[:, 3:].copy() if uv is not None else None,
        target,
    )


def textured_parts(
    triangles: dict[str, np.ndarray], finishes: dict[str, Finish], seed: int, target: bool = True
) -> list[Part]:
    """One textured `Part` per role in `triangles` (role -> (F, 3, 3) corners, metres)."""
    parts = []
    for role, corners in triangles.items():
        finish = finishes[role]
        tile = TEXTURES[finish.texture].tile_m if finish.texture is not None else 1.0
        uv = planar_uv(corners, tile, finish.rotate)
        parts.append(make_part(role, corners, uv, finish.material(role, seed), target))
    return parts
