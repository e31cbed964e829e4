"""Surface metrics against a brute-force SciPy reference and analytic answers."""

from __future__ import annotations

import time

import numpy as np
import pytest
import trimesh
from scipy.spatial import cKDTree, distance_matrix

from nbv.recon.metrics import (
    MetricsConfig,
    compare_points,
    evaluate_surfaces,
    load_geometry,
    nearest_distances,
    point_tree,
    sample_points,
)


def brute_metrics(pred: np.ndarray, ref: np.ndarray, threshold: float) -> dict[str, float]:
    """All-pairs distances: the definitions of docs/reconstruction.md written out directly."""
    d = distance_matrix(pred, ref)
    to_ref, to_pred = d.min(axis=1), d.min(axis=0)
    p, r = np.mean(to_ref < threshold), np.mean(to_pred < threshold)
    return {"chamfer_cm": 50.0 * (to_ref.mean() + to_pred.mean()),
            "hausdorff_cm": 100.0 * max(to_ref.max(), to_pred.max()),
            "precision": p, "recall": r, "coverage": r, "fscore": 2 * p * r / (p + r)}


def unit_square(z: float) -> trimesh.Trimesh:
    vertices = np.array([[0, 0, z], [1, 0, z], [1, 1, z], [0, 1, z]], dtype=float)
    return trimesh.Trimesh(vertices, [[0, 1, 2], [0, 2, 3]], process=False)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_metrics_match_brute_force_on_random_clouds(seed: int) -> None:
    rng = np.random.default_rng(seed)
    pred = rng.random((700, 3)) * 0.1
    ref = rng.random((500, 3)) * 0.1 + 0.01
    ours = compare_points(pred, ref, threshold_cm=1.0).as_dict()
    for key, value in brute_metrics(pred, ref, 0.01).items():
        assert ours[key] == pytest.approx(value, rel=1e-12, abs=1e-12), key
    assert ours["n_points"] == 500


def test_nearest_distances_match_brute_force() -> None:
    rng = np.random.default_rng(3)
    query, ref = rng.normal(size=(300, 3)), rng.normal(size=(400, 3))
    np.testing.assert_allclose(nearest_distances(query, ref), distance_matrix(query, ref).min(1), rtol=1e-12)


def walls_with_float_noise(n: int, rng: np.random.Generator) -> np.ndarray:
    """Four walls of a 1 x 0.6 x 0.8 m box, each point 1e-9 m off its plane: a TSDF reconstruction of
    flat walls, the set SciPy's default tree cannot prune for far queries."""
    side, u, z = rng.integers(0, 4, n), rng.random(n), rng.random(n) * 0.8
    x = np.where(side < 2, np.where(side == 0, -0.5, 0.5), u - 0.5)
    y = np.where(side < 2, 0.6 * u - 0.3, np.where(side == 2, -0.3, 0.3))
    return np.column_stack([x, y, z]) + rng.normal(0.0, 1e-9, (n, 3))


def test_nearest_distances_are_scipys_default_bits_and_fast_on_thin_walls() -> None:
    rng = np.random.default_rng(4)
    walls = walls_with_float_noise(100_000, rng)
    floor = np.column_stack([rng.uniform(-0.5, 0.5, 1500), rng.uniform(-0.3, 0.3, 1500), np.zeros(1500)])
    assert np.array_equal(nearest_distances(floor, walls), cKDTree(walls).query(floor, k=1)[0])
    assert np.array_equal(nearest_distances(walls[:5000], floor), cKDTree(floor).query(walls[:5000], k=1)[0])
    default, ours = cKDTree(walls), point_tree(walls)
    seconds = []
    for tree in (default, ours):
        start = time.process_time()
        tree.query(floor, k=1, workers=1)
        seconds.append(time.process_time() - start)
    assert seconds[1] * 3 < seconds[0], seconds


def test_parallel_unit_squares_one_centimetre_apart() -> None:
    config = MetricsConfig(n_points=40_000, threshold_cm=1.0, seed=0)
    result = evaluate_surfaces(unit_square(0.01), {"gt": unit_square(0.0)}, config)["gt"]
    # Same seed, congruent squares: every sample faces its twin exactly 1 cm away.
    assert result.chamfer_cm == pytest.approx(1.0, abs=1e-9)
    assert result.hausdorff_cm == pytest.approx(1.0, abs=1e-9)
    shifted = evaluate_surfaces(unit_square(0.01), {"gt": unit_square(0.0)},
                                MetricsConfig(n_points=40_000, threshold_cm=2.0, seed=5))["gt"]
    assert shifted.chamfer_cm == pytest.approx(1.0, abs=0.05)
    assert shifted.hausdorff_cm == pytest.approx(1.0, abs=0.1)
    assert shifted.coverage == 1.0 and shifted.fscore == 1.0


def test_identical_surfaces_score_zero_and_full_coverage() -> None:
    mesh = trimesh.creation.box(extents=(1.0, 0.6, 0.8))
    result = evaluate_surfaces(mesh, {"gt": mesh, "reference": mesh}, MetricsConfig(n_points=5000))
    for metrics in result.values():
        assert metrics.chamfer_cm == 0.0 and metrics.hausdorff_cm == 0.0
        assert metrics.coverage == metrics.precision == metrics.fscore == 1.0


def test_half_surface_has_half_coverage_and_full_precision() -> None:
    square = unit_square(0.0)
    half = trimesh.Trimesh([[0, 0, 0], [0.5, 0, 0], [0.5, 1, 0], [0, 1, 0]], [[0, 1, 2], [0, 2, 3]])
    result = evaluate_surfaces(half, {"gt": square}, MetricsConfig(n_points=40_000, threshold_cm=1.0))["gt"]
    assert result.precision == pytest.approx(1.0, abs=1e-3)
    assert result.coverage == pytest.approx(0.51, abs=0.01)  # the 1 cm band past x = 0.5 counts
    assert result.hausdorff_cm == pytest.approx(50.0, abs=0.5)


def test_sampling_is_seeded_and_uniform_by_area() -> None:
    mesh = trimesh.creation.box(extents=(1.0, 1.0, 0.01))
    a, b = sample_points(mesh, 20_000, seed=7), sample_points(mesh, 20_000, seed=7)
    np.testing.assert_array_equal(a, b)
    assert not np.array_equal(a, sample_points(mesh, 20_000, seed=8))
    top = np.mean(np.isclose(a[:, 2], 0.005))
    assert top == pytest.approx(1.0 / 2.04, abs=0.02)  # area share of the top face


def test_point_clouds_are_subsampled_without_replacement() -> None:
    cloud = np.random.default_rng(0).random((1000, 3))
    sub = sample_points(trimesh.PointCloud(cloud), 100, seed=0)
    assert len(sub) == 100 and len(np.unique(sub, axis=0)) == 100
    np.testing.assert_array_equal(sample_points(cloud, 5000, seed=0), cloud)


@pytest.mark.parametrize("bad, message", [
    (trimesh.Trimesh(np.zeros((0, 3)), np.zeros((0, 3), int)), "empty mesh"),
    (np.zeros((0, 3)), "empty"),
    (np.array([[0.0, np.nan, 0.0]]), "NaN"),
    (trimesh.Trimesh([[0, 0, 0], [1, 0, 0], [2, 0, 0]], [[0, 1, 2]], process=False), "degenerate"),
])
def test_bad_surfaces_are_rejected_by_name(bad, message: str) -> None:
    with pytest.raises(ValueError, match=message) as info:
        evaluate_surfaces(bad, {"gt": unit_square(0.0)}, MetricsConfig(n_points=100))
    assert "reconstruction" in str(info.value)
    with pytest.raises(ValueError, match="gt reference"):
        evaluate_surfaces(unit_square(0.0), {"gt": bad}, MetricsConfig(n_points=100))


def test_load_geometry_reads_meshes_and_clouds_and_rejects_empty_files(tmp_path) -> None:
    mesh_path, cloud_path = tmp_path / "m.ply", tmp_path / "c.ply"
    unit_square(0.0).export(mesh_path)
    trimesh.PointCloud(np.random.default_rng(0).random((50, 3))).export(cloud_path)
    assert isinstance(load_geometry(mesh_path), trimesh.Trimesh)
    assert len(load_geometry(cloud_path).vertices) == 50
    empty = tmp_path / "empty.ply"
    empty.write_text("ply\nformat ascii 1.0\nelement vertex 0\nproperty float x\nproperty float y\n"
                     "property float z\nend_header\n")
    with pytest.raises(ValueError, match="empty.ply"):
        load_geometry(empty)
    garbage = tmp_path / "garbage.ply"
    garbage.write_bytes(b"not a ply file")
    with pytest.raises(ValueError, match="garbage.ply"):
        load_geometry(garbage)
    with pytest.raises(FileNotFoundError, match="missing.ply"):
        load_geometry(tmp_path / "missing.ply")
