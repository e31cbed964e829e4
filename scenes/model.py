"""The scene description shared by every package: plain arrays, no renderer.

A `Scene` is a list of textured triangle `Part`s plus `Lighting`. `render/`
turns it into a Mitsuba scene; `nbv/` takes the target mesh (the parts marked
`target`, i.e. everything but the ground) for metrics. Units are metres, the
world is right-handed with z up, and a normalised target stands on z = 0,
centred on the z axis, its largest side 1 m (docs/conventions.md).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import trimesh


@dataclass(frozen=True)
class Material:
    """A diffuse (optionally glossy) surface, textured or of one colour."""

    name: str
    """Material name, unique within a scene."""
    color: tuple[float, float, float] = (0.7, 0.7, 0.7)
    """sRGB base colour in [0, 1], used where `texture` is None."""
    texture: Path | None = None
    """sRGB PNG tiled by the part's UVs (wrap mode repeat); None for a plain colour."""
    roughness: float | None = None
    """None for a Lambertian surface; else the GGX roughness of a plastic coating."""


@dataclass(frozen=True)
class Part:
    """One triangle mesh with one material."""

    name: str
    """Part name, unique within a scene."""
    vertices: np.ndarray
    """(V, 3) float64 positions in metres."""
    faces: np.ndarray
    """(F, 3) int64 vertex indices, counter-clockwise seen from outside."""
    material: Material
    """Surface appearance."""
    uv: np.ndarray | None = None
    """(V, 2) float texture coordinates, or None. As Mitsuba samples bitmaps, v grows down the
    image (v = 0 is its top row); OBJ-style coordinates (v up) are flipped when a mesh is loaded."""
    target: bool = True
    """False for context geometry (the ground) that metrics must ignore."""

    def __post_init__(self) -> None:
        validate_arrays(self.name, self.vertices, self.faces, self.uv)


@dataclass(frozen=True)
class Lighting:
    """A sun (directional light) and a uniform sky."""

    sun_azimuth_deg: float = 35.0
    """Azimuth of the sun, counter-clockwise from +x, degrees."""
    sun_elevation_deg: float = 50.0
    """Elevation of the sun above the horizon, degrees."""
    sun_irradiance: float = 3.0
    """Irradiance of the sun (linear, per RGB channel)."""
    sky_radiance: tuple[float, float, float] = (0.55, 0.6, 0.7)
    """Linear RGB radiance of the uniform sky."""

    def sun_direction(self) -> np.ndarray:
        """Unit vector along which sunlight travels (from the sun towards the scene)."""
        az, el = np.radians(self.sun_azimuth_deg), np.radians(self.sun_elevation_deg)
        return -np.array([np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), np.sin(el)])


@dataclass(frozen=True)
class Scene:
    """A renderable target with its context, or a user's Mitsuba XML file."""

    name: str
    """Scene identifier, as given on the command line (e.g. a preset name)."""
    parts: tuple[Part, ...]
    """Geometry; parts with `target=True` form the reconstruction target."""
    lighting: Lighting = field(default_factory=Lighting)
    """Sun and sky."""
    mitsuba_xml: Path | None = None
    """A Mitsuba XML file rendered as is instead of `parts` and `lighting`."""

    def target_mesh(self) -> trimesh.Trimesh:
        """The target parts merged into one mesh (no ground), as exported and measured."""
        if self.mitsuba_xml is not None:
            raise ValueError(f"{self.mitsuba_xml} is a Mitsuba XML scene, rendered as is: it has no "
                             "separate target mesh to export or measure (export the mesh files its shapes "
                             "load instead)")
        targets = [p for p in self.parts if p.target]
        if not targets:
            raise ValueError(f"scene {self.name!r} has no target geometry")
        meshes = [trimesh.Trimesh(p.vertices, p.faces, process=False) for p in targets]
        return trimesh.util.concatenate(meshes)

    def center(self) -> np.ndarray:
        """Centre of the target's bounding box: the point every viewpoint looks at."""
        lo, hi = self.bounds()
        return (lo + hi) / 2.0

    def bounds(self) -> tuple[np.ndarray, np.ndarray]:
        """Axis-aligned bounds (min, max) of the target parts."""
        verts = np.concatenate([p.vertices for p in self.parts if p.target])
        return verts.min(axis=0), verts.max(axis=0)

    def sample_surface(self, count: int, seed: int) -> np.ndarray:
        """`count` points drawn uniformly (by area) from the target surface, seeded."""
        mesh = self.target_mesh()
        points, _ = trimesh.sample.sample_surface(mesh, count, seed=seed)
        return np.asarray(points, dtype=np.float64)


def validate_arrays(
    name: str, vertices: np.ndarray, faces: np.ndarray, uv: np.ndarray | None
) -> None:
    """Reject mesh arrays that would crash or silently corrupt rendering, naming the fault."""
    if vertices.ndim != 2 or vertices.shape[1] != 3:
        raise ValueError(f"part {name!r}: vertices must be (V, 3), got {vertices.shape}")
    if faces.ndim != 2 or faces.shape[1] != 3:
        raise ValueError(f"part {name!r}: faces must be (F, 3), got {faces.shape}")
    if len(faces) == 0:
        raise ValueError(f"part {name!r}: mesh has no faces")
    if not np.all(np.isfinite(vertices)):
        raise ValueError(f"part {name!r}: vertices contain NaN or infinite values")
    if faces.min() < 0 or faces.max() >= len(vertices):
        raise ValueError(
            f"part {name!r}: face indices out of range [0, {len(vertices)}):"
            f" min {faces.min()}, max {faces.max()}"
        )
    if uv is not None and uv.shape != (len(vertices), 2):
        raise ValueError(f"part {name!r}: uv must be ({len(vertices)}, 2), got {uv.shape}")
