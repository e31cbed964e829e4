"""Fused coverage's pieces: the bounded neighbour test against brute force; meshes as their PLY holds them."""

from __future__ import annotations

import numpy as np
import trimesh

from nbv.recon.fused_coverage import as_stored, within


def test_within_is_a_brute_force_nearest_distance_below_the_radius():
    rng = np.random.default_rng(0)
    query, points = rng.random((300, 3)), rng.random((200, 3))
    brute = np.sqrt(((query[:, None] - points[None]) ** 2).sum(-1)).min(1) < 0.05
    tree = trimesh.PointCloud(points).kdtree
    assert 0 < brute.sum() < len(query)
    assert np.array_equal(within(query, tree, 0.05), brute)
    assert np.array_equal(within(query, tree, 0.05, workers=1), brute)


def test_a_stored_mesh_has_float32_coordinates_and_the_same_faces():
    mesh = trimesh.creation.icosphere(subdivisions=1)
    mesh.vertices *= 1.0 / 3.0  # not exact in float32
    stored = as_stored(mesh)
    assert np.array_equal(stored.faces, mesh.faces)
    assert np.array_equal(stored.vertices, mesh.vertices.astype(np.float32).astype(np.float64))
    assert not np.array_equal(stored.vertices, mesh.vertices)
