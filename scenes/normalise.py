"""Normalising a target (docs/conventions.md) and the ground it stands on.

A normalised scene is z-up, its target's bounding box is centred on the z axis,
its base lies on z = 0 and its largest side measures 1 m. Parts that are not
target (the ground) follow the same transform but do not count for the bounds.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from scenes.axes import UP_AXES
from scenes.model import Part
from scenes.surface import Finish, make_part
from scenes.textures import TEXTURES


def up_to_z(vertices: np.ndarray, up_axis: str) -> np.ndarray:
    """Rotate (V, 3) positions so that `up_axis` becomes +z (a proper rotation: y up -> z up)."""
    if up_axis not in UP_AXES:
        raise ValueError(f"up axis must be one of {', '.join(UP_AXES)}, got {up_axis!r}")
    if up_axis == "z":
        return vertices
    return np.stack([vertices[:, 0], -vertices[:, 2], vertices[:, 1]], axis=1)


def normalise_parts(parts: list[Part], up_axis: str = "z") -> tuple[Part, ...]:
    """Parts rotated to z up, scaled and moved so the target stands normalised.

    Raises:
        ValueError: no target part, or a target of zero or overflowing size.
    """
    verts = [up_to_z(p.vertices, up_axis) for p in parts]
    targets = [v for v, p in zip(verts, parts) if p.target]
    if not targets:
        raise ValueError("cannot normalise: the scene has no target geometry")
    lo = np.min([v.min(axis=0) for v in targets], axis=0)
    hi = np.max([v.max(axis=0) for v in targets], axis=0)
    with np.errstate(over="ignore", invalid="ignore"):
        extent = float(np.max(hi - lo))
    if not extent > 0:
        raise ValueError("cannot normalise: the target mesh has zero size (all vertices coincide)")
    if not np.isfinite(extent):
        raise ValueError(f"cannot normalise: the target mesh's extent overflows (from {lo} to {hi})")
    offset = np.array([lo[0] / 2 + hi[0] / 2, lo[1] / 2 + hi[1] / 2, lo[2]])
    with np.errstate(over="ignore", invalid="ignore"):
        moved = [(v - offset) / extent for v in verts]
    if not all(np.all(np.isfinite(v)) for v in moved):
        raise ValueError("cannot normalise: a part lies too far from the target (coordinates overflow)")
    return tuple(replace(p, vertices=v) for v, p in zip(moved, parts))


def make_ground(
    finish: Finish,
    seed: int,
    center: tuple[float, float] | np.ndarray = (0.0, 0.0),
    half_m: float = 3.0,
    tile_m: float | None = None,
) -> Part:
    """A textured square ground plane at z = 0 (not part of the target).

    Args:
        finish: ground finish (grass, gravel, ...).
        seed: texture seed.
        center: (x, y) centre of the square.
        half_m: half the side of the square.
        tile_m: metres per texture tile (default: the texture's real-world tile).
    """
    cx, cy = float(center[0]), float(center[1])
    corners = np.array(
        [
            [cx - half_m, cy - half_m, 0.0],
            [cx + half_m, cy - half_m, 0.0],
            [cx + half_m, cy + half_m, 0.0],
            [cx - half_m, cy + half_m, 0.0],
        ]
    )
    triangles = corners[[[0, 1, 2], [0, 2, 3]]]
    tile = tile_m or (TEXTURES[finish.texture].tile_m if finish.texture else 1.0)
    uv = triangles[..., :2] / tile
    return make_part("ground", triangles, uv, finish.material("ground", seed), target=False)
