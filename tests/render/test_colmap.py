"""COLMAP export: pycolmap reads text and binary alike; poses, intrinsics and points match the dataset."""

from __future__ import annotations

import json
from dataclasses import replace

import numpy as np
import open3d as o3d
import pycolmap
import pytest

from render.camera import UAVCamera
from render.capture import capture_dataset
from render.colmap import ExportConfig, build_model, export_dataset, world_to_camera
from render.dataset import read_dataset
from render.scan import CirclePlan, circle_scan
from render.settings import RenderSettings
from render.viewpoint import opencv_to_opengl
from scenes import load_scene

FORMATS = ("text", "binary")


@pytest.fixture(scope="module")
def scan(tmp_path_factory):
    """A 4-view circle scan of test_building at 64x48, 1 spp."""
    out = tmp_path_factory.mktemp("colmap") / "ds"
    camera = UAVCamera(64, 48)
    capture_dataset(load_scene("test_building"), camera, circle_scan(camera, CirclePlan(views=4)), out,
                    RenderSettings(spp=1), progress=False)
    return out


def read_model(folder, kind: str) -> pycolmap.Reconstruction:
    model = pycolmap.Reconstruction()
    getattr(model, f"read_{kind}")(folder / "sparse" / "0")
    return model


@pytest.fixture(scope="module")
def exported(scan, tmp_path_factory):
    out = tmp_path_factory.mktemp("export") / "colmap"
    assert export_dataset(ExportConfig(dataset=scan, out=out, points_per_view=300)) == out
    return out


@pytest.mark.parametrize("kind", FORMATS)
def test_cameras_and_intrinsics_match_transforms_json(scan, exported, kind):
    doc = json.loads((scan / "transforms.json").read_text())
    model = read_model(exported, kind)
    assert model.num_cameras() == 1 and model.num_images() == len(doc["frames"]) == 4
    camera = model.cameras[1]
    assert camera.model.name == "PINHOLE" and (camera.width, camera.height) == (doc["w"], doc["h"])
    assert camera.params.tolist() == [doc["fl_x"], doc["fl_y"], doc["cx"], doc["cy"]]
    for image_id, frame in enumerate(doc["frames"], start=1):
        image = model.images[image_id]
        c2w = opencv_to_opengl(np.array(frame["transform_matrix"]))
        assert image.name == frame["file_path"].removeprefix("images/")
        np.testing.assert_allclose(image.projection_center(), c2w[:3, 3], atol=1e-6)
        np.testing.assert_allclose(image.cam_from_world().rotation.matrix(), c2w[:3, :3].T, atol=1e-6)
        assert (exported / "images" / image.name).resolve() == (scan / frame["file_path"]).resolve()


@pytest.mark.parametrize("kind", FORMATS)
def test_points_lie_on_the_scene_and_reproject_to_their_pixels(exported, kind):
    model = read_model(exported, kind)
    assert 0 < model.num_points3D() <= 4 * 300
    xyz = np.array([p.xyz for p in model.points3D.values()])
    raycast = o3d.t.geometry.RaycastingScene()
    for part in load_scene("test_building").parts:
        raycast.add_triangles(o3d.core.Tensor(part.vertices.astype(np.float32)),
                              o3d.core.Tensor(part.faces.astype(np.uint32)))
    distance = raycast.compute_distance(o3d.core.Tensor(xyz.astype(np.float32))).numpy()
    assert distance.max() < 2e-3  # depth is stored in whole millimetres
    camera = model.cameras[1]
    for point_id, point in list(model.points3D.items())[::50]:
        (element,) = point.track.elements
        image = model.images[element.image_id]
        observed = image.points2D[element.point2D_idx]
        assert observed.point3D_id == point_id
        np.testing.assert_allclose(camera.img_from_cam(image.cam_from_world() * point.xyz), observed.xy,
                                   atol=1e-6)
    assert model.compute_mean_reprojection_error() < 1e-6


def test_text_and_binary_agree_and_the_seed_repeats(scan, exported, tmp_path):
    text, binary = read_model(exported, "text"), read_model(exported, "binary")
    ids = sorted(binary.points3D)
    assert sorted(text.points3D) == ids
    for i in ids[::97]:
        assert text.points3D[i].xyz.tolist() == binary.points3D[i].xyz.tolist()
        assert text.points3D[i].color.tolist() == binary.points3D[i].color.tolist()
    export_dataset(ExportConfig(dataset=scan, out=tmp_path / "again", points_per_view=300))
    for name in ("images.bin", "points3D.bin", "points3D.txt"):
        again = (tmp_path / "again/sparse/0" / name).read_bytes()
        assert again == (exported / "sparse/0" / name).read_bytes()


def test_copied_images_and_no_points(scan, tmp_path):
    out = export_dataset(ExportConfig(dataset=scan, out=tmp_path / "c", images="copy", points=False))
    image = out / "images" / "0000.png"
    assert not image.is_symlink() and image.read_bytes() == (scan / "images/0000.png").read_bytes()
    for kind in FORMATS:
        model = read_model(out, kind)
        assert model.num_points3D() == 0 and model.num_images() == 4
    assert (out / "sparse/0/points3D.txt").is_file() and (out / "sparse/0/points3D.bin").stat().st_size == 8


def test_world_to_camera_is_colmaps_convention():
    c2w = np.eye(4)
    c2w[:3, 3] = [1.0, 2.0, 3.0]
    q, t = world_to_camera(c2w)
    assert q.tolist() == [1.0, 0.0, 0.0, 0.0] and t.tolist() == [-1.0, -2.0, -3.0]


@pytest.mark.parametrize("name", ["00\n02.png", "00 02.png", "00\t02.png"])
def test_image_name_with_newline_or_space_refused_by_colmap_export(scan, tmp_path, name):
    """A name the reader would refuse (a newline) or COLMAP's text format cannot hold (a space) is refused
    before anything is written, whoever built the dataset."""
    dataset = read_dataset(scan)
    frame = dataset.frames[2]
    odd = tmp_path / name
    odd.write_bytes(frame.rgb_path.read_bytes())
    frames = (*dataset.frames[:2], replace(frame, rgb_path=odd), *dataset.frames[3:])
    with pytest.raises(ValueError, match="COLMAP's images.txt cannot hold the image name"):
        build_model(replace(dataset, frames=frames), 0, 0)
