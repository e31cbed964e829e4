"""Heat maps: distances against analytic answers, colours on the fixed scale, files read back."""

from __future__ import annotations

import numpy as np
import pytest
import trimesh
from PIL import Image
from scipy.spatial import cKDTree

from nbv.recon.heatmap import HeatmapConfig, distance_colors, vertex_distances, write_heatmap


def test_vertex_distance_to_a_mesh_is_point_to_triangle() -> None:
    ground = trimesh.Trimesh([[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0]], [[0, 1, 2], [0, 2, 3]])
    probe = trimesh.Trimesh([[0.1, 0.2, 0.03], [0.5, -0.4, -0.02], [2.0, 0.0, 0.0]], [[0, 1, 2]])
    np.testing.assert_allclose(vertex_distances(probe, ground), [0.03, 0.02, 1.0], atol=1e-6)


def test_vertex_distance_to_points_is_nearest_neighbour() -> None:
    rng = np.random.default_rng(0)
    mesh = trimesh.creation.icosphere(subdivisions=2)
    cloud = rng.normal(size=(500, 3))
    expected, _ = cKDTree(cloud).query(mesh.vertices)
    np.testing.assert_allclose(vertex_distances(mesh, trimesh.PointCloud(cloud)), expected, rtol=1e-12)


def test_colour_scale_saturates_at_max() -> None:
    config = HeatmapConfig(max_cm=2.0, colormap="viridis")
    colors = distance_colors(np.array([0.0, 0.02, 0.5]), config)
    assert colors.dtype == np.uint8 and colors.shape == (3, 4)
    np.testing.assert_array_equal(colors[1], colors[2])
    assert not np.array_equal(colors[0], colors[1])


def test_write_heatmap_files_read_back(tmp_path) -> None:
    reference = trimesh.creation.box(extents=(1.0, 0.6, 0.8))
    bumped = reference.subdivide().subdivide()
    bumped.vertices[bumped.vertices[:, 2] > 0.39] += (0, 0, 0.012)  # the roof 1.2 cm too high
    config = HeatmapConfig(max_cm=2.0, views=(30.0, 210.0))
    ply, png = write_heatmap(bumped, reference, tmp_path, config, title="bumped box")
    back = trimesh.load(ply, process=False)
    assert len(back.vertices) == len(bumped.vertices)
    top = bumped.vertices[:, 2] > 0.39
    expected = distance_colors(np.where(top, 0.012, 0.0), config)
    np.testing.assert_array_equal(back.visual.vertex_colors, expected)
    image = np.asarray(Image.open(png).convert("RGB"))
    assert image.shape[1] > image.shape[0] > 200
    assert len(np.unique(image.reshape(-1, 3), axis=0)) > 20  # drawn, not blank


def test_empty_mesh_is_rejected(tmp_path) -> None:
    empty = trimesh.Trimesh(np.zeros((0, 3)), np.zeros((0, 3), int))
    with pytest.raises(ValueError, match="heat-map mesh is an empty mesh"):
        write_heatmap(empty, trimesh.creation.box(), tmp_path)
