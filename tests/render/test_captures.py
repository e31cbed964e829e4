"""Captures from other tools: COLMAP (text, binary) and nerfstudio read in any similarity frame, the target
frame estimated, images undistorted, the kept subset written back and read by pycolmap / as JSON."""

from __future__ import annotations

import json
import math
from pathlib import Path

import cv2
import numpy as np
import pycolmap
import pytest
from foreign_captures import moved, similarity, write_colmap, write_nerfstudio
from PIL import Image
from synthetic import write_circle_dataset

from nbv.cli import main
from render.camera import UAVCamera
from render.captures.colmap_capture import intrinsics
from render.captures.colmap_model import Camera
from render.captures.dataset import CaptureDataset
from render.captures.frame import CaptureFrameConfig, local_viewpoint, target_frame
from render.captures.open import read_views, write_kept
from render.dataset import DatasetError, read_dataset
from render.scan import hemisphere_scan
from render.viewpoint import viewpoint_to_c2w

CENTER = np.array([0.0, 0.0, 0.5])
"""write_circle_dataset's centre."""
DISTORTION = (0.05, -0.02, 0.001, 0.0)
"""Small OpenCV k1, k2, p1, p2."""


@pytest.fixture(scope="module")
def native(tmp_path_factory):
    """Eight textured views on a circle at 96x72 (no renderer)."""
    return read_dataset(write_circle_dataset(tmp_path_factory.mktemp("native") / "ds", list(range(8))))


@pytest.fixture(scope="module")
def captures(native, tmp_path_factory):
    """The native views as COLMAP text, COLMAP binary and nerfstudio JPEG, in one random similarity frame."""
    root, sim = tmp_path_factory.mktemp("captures"), similarity(1)
    return sim, {"text": write_colmap(native, root / "text", "text", sim),
                 "binary": write_colmap(native, root / "binary", "binary", sim),
                 "nerfstudio": write_nerfstudio(native, root / "ns", sim, crop=(3, 2, 0, 0))}


@pytest.mark.parametrize("kind", ["text", "binary", "nerfstudio"])
def test_frame_estimated_and_viewpoints_match_the_native_scan(native, captures, kind):
    (rot, t, s), paths = captures
    capture = read_views(paths[kind])
    assert isinstance(capture, CaptureDataset) and capture.kind == ("nerfstudio" if kind == "nerfstudio"
                                                                    else "colmap")
    np.testing.assert_allclose(capture.target.center, s * rot @ CENTER + t, atol=1e-8)
    np.testing.assert_allclose(capture.target.up, rot @ [0.0, 0.0, 1.0], atol=1e-8)
    assert [f.rgb_path.name for f in capture.frames][:2] in (["0000.png", "0001.png"],
                                                             ["frame_00001.jpg", "frame_00002.jpg"])
    for mine, theirs in zip(capture.frames, native.frames):  # azimuth 0 is the first frame's (here 0)
        assert mine.viewpoint.azimuth == pytest.approx(theirs.viewpoint.azimuth, abs=2e-9)
        assert mine.viewpoint.elevation == pytest.approx(theirs.viewpoint.elevation, abs=1e-9)
        assert mine.viewpoint.radius == pytest.approx(1.0)  # median camera distance is the unit
    assert capture.rgb(0).shape == (capture.camera.height, capture.camera.width, 3)


def test_azimuths_do_not_depend_on_the_gauge(native, tmp_path):
    """Two similarity frames and a first frame off azimuth 0: the same azimuths, relative to frame 0."""
    shifted = read_dataset(write_circle_dataset(tmp_path / "ds", [3, 4, 5, 6, 7, 0, 1, 2]))
    a = read_views(write_nerfstudio(shifted, tmp_path / "a", similarity(2)))
    b = read_views(write_nerfstudio(shifted, tmp_path / "b", similarity(3)))
    azimuths = [f.viewpoint.azimuth for f in a.frames]
    assert azimuths == [f.viewpoint.azimuth for f in b.frames]
    np.testing.assert_allclose(azimuths, [2 * math.pi * i / 8 for i in range(8)], atol=2e-9)


def test_given_centre_and_up_are_used_and_recorded(native, captures):
    (rot, t, s), paths = captures
    center = s * rot @ (CENTER + [0.0, 0.0, 0.3]) + t
    config = CaptureFrameConfig(capture_center=tuple(center), capture_up=tuple(rot @ [0.0, 0.0, 2.0]))
    capture = read_views(paths["binary"], config)
    record = capture.meta["capture"]
    assert record["center"] == pytest.approx(center.tolist()) and not record["center_estimated"]
    assert not record["up_estimated"] and record["axis_miss"] > 0.05  # the axes pass 0.3 m below it
    assert capture.frames[0].viewpoint.elevation < native.frames[0].viewpoint.elevation


def test_undistorting_the_images_recovers_the_pinhole_views(native, tmp_path):
    """Distortion is undone on the images: a distorted capture reads back as the pinhole views."""
    sim, strong = similarity(4), (0.2, 0.05, 0.002, -0.002)
    plain = read_views(write_nerfstudio(native, tmp_path / "plain", sim))
    lens = read_views(write_nerfstudio(native, tmp_path / "lens", sim, coeffs=strong))
    assert lens.frames[0].meta["undistort"] and "undistort" not in plain.frames[0].meta  # keys the cache
    inner, truth = np.s_[6:-6, 6:-6], native.rgb(0).astype(np.float64)
    jpeg = np.abs(plain.rgb(0) - truth)[inner].mean()
    before = np.abs(np.asarray(Image.open(lens.frames[0].rgb_path), np.float64) - truth)[inner].mean()
    after = np.abs(lens.rgb(0) - truth)[inner].mean()
    assert jpeg < after < 0.3 * before, (jpeg, before, after)  # measured: 0.64 < 1.63 < 0.3 * 7.40


def test_per_frame_intrinsics_read_as_shared_ones(native, tmp_path):
    sim = similarity(5)
    shared = read_views(write_nerfstudio(native, tmp_path / "shared", sim, DISTORTION, (2, 1, 1, 0)))
    per_frame = read_views(write_nerfstudio(native, tmp_path / "per", sim, DISTORTION, (2, 1, 1, 0), True))
    assert shared.intrinsics == per_frame.intrinsics and shared.intrinsics[0].cx == pytest.approx(
        native.camera.K[0, 2] - 2)
    np.testing.assert_array_equal(shared.rgb(3), per_frame.rgb(3))


@pytest.mark.parametrize("kind", ["text", "binary"])
def test_kept_colmap_subset_reads_back_in_pycolmap(captures, kind, tmp_path):
    capture = read_views(captures[1][kind])
    kept = [0, 2, 5, 7]
    write_kept(capture, kept, tmp_path / "out", {}, extra={"refine.json": {"kept": kept}})
    source, model = pycolmap.Reconstruction(), pycolmap.Reconstruction()
    getattr(source, f"read_{kind}")(captures[1][kind] / "sparse" / "0")
    getattr(model, f"read_{kind}")(tmp_path / "out" / "sparse" / "0")
    names = [capture.frames[i].rgb_path.name for i in kept]
    assert model.num_images() == len(kept) and sorted(im.name for im in model.images.values()) == names
    ids = {capture.keys[i] for i in kept}
    for image_id, image in model.images.items():
        assert image_id in ids and (tmp_path / "out" / "images" / image.name).is_file()
        np.testing.assert_allclose(image.cam_from_world().matrix(),
                                   source.images[image_id].cam_from_world().matrix(), atol=1e-12)
    expected = {pid for pid, p in source.points3D.items() if any(e.image_id in ids for e in p.track.elements)}
    assert set(model.points3D) == expected
    assert all(e.image_id in ids for p in model.points3D.values() for e in p.track.elements)
    assert json.loads((tmp_path / "out" / "refine.json").read_text()) == {"kept": kept}


def test_kept_nerfstudio_subset_keeps_the_document(captures, tmp_path):
    path = captures[1]["nerfstudio"]
    capture = read_views(path)
    write_kept(capture, [1, 4], tmp_path / "out", {})
    doc, source = (json.loads((p / "transforms.json").read_text()) for p in (tmp_path / "out", path))
    assert doc["frames"] == [source["frames"][1], source["frames"][4]]
    assert {**doc, "frames": None} == {**source, "frames": None}
    assert all((tmp_path / "out" / f["file_path"]).read_bytes() == (path / f["file_path"]).read_bytes()
               for f in doc["frames"])
    again = read_views(tmp_path / "out")  # still a capture: no `nbv` block was added
    assert isinstance(again, CaptureDataset) and len(again) == 2


def test_forward_facing_capture_asks_for_the_centre(native, tmp_path):
    sim = similarity(6)
    doc_root = write_nerfstudio(native, tmp_path / "ns", sim)
    doc = json.loads((doc_root / "transforms.json").read_text())
    pose = doc["frames"][0]["transform_matrix"]
    for i, frame in enumerate(doc["frames"]):  # every camera looks the same way, side by side
        frame["transform_matrix"] = [row[:3] + [row[3] + 0.1 * i] for row in pose[:3]] + [pose[3]]
    (doc_root / "transforms.json").write_text(json.dumps(doc))
    with pytest.raises(DatasetError, match="optical axes are nearly parallel.*--capture-center"):
        read_views(doc_root)
    center = moved(native.frames[0].c2w, sim)[:3, 3] + 5 * moved(native.frames[0].c2w, sim)[:3, 2]
    assert len(read_views(doc_root, CaptureFrameConfig(capture_center=tuple(center)))) == 8


@pytest.mark.parametrize("command", ["reconstruct", "evaluate"])
def test_reconstruct_and_evaluate_say_a_capture_has_no_depth(captures, command, tmp_path, capsys):
    path = captures[1]["text" if command == "reconstruct" else "nerfstudio"]
    args = [str(path), "--out", str(tmp_path / "out")] + (["--gt", "test_building"] if command == "evaluate"
                                                         else [])
    assert main([command, *args]) == 2
    err = capsys.readouterr().err
    assert "has no depth maps, and this command needs depth" in err and "Traceback" not in err
    assert not (tmp_path / "out").exists()


def test_hemisphere_frame_is_exact_to_the_top_view():
    """The 288 poses of the full scan in a similarity frame: the up axis from the level x axes is exact
    (the mean up vector tilts by the top view's), and every azimuth, the top view's included, matches."""
    views = hemisphere_scan(UAVCamera())
    sim = similarity(9)
    c2ws = np.stack([moved(viewpoint_to_c2w(v, CENTER), sim) for v in views])
    target = target_frame(c2ws, CaptureFrameConfig(), Path("scan"))
    np.testing.assert_allclose(target.up, sim[0] @ [0.0, 0.0, 1.0], atol=1e-12)
    mean_up = -c2ws[:, :3, 1].mean(0)
    assert np.degrees(np.arccos(mean_up @ target.up / np.linalg.norm(mean_up))) > 0.2
    assert views[-1].elevation == pytest.approx(math.pi / 2)
    for view, c2w in zip(views, c2ws):
        mine = local_viewpoint(target.to_local(c2w))
        assert abs((mine.azimuth - view.azimuth + math.pi) % (2 * math.pi) - math.pi) < 2e-9
        assert mine.elevation == pytest.approx(view.elevation, abs=1e-9)


@pytest.mark.parametrize(("model", "params"), [
    ("SIMPLE_RADIAL", [90.0, 40.0, 30.0, 0.08]), ("RADIAL", [90.0, 40.0, 30.0, 0.08, -0.03]),
    ("OPENCV", [90.0, 95.0, 40.0, 30.0, 0.08, -0.03, 0.002, -0.001]),
    ("FULL_OPENCV", [90.0, 95.0, 40.0, 30.0, 0.08, -0.03, 0.002, -0.001, 0.01, 0.02, -0.01, 0.005])])
def test_colmap_camera_models_map_to_opencv_as_colmap_projects(model, params):
    """A point COLMAP's own camera model projects lands where OpenCV projects it with our intrinsics."""
    camera = Camera(1, model, 80, 60, tuple(params))
    intr = intrinsics(camera, Path("cameras.txt"))
    rays = np.array([[0.1, -0.2, 1.0], [-0.3, 0.25, 1.0], [0.0, 0.0, 1.0]])
    theirs = pycolmap.Camera(model=model, width=80, height=60, params=params).img_from_cam(rays)
    ours = cv2.projectPoints(rays, np.zeros(3), np.zeros(3), intr.K, np.array(intr.distortion))[0][:, 0]
    np.testing.assert_allclose(ours + 0.5, theirs, atol=1e-9)  # COLMAP's pixel centres sit at +0.5
