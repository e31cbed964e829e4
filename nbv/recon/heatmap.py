"""Distance heat maps: our stand-in for the paper's CloudCompare mesh-to-mesh figure (Fig. 5).

Each vertex of a reconstructed mesh is coloured by its distance to a reference
surface: the exact point-to-triangle distance when the reference is a mesh
(Open3D `RaycastingScene`, as CloudCompare's mesh-to-mesh comparison), the
nearest-neighbour distance when it is a point cloud. The colour scale is fixed
(0 to `max_cm`, larger distances saturate) so that figures compare across runs.
Outputs: a PLY with per-vertex colours and a PNG of orthographic views from a
few sides with a colour bar, drawn by matplotlib (painter's algorithm over the
triangles, mildly shaded so the shape reads), so it needs no display.

Example:
    A triangle 1 cm above another, and the colours of 0 and of 5 cm (saturated) on the default scale:

    >>> below = trimesh.Trimesh([[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1, 2]])
    >>> above = trimesh.Trimesh([[0, 0, 0.01], [1, 0, 0.01], [0, 1, 0.01]], [[0, 1, 2]])
    >>> vertex_distances(above, below).round(6).tolist()
    [0.01, 0.01, 0.01]
    >>> distance_colors(np.array([0.0, 0.05]))[:, :3].tolist()
    [[0, 0, 128], [128, 0, 0]]
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import open3d as o3d
import open3d.core as o3c
import trimesh
from matplotlib import colormaps
from matplotlib.cm import ScalarMappable
from matplotlib.collections import PolyCollection
from matplotlib.colors import Normalize
from matplotlib.figure import Figure

from common.io import atomic_path
from nbv.recon.config import HeatmapConfig
from nbv.recon.metrics import Geometry, as_points, nearest_distances


def vertex_distances(mesh: trimesh.Trimesh, reference: Geometry) -> np.ndarray:
    """Distance (metres) from each vertex of `mesh` to the reference surface or points."""
    vertices = as_points(mesh, "heat-map mesh")
    if isinstance(reference, trimesh.Trimesh):
        as_points(reference, "heat-map reference")
        scene = o3d.t.geometry.RaycastingScene()
        scene.add_triangles(o3c.Tensor(np.asarray(reference.vertices, np.float32)),
                            o3c.Tensor(np.asarray(reference.faces, np.uint32)))
        return scene.compute_distance(o3c.Tensor(vertices.astype(np.float32))).numpy().astype(np.float64)
    return nearest_distances(vertices, as_points(reference, "heat-map reference"))


def distance_colors(distances: np.ndarray, config: HeatmapConfig = HeatmapConfig()) -> np.ndarray:
    """(N, 4) uint8 RGBA colours of distances in metres on the fixed scale."""
    scaled = np.clip(np.asarray(distances) * 100.0 / config.max_cm, 0.0, 1.0)
    return np.round(colormaps[config.colormap](scaled) * 255.0).astype(np.uint8)


def save_heatmap_ply(mesh: trimesh.Trimesh, distances: np.ndarray, path: str | Path,
                     config: HeatmapConfig = HeatmapConfig()) -> Path:
    """Write the mesh with per-vertex distance colours as a binary PLY."""
    coloured = trimesh.Trimesh(mesh.vertices, mesh.faces, process=False,
                               vertex_colors=distance_colors(distances, config))
    out = Path(path)
    out.parent.mkdir(parents=True, exist_ok=True)
    with atomic_path(out) as tmp:
        coloured.export(tmp, file_type="ply")
    return out


def _display_mesh(mesh: trimesh.Trimesh, max_faces: int) -> trimesh.Trimesh:
    """The mesh itself, or a vertex-clustered simplification with at most about `max_faces` faces."""
    if len(mesh.faces) <= max_faces:
        return mesh
    legacy = o3d.geometry.TriangleMesh(o3d.utility.Vector3dVector(np.asarray(mesh.vertices)),
                                       o3d.utility.Vector3iVector(np.asarray(mesh.faces, np.int32)))
    cell = math.sqrt(mesh.area / max_faces) * 1.5
    simple = legacy.simplify_vertex_clustering(voxel_size=cell)
    return trimesh.Trimesh(np.asarray(simple.vertices), np.asarray(simple.triangles), process=False)


def _view_axes(azimuth_deg: float, elevation_deg: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Screen right, screen up and the direction towards the viewer for an orthographic view."""
    az, el = math.radians(azimuth_deg), math.radians(elevation_deg)
    toward = np.array([math.cos(el) * math.cos(az), math.cos(el) * math.sin(az), math.sin(el)])
    right = np.array([-math.sin(az), math.cos(az), 0.0])
    return right, np.cross(toward, right), toward


def render_heatmap_png(mesh: trimesh.Trimesh, reference: Geometry, path: str | Path,
                       config: HeatmapConfig = HeatmapConfig(), title: str = "") -> Path:
    """Draw the mesh coloured by distance to `reference` from each configured side, with a colour bar.

    Faces are drawn far to near (painter's algorithm) in an orthographic
    projection; a face's colour is its vertices' mean distance, shaded by the
    angle to the viewer so the shape reads (the bar gives the unshaded scale).
    """
    shown = _display_mesh(mesh, config.max_faces)
    face_dist = vertex_distances(shown, reference)[shown.faces].mean(axis=1)
    base = distance_colors(face_dist, config).astype(np.float64) / 255.0
    tris = np.asarray(shown.vertices)[shown.faces]
    normals = np.asarray(shown.face_normals)
    lo, hi = shown.bounds
    span = float(np.max(hi - lo)) * 0.6
    centre = (lo + hi) / 2.0
    n = len(config.views)
    fig = Figure(figsize=(3.6 * n + 1.2, 3.9))
    axes = fig.subplots(1, n, squeeze=False)
    for ax, azimuth in zip(axes[0], config.views):
        right, up, toward = _view_axes(azimuth, config.elevation_deg)
        rel = tris - centre
        xy = np.stack([rel @ right, rel @ up], axis=-1)
        order = np.argsort((rel @ toward).mean(axis=1))
        shade = 0.65 + 0.35 * np.abs(normals @ toward)
        colors = base.copy()
        colors[:, :3] *= shade[:, None]
        # autolim off: the limits are set just below, so a data-limit pass over every face is wasted.
        ax.add_collection(PolyCollection(xy[order], facecolors=colors[order], edgecolors="none",
                                         antialiased=False), autolim=False)
        ax.set_xlim(-span, span)
        ax.set_ylim(-span, span)
        ax.set_aspect("equal")
        ax.set_axis_off()
        ax.set_title(f"azimuth {azimuth:.0f}°, elevation {config.elevation_deg:.0f}°", fontsize=9)
    mappable = ScalarMappable(norm=Normalize(0.0, config.max_cm), cmap=config.colormap)
    bar = fig.colorbar(mappable, ax=axes[0].tolist(), fraction=0.02, pad=0.01, extend="max")
    bar.set_label("distance to reference (cm)")
    if title:
        fig.suptitle(title, fontsize=11)
    out = Path(path)
    out.parent.mkdir(parents=True, exist_ok=True)
    with atomic_path(out) as tmp:
        fig.savefig(tmp, dpi=110)
    return out


def write_heatmap(mesh: trimesh.Trimesh, reference: Geometry, out: str | Path,
                  config: HeatmapConfig = HeatmapConfig(), name: str = "heatmap",
                  title: str = "") -> tuple[Path, Path]:
    """Write `out/<name>.ply` (coloured vertices) and `out/<name>.png`; return both paths."""
    folder = Path(out)
    ply = save_heatmap_ply(mesh, vertex_distances(mesh, reference), folder / f"{name}.ply", config)
    png = render_heatmap_png(mesh, reference, folder / f"{name}.png", config, title)
    return ply, png
