"""The renderer against geometry: plane depth, point projection, variants, kernel reuse."""

import numpy as np
import pytest

from render.camera import UAVCamera
from render.renderer import MitsubaRenderer
from render.settings import RenderSettings
from render.viewpoint import Viewpoint, viewpoint_to_c2w
from scenes import load_scene
from scenes.model import Lighting, Material, Part, Scene


def quad(name, center, half, color, z=0.0, target=True):
    cx, cy = center
    verts = np.array([[cx - half, cy - half, z], [cx + half, cy - half, z],
                      [cx + half, cy + half, z], [cx - half, cy + half, z]], float)
    return Part(name, verts, np.array([[0, 1, 2], [0, 2, 3]]), Material(name, color=color), target=target)


def marker_scene():
    """A grey 4 m floor with a small red square at a known, off-centre spot."""
    return Scene("markers", (quad("floor", (0, 0), 2.0, (0.5, 0.5, 0.5)),
                             quad("red", (0.35, -0.2), 0.03, (1.0, 0.0, 0.0), z=1e-3)),
                 Lighting(sun_elevation_deg=90.0))


def test_depth_of_a_fronto_parallel_plane_is_exact(variant):
    cam = UAVCamera(80, 60, 35.0)
    renderer = MitsubaRenderer(marker_scene(), cam, RenderSettings(spp=1, variant=variant))
    c2w = viewpoint_to_c2w(Viewpoint(1.5, 0.7, np.pi / 2), np.zeros(3))
    depth = renderer.render_depth(c2w)
    # z-depth, not ray length: constant over the whole image (the marker sits 1 mm up).
    floor = np.abs(depth - 1.5) < 0.0005
    assert floor.mean() > 0.95
    assert np.abs(depth[~floor] - 1.499).max() < 1e-3


def test_a_known_point_projects_where_it_is_rendered(variant):
    cam = UAVCamera(160, 120, 35.0)
    renderer = MitsubaRenderer(marker_scene(), cam, RenderSettings(spp=4, max_depth=2, variant=variant))
    c2w = viewpoint_to_c2w(Viewpoint(1.2, 2.2, 1.1), np.zeros(3))
    rgb = renderer.render_rgb(c2w).astype(int)
    red = (rgb[..., 0] > 120) & (rgb[..., 1] < 60)
    assert red.sum() > 4
    rows, cols = np.nonzero(red)
    seen = np.array([cols.mean(), rows.mean()])
    point = np.array([0.35, -0.2, 1e-3, 1.0])
    cam_pt = (np.linalg.inv(c2w) @ point)[:3]
    expected = (cam.K @ cam_pt)[:2] / cam_pt[2]
    assert np.linalg.norm(seen - expected) < 1.0


def test_scalar_and_llvm_depth_agree():
    pytest.importorskip("mitsuba")
    from render.variant import available_variants
    if "llvm_ad_rgb" not in available_variants():
        pytest.skip("llvm_ad_rgb unavailable")
    scene, cam = load_scene("test_building"), UAVCamera(96, 72)
    c2w = viewpoint_to_c2w(Viewpoint(2.0, 0.9, 0.4), scene.center())
    depths = [MitsubaRenderer(scene, cam, RenderSettings(variant=v)).render_depth(c2w)
              for v in ("scalar_rgb", "llvm_ad_rgb")]
    both = (depths[0] > 0) & (depths[1] > 0)
    assert both.mean() > 0.5
    assert np.median(np.abs(depths[0][both] - depths[1][both])) <= 1e-3


def test_a_new_pose_compiles_no_new_kernel_in_llvm():
    from render.variant import available_variants
    if "llvm_ad_rgb" not in available_variants():
        pytest.skip("llvm_ad_rgb unavailable")
    import drjit as dr
    scene = load_scene("test_building")
    renderer = MitsubaRenderer(scene, UAVCamera(64, 48), RenderSettings(spp=2, variant="llvm_ad_rgb"))
    renderer.render(viewpoint_to_c2w(Viewpoint(2.0, 0.1, 0.3), renderer.center))
    dr.set_flag(dr.JitFlag.KernelHistory, True)
    try:
        dr.kernel_history()  # clears the history
        renderer.render(viewpoint_to_c2w(Viewpoint(2.3, 2.5, 0.9), renderer.center), seed=7)
        kernels = [k for k in dr.kernel_history() if k["type"] == dr.KernelType.JIT]
    finally:
        dr.set_flag(dr.JitFlag.KernelHistory, False)
    assert kernels, "no kernel ran"
    assert all(k["cache_hit"] for k in kernels), kernels


def test_same_seed_same_image_and_views_are_photoreal():
    scene = load_scene("test_building")
    renderer = MitsubaRenderer(scene, UAVCamera(64, 48), RenderSettings(spp=4))
    c2w = viewpoint_to_c2w(Viewpoint(2.0, 1.0, 0.4), renderer.center)
    a, b = renderer.render_rgb(c2w, seed=3), renderer.render_rgb(c2w, seed=3)
    np.testing.assert_array_equal(a, b)
    assert a.dtype == np.uint8 and a.shape == (48, 64, 3)
    assert 40 < a.mean() < 220 and a.std() > 10


def test_nan_pose_and_bad_settings_are_rejected():
    renderer = MitsubaRenderer(marker_scene(), UAVCamera(16, 12))
    pose = np.eye(4)
    pose[2, 3] = np.nan
    with pytest.raises(ValueError, match="NaN"):
        renderer.render(pose)
    with pytest.raises(ValueError, match="spp"):
        RenderSettings(spp=0)
