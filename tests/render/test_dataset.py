"""View datasets: round trip, back-projection onto the exported mesh, atomic writes, bad files."""

import json

import cv2
import numpy as np
import pytest
import trimesh
from PIL import Image

from nbv.cli import main
from render.camera import UAVCamera
from render.capture import capture_dataset
from render.dataset import DatasetError, DatasetWriter, read_dataset, write_subset
from render.renderer import MitsubaRenderer
from render.scan import CirclePlan, HemispherePlan, circle_scan, hemisphere_scan
from render.settings import RenderSettings
from render.viewpoint import Viewpoint, viewpoint_to_c2w
from scenes import load_scene


def small_dataset(path, views=3, size=(32, 24)):
    cam = UAVCamera(*size)
    rng = np.random.default_rng(0)
    with DatasetWriter(path, cam, {"scene": "synthetic", "center": [0, 0, 0.4]}) as w:
        for i in range(views):
            view = Viewpoint(2.0, i, 0.3)
            depth = rng.uniform(1.0, 3.0, (size[1], size[0])).astype(np.float32)
            w.add(rng.integers(0, 256, (size[1], size[0], 3), dtype=np.uint8), depth,
                  viewpoint_to_c2w(view, np.array([0, 0, 0.4])), view)
    return cam


def test_round_trip_keeps_images_poses_and_millimetre_depth(tmp_path):
    cam = small_dataset(tmp_path / "ds")
    ds = read_dataset(tmp_path / "ds")
    assert len(ds) == 3 and ds.camera == cam
    rng = np.random.default_rng(0)
    for i in range(3):
        view = Viewpoint(2.0, i, 0.3)
        depth = rng.uniform(1.0, 3.0, (24, 32)).astype(np.float32)
        np.testing.assert_array_equal(ds.rgb(i), rng.integers(0, 256, (24, 32, 3), dtype=np.uint8))
        assert np.abs(ds.depth(i) - depth).max() <= 0.0005 + 1e-6
        np.testing.assert_allclose(ds.frames[i].c2w, viewpoint_to_c2w(view, ds.center), atol=1e-12)
        np.testing.assert_allclose(ds.frames[i].viewpoint.as_array(), view.as_array(), atol=1e-12)


def test_transforms_json_follows_nerfstudio(tmp_path):
    cam = small_dataset(tmp_path / "ds", views=1)
    doc = json.loads((tmp_path / "ds" / "transforms.json").read_text())
    assert (doc["cx"], doc["cy"], doc["w"], doc["h"]) == (16.0, 12.0, 32, 24)
    assert doc["fl_x"] == pytest.approx(cam.fx) and doc["depth_unit_scale_factor"] == 0.001
    gl = np.array(doc["frames"][0]["transform_matrix"])
    cv = viewpoint_to_c2w(Viewpoint(2.0, 0.0, 0.3), np.array([0, 0, 0.4]))
    np.testing.assert_allclose(gl[:3, 1:3], -cv[:3, 1:3], atol=1e-12)  # OpenGL: y up, z backward
    depth = cv2.imread(str(tmp_path / "ds" / doc["frames"][0]["depth_file_path"]), cv2.IMREAD_UNCHANGED)
    assert depth.dtype == np.uint16


def backproject_from_files(root):
    """World points of every valid depth pixel, using only transforms.json and the depth PNGs."""
    doc = json.loads((root / "transforms.json").read_text())
    fx, fy, cx, cy = doc["fl_x"], doc["fl_y"], doc["cx"], doc["cy"]
    points = []
    for frame in doc["frames"]:
        raw = cv2.imread(str(root / frame["depth_file_path"]), cv2.IMREAD_UNCHANGED)
        depth = raw * doc["depth_unit_scale_factor"]
        v, u = np.nonzero(depth > 0)
        z = depth[v, u]
        # nerfstudio puts pixel centres at +0.5, and its camera is OpenGL (y up, z backward).
        cam = np.stack([(u + 0.5 - cx) / fx * z, -(v + 0.5 - cy) / fy * z, -z, np.ones_like(z)])
        points.append((np.array(frame["transform_matrix"]) @ cam)[:3].T)
    return np.concatenate(points)


def distance_to_mesh(mesh, points):
    """Exact unsigned point-to-triangle distance (Open3D's raycasting scene)."""
    import open3d as o3d

    rays = o3d.t.geometry.RaycastingScene()
    rays.add_triangles(o3d.core.Tensor(np.asarray(mesh.vertices, np.float32)),
                       o3d.core.Tensor(np.asarray(mesh.faces, np.uint32)))
    return rays.compute_distance(o3d.core.Tensor(points.astype(np.float32))).numpy()


def test_backprojected_depth_lands_on_the_exported_mesh(tmp_path, variant):
    scene = load_scene("test_building")
    cam = UAVCamera(96, 72)
    views = hemisphere_scan(cam, HemispherePlan(end_overlap=0.3, side_overlap=0.2))
    capture_dataset(scene, cam, views, tmp_path / "ds", RenderSettings(spp=1, variant=variant),
                    progress=False)
    assert main(["scene", "export", "test_building", "--out", str(tmp_path / "gt")]) == 0
    mesh = trimesh.load(tmp_path / "gt" / "mesh.ply", force="mesh")
    points = backproject_from_files(tmp_path / "ds")
    points = points[points[:, 2] > 0.003]  # the ground is not part of the target
    assert len(points) > 2000
    dist = distance_to_mesh(mesh, points)
    assert np.median(dist) <= 0.001
    assert np.percentile(dist, 95) <= 0.005


def test_interrupted_scan_leaves_nothing_behind(tmp_path, monkeypatch):
    scene = load_scene("test_building")
    calls = {"n": 0}
    real = MitsubaRenderer.render

    def flaky(self, c2w, seed=None):
        calls["n"] += 1
        if calls["n"] == 3:
            raise KeyboardInterrupt
        return real(self, c2w, seed)

    monkeypatch.setattr(MitsubaRenderer, "render", flaky)
    views = circle_scan(UAVCamera(), CirclePlan(views=5))
    (tmp_path / "ds").mkdir()
    (tmp_path / "ds" / "keep.txt").write_text("old")
    with pytest.raises(KeyboardInterrupt):
        capture_dataset(scene, UAVCamera(32, 24), views, tmp_path / "ds", RenderSettings(spp=1),
                        overwrite=True, progress=False)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["ds"]
    assert (tmp_path / "ds" / "keep.txt").read_text() == "old"


def test_existing_output_is_not_overwritten_without_consent(tmp_path):
    small_dataset(tmp_path / "ds")
    with pytest.raises(FileExistsError, match="--overwrite"):
        small_dataset(tmp_path / "ds")


def test_unwritable_output_folder_is_named(tmp_path):
    (tmp_path / "file").write_text("x")
    with pytest.raises(FileExistsError, match="file"):
        small_dataset(tmp_path / "file")
    with pytest.raises(FileNotFoundError, match="file/ds cannot be made: .* is a file, not a folder"):
        small_dataset(tmp_path / "file" / "ds")


@pytest.mark.parametrize("corrupt, message", [
    (lambda d: (d / "transforms.json").write_text("{not json"), "corrupt JSON"),
    (lambda d: (d / "transforms.json").unlink(), "not found"),
    (lambda d: _edit(d, lambda doc: doc.pop("w")), "field w is missing"),
    (lambda d: _edit(d, lambda doc: doc["frames"][1].pop("transform_matrix")),
     r"frames\[1\].transform_matrix"),
    (lambda d: _edit(d, lambda doc: doc["frames"][0]["transform_matrix"][0].__setitem__(3, float("nan"))),
     "NaN"),
    (lambda d: (d / "images" / "0002.png").unlink(), r"frames\[2\].file_path names a missing file"),
])
def test_corrupt_datasets_name_the_file_and_field(tmp_path, corrupt, message):
    small_dataset(tmp_path / "ds")
    corrupt(tmp_path / "ds")
    with pytest.raises(DatasetError, match=message):
        read_dataset(tmp_path / "ds")


def test_image_of_the_wrong_size_is_reported(tmp_path):
    small_dataset(tmp_path / "ds")
    Image.fromarray(np.zeros((10, 10, 3), np.uint8)).save(tmp_path / "ds" / "images" / "0001.png")
    with pytest.raises(DatasetError, match="0001.png: image is 10x10"):
        read_dataset(tmp_path / "ds").rgb(1)


def _edit(root, change):
    doc = json.loads((root / "transforms.json").read_text())
    change(doc)
    (root / "transforms.json").write_text(json.dumps(doc))


def test_subset_records_source_indices(tmp_path):
    small_dataset(tmp_path / "ds", views=4)
    ds = read_dataset(tmp_path / "ds")
    write_subset(ds, [3, 1], tmp_path / "sub", {"refined": True})
    sub = read_dataset(tmp_path / "sub")
    assert [f.meta["source_index"] for f in sub.frames] == [3, 1]
    np.testing.assert_array_equal(sub.rgb(0), ds.rgb(3))
    assert sub.meta["refined"] is True and sub.meta["scene"] == "synthetic"
