"""Solid modelling with materials: closed solids are added and cut in order.

Buildings are assembled from overlapping closed solids (walls, plinths, beams,
roof plates, chimneys) and recesses cut into them (window and door openings).
Boolean union removes every face buried inside another solid, so the target
mesh holds only surfaces that can be seen from outside (a wall's foot inside a
plinth, a chimney's root inside the roof, a beam's back against the wall are
all gone). Faces lying on the ground (z = 0) and facing down are dropped too:
no camera above the ground could see them. Each output triangle keeps the
material of the solid it came from (a cut face takes the cutter's material).
"""

from __future__ import annotations

import manifold3d as mf
import numpy as np

GROUND_EPS = 1e-6
"""Height (metres) under which a downward face counts as lying on the ground."""


class SolidBuilder:
    """Accumulates `add` and `cut` operations on closed solids, each with a material name."""

    def __init__(self) -> None:
        self._ops: list[tuple[str, list[mf.Manifold]]] = []
        self._materials: dict[int, str] = {}

    def add(self, solid: mf.Manifold, material: str) -> None:
        """Union `solid` (faces of `material`) into the model."""
        self._push("add", solid, material)

    def cut(self, solid: mf.Manifold, material: str) -> None:
        """Subtract `solid` from everything added so far; the new faces get `material`."""
        self._push("cut", solid, material)

    def _push(self, kind: str, solid: mf.Manifold, material: str) -> None:
        if solid.is_empty():
            raise ValueError(f"empty solid for material {material!r}")
        original = solid.as_original()
        self._materials[original.original_id()] = material
        if self._ops and self._ops[-1][0] == kind:
            self._ops[-1][1].append(original)
        else:
            self._ops.append((kind, [original]))

    def triangles(self) -> dict[str, np.ndarray]:
        """The resulting surface: material name -> (F, 3, 3) triangle corners (outward winding)."""
        result: mf.Manifold | None = None
        for kind, solids in self._ops:
            group = mf.Manifold.batch_boolean(solids, mf.OpType.Add) if len(solids) > 1 else solids[0]
            if kind == "add":
                result = group if result is None else result + group
            elif result is not None:
                result = result - group
        if result is None or result.is_empty():
            raise ValueError("the solid model is empty")
        mesh = result.to_mesh64()
        corners = np.asarray(mesh.vert_properties)[:, :3][np.asarray(mesh.tri_verts)]
        runs = np.asarray(mesh.run_index) // 3
        ids = np.asarray(mesh.run_original_id)
        material = np.empty(len(corners), dtype=object)
        for start, stop, ident in zip(runs[:-1], runs[1:], ids):
            material[start:stop] = self._materials[int(ident)]
        normal = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
        area2 = np.linalg.norm(normal, axis=1)
        keep = (area2 > 1e-12) & ~((corners[:, :, 2].max(axis=1) < GROUND_EPS) & (normal[:, 2] < 0))
        return {name: corners[keep & (material == name)] for name in dict.fromkeys(material[keep])}
