"""TSDF fusion against exact ray-cast depth and against a small rendered hemisphere scan."""

from __future__ import annotations

import math

import numpy as np
import pytest
import trimesh
from PIL import Image

from nbv.recon.heatmap import vertex_distances
from nbv.recon.metrics import MetricsConfig, evaluate_surfaces
from nbv.recon.tsdf import (
    ReconstructionConfig,
    TSDFFusion,
    reconstruct_dataset,
    reconstruct_views,
    save_reconstruction,
)
from render.camera import UAVCamera
from render.dataset import DatasetError, DatasetWriter, read_dataset
from render.raycast import DepthRaycaster
from render.scan import HemispherePlan, hemisphere_scan
from render.viewpoint import Viewpoint, viewpoint_to_c2w
from scenes import load_scene

CAMERA = UAVCamera(160, 120)
SMALL_SCAN = HemispherePlan(end_overlap=0.6, side_overlap=0.6)  # 57 views at R = 2 m
VOXEL = ReconstructionConfig().voxel_size_m


@pytest.fixture(scope="module")
def scene():
    return load_scene("test_building")


@pytest.fixture(scope="module")
def gt(scene) -> trimesh.Trimesh:
    return scene.target_mesh()


@pytest.fixture(scope="module")
def raycast_views(scene) -> list[tuple[np.ndarray, np.ndarray, np.ndarray, Viewpoint]]:
    """Exact depth of the whole scene (target and ground) along the small hemisphere scan."""
    caster = DepthRaycaster([trimesh.Trimesh(p.vertices, p.faces) for p in scene.parts],
                            CAMERA.K, CAMERA.width, CAMERA.height)
    rgb = np.full((CAMERA.height, CAMERA.width, 3), (200, 100, 50), np.uint8)
    views = []
    for view in hemisphere_scan(CAMERA, SMALL_SCAN):
        c2w = viewpoint_to_c2w(view, scene.center())
        views.append((rgb, caster.depth(c2w), c2w, view))
    return views


@pytest.fixture(scope="module")
def raycast_recon(raycast_views):
    return reconstruct_views([v[:3] for v in raycast_views], CAMERA.K)


def test_full_scan_of_exact_depth_matches_ground_truth(raycast_recon, gt) -> None:
    """Renderer-free twin of the acceptance test: exact depth of the test building, 160 x 120 px."""
    metrics = evaluate_surfaces(raycast_recon.mesh, {"gt": gt}, MetricsConfig(n_points=500_000))["gt"]
    assert metrics.coverage >= 0.95
    assert metrics.chamfer_cm <= 0.3
    distances = vertex_distances(raycast_recon.mesh, gt)
    assert np.percentile(distances, 95) <= 2 * VOXEL  # no spurious surfaces
    assert raycast_recon.n_views == 57


def test_ground_is_cropped_by_default_and_kept_on_request(raycast_views, raycast_recon) -> None:
    crop = ReconstructionConfig().ground_crop_m
    assert crop == pytest.approx(VOXEL)
    assert raycast_recon.mesh.vertices[:, 2].min() >= crop
    assert raycast_recon.points.vertices[:, 2].min() >= crop
    config = ReconstructionConfig(crop_ground=False)
    kept = reconstruct_views([v[:3] for v in raycast_views[-1:]], CAMERA.K, config)  # the pole view
    ground = np.abs(kept.mesh.vertices[:, 2]) < VOXEL
    assert np.any(ground & (np.abs(kept.mesh.vertices[:, 0]) > 0.8))  # ground well beyond the walls


def test_colours_are_fused_and_optional(raycast_views, raycast_recon) -> None:
    colors = raycast_recon.mesh.visual.vertex_colors[:, :3].astype(int)
    np.testing.assert_allclose(np.median(colors, axis=0), (200, 100, 50), atol=1)
    assert raycast_recon.points.colors.shape == (len(raycast_recon.points.vertices), 4)
    subset = [v[:3] for v in raycast_views[::6]]
    plain = reconstruct_views(subset, CAMERA.K, ReconstructionConfig(color=False))
    np.testing.assert_array_equal(plain.mesh.vertices, reconstruct_views(subset, CAMERA.K).mesh.vertices)


def test_fusion_is_deterministic_and_incremental_equals_batch(raycast_views) -> None:
    subset = [v[:3] for v in raycast_views[::6]]
    fusion = TSDFFusion(CAMERA.K, CAMERA.width, CAMERA.height)
    for view in subset:
        fusion.integrate(*view)
    batch = reconstruct_views(subset, CAMERA.K)
    incremental = fusion.extract_mesh()
    np.testing.assert_array_equal(incremental.vertices, batch.mesh.vertices)
    np.testing.assert_array_equal(incremental.faces, batch.mesh.faces)
    np.testing.assert_array_equal(fusion.extract_points().vertices, batch.points.vertices)


def test_frontal_plane_lands_at_its_depth() -> None:
    """One camera on +x looking at a wall at x = 0.5: checks world-to-camera handling and z-depth."""
    wall = trimesh.Trimesh([[0.5, -1, 0.05], [0.5, 1, 0.05], [0.5, 1, 1.5], [0.5, -1, 1.5]],
                           [[0, 1, 2], [0, 2, 3]])
    c2w = viewpoint_to_c2w(Viewpoint(1.5, 0.0, 0.0), np.array([0.0, 0.0, 0.6]))
    depth = DepthRaycaster([wall], CAMERA.K, CAMERA.width, CAMERA.height).depth(c2w)
    np.testing.assert_allclose(depth[depth > 0], 1.0, atol=1e-5)
    rgb = np.zeros((CAMERA.height, CAMERA.width, 3), np.uint8)
    recon = reconstruct_views([(rgb, depth, c2w)], CAMERA.K)
    np.testing.assert_allclose(recon.mesh.vertices[:, 0], 0.5, atol=0.1 * VOXEL)


@pytest.mark.slow
def test_rendered_hemisphere_scan_of_a_preset_covers_and_one_side_does_not(tmp_path) -> None:
    """The acceptance scan: Mitsuba renders of a preset written as a dataset, read back, fused, measured.

    240 x 180 px, 37 views at R = 2 m (a small version of the 288-view scan): a pixel spans
    8.6 mm on the target, about two voxels.
    """
    from render.capture import capture_dataset
    from render.settings import RenderSettings

    preset = load_scene("medieval_tavern")
    camera = UAVCamera(240, 180)
    views = hemisphere_scan(camera, HemispherePlan(end_overlap=0.5, side_overlap=0.5))
    path = capture_dataset(preset, camera, views, tmp_path / "scan",
                           RenderSettings(spp=1, integrator="direct"), progress=False)
    dataset = read_dataset(path)
    gt = preset.target_mesh()
    full = reconstruct_dataset(dataset)
    metrics = evaluate_surfaces(full.mesh, {"gt": gt}, MetricsConfig())["gt"]
    assert metrics.coverage >= 0.95
    assert metrics.chamfer_cm <= 0.3
    assert np.percentile(vertex_distances(full.mesh, gt), 95) <= 2 * VOXEL
    east = [i for i, f in enumerate(dataset.frames) if math.cos(f.viewpoint.azimuth) > 0.5]
    side = reconstruct_dataset(dataset, indices=east)
    one_side = evaluate_surfaces(side.mesh, {"gt": gt}, MetricsConfig(n_points=100_000))["gt"]
    assert one_side.coverage <= 0.85 and one_side.coverage <= metrics.coverage - 0.1
    mesh_path, points_path = save_reconstruction(full, tmp_path / "recon")
    back = trimesh.load(mesh_path, process=False)
    np.testing.assert_allclose(back.vertices, full.mesh.vertices, atol=1e-6)
    assert len(trimesh.load(points_path).vertices) == len(full.points.vertices)


def _good_view():
    rgb = np.zeros((CAMERA.height, CAMERA.width, 3), np.uint8)
    depth = np.full((CAMERA.height, CAMERA.width), 2.0, np.float32)
    return rgb, depth, viewpoint_to_c2w(Viewpoint(2.0, 0.0, 0.5), np.zeros(3))


def test_nan_pose_is_rejected_by_view() -> None:
    rgb, depth, c2w = _good_view()
    bad = c2w.copy()
    bad[0, 3] = np.nan
    with pytest.raises(ValueError, match="view 1 pose contains NaN"):
        reconstruct_views([(rgb, depth, c2w), (rgb, depth, bad)], CAMERA.K)


@pytest.mark.parametrize("change, message", [
    (lambda rgb, depth: (rgb, depth[:, :80]), "view 0: depth map is"),
    (lambda rgb, depth: (rgb[:60], depth), r"view 0: rgb must be \(120, 160, 3\)"),
    (lambda rgb, depth: (rgb, np.where(depth > 0, np.nan, depth)), "view 0: depth contains NaN"),
])
def test_malformed_views_are_rejected_by_view(change, message: str) -> None:
    rgb, depth, c2w = _good_view()
    fusion = TSDFFusion(CAMERA.K, CAMERA.width, CAMERA.height)
    with pytest.raises(ValueError, match=message):
        fusion.integrate(*change(rgb, depth), c2w)


def test_empty_input_and_empty_depth_are_clear_errors() -> None:
    with pytest.raises(ValueError, match="no views"):
        reconstruct_views([], CAMERA.K)
    rgb, depth, c2w = _good_view()
    with pytest.raises(ValueError, match="no surface reconstructed from 1 views"):
        reconstruct_views([(rgb, np.zeros_like(depth), c2w)], CAMERA.K)
    with pytest.raises(ValueError, match="intrinsics K"):
        TSDFFusion(np.full((3, 3), np.nan), CAMERA.width, CAMERA.height)
    with pytest.raises(ValueError, match="truncation_m"):
        ReconstructionConfig(truncation_m=0.001)


def test_dataset_whose_depth_does_not_match_its_images_is_named(tmp_path) -> None:
    rgb, depth, c2w = _good_view()
    with DatasetWriter(tmp_path / "ds", CAMERA, {"scene": "none"}) as writer:
        writer.add(rgb, depth, c2w)
        writer.add(rgb, depth, c2w)
    depth_file = tmp_path / "ds" / "depth" / "0001.png"
    Image.fromarray(np.zeros((60, 80), np.uint16)).save(depth_file)
    with pytest.raises(DatasetError, match="0001.png"):
        reconstruct_dataset(read_dataset(tmp_path / "ds"))
