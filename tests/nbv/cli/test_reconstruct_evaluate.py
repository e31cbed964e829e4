"""`nbv reconstruct` and `nbv evaluate` end to end on a tiny ray-cast dataset."""

from __future__ import annotations

import json
import shutil

import numpy as np
import pytest
import trimesh

from nbv.cli import main
from render.camera import UAVCamera
from render.dataset import DatasetWriter
from render.raycast import DepthRaycaster
from render.scan import HemispherePlan, hemisphere_scan
from render.viewpoint import viewpoint_to_c2w
from scenes import load_scene

CAMERA = UAVCamera(160, 120)
KEYS = {"chamfer_cm", "hausdorff_cm", "coverage", "fscore", "precision", "recall", "threshold_cm", "n_points"}


@pytest.fixture(scope="module")
def dataset(tmp_path_factory):
    """A renderer-free dataset: exact depth of the test building, a flat colour."""
    scene = load_scene("test_building")
    caster = DepthRaycaster([trimesh.Trimesh(p.vertices, p.faces) for p in scene.parts],
                            CAMERA.K, CAMERA.width, CAMERA.height)
    rgb = np.full((CAMERA.height, CAMERA.width, 3), 180, np.uint8)
    out = tmp_path_factory.mktemp("cli") / "scan"
    views = hemisphere_scan(CAMERA, HemispherePlan(end_overlap=0.5, side_overlap=0.5))
    with DatasetWriter(out, CAMERA, {"scene": scene.name, "center": scene.center().tolist()}) as writer:
        for view in views:
            c2w = viewpoint_to_c2w(view, scene.center())
            writer.add(rgb, caster.depth(c2w), c2w, view)
    return out


def test_reconstruct_then_evaluate(dataset, tmp_path, capsys) -> None:
    recon = tmp_path / "recon"
    assert main(["reconstruct", str(dataset), "--out", str(recon)]) == 0
    mesh = trimesh.load(recon / "mesh.ply", process=False)
    assert len(mesh.faces) > 1000
    assert len(trimesh.load(recon / "points.ply").vertices) > 1000
    summary = json.loads((recon / "reconstruction.json").read_text())
    assert summary["views"] == 37 and summary["config"]["recon"]["voxel_size_m"] == 0.004

    ev = tmp_path / "eval"
    assert main(["evaluate", str(recon / "mesh.ply"), "--gt", "test_building", "--reference",
                 str(recon / "mesh.ply"), "--out", str(ev), "--metric-points", "50000"]) == 0
    doc = json.loads((ev / "metrics.json").read_text())
    assert set(doc["gt"]) == KEYS and set(doc["reference"]) == KEYS
    assert doc["reference"]["chamfer_cm"] == 0.0 and doc["reference"]["coverage"] == 1.0
    assert doc["gt"]["coverage"] > 0.95 and doc["gt"]["chamfer_cm"] < 0.5
    assert doc["gt"]["n_points"] == 50000 and doc["gt"]["threshold_cm"] == 1.0
    assert doc["run"]["heatmap_against"] == "reference"
    assert (ev / "heatmap.png").stat().st_size > 10_000 and (ev / "heatmap.ply").is_file()
    assert "chamfer cm" in capsys.readouterr().out

    # The ground truth exported to a file gives the same figures as the scene name.
    gt_file = tmp_path / "gt.ply"
    load_scene("test_building").target_mesh().export(gt_file)
    assert main(["evaluate", str(recon / "mesh.ply"), "--gt", str(gt_file), "--out", str(tmp_path / "ev2"),
                 "--metric-points", "50000", "--threshold-cm", "0.5"]) == 0
    doc2 = json.loads((tmp_path / "ev2" / "metrics.json").read_text())
    assert set(doc2) == {"gt", "run", "commit", "command", "config"} and doc2["gt"]["threshold_cm"] == 0.5
    assert doc2["gt"]["chamfer_cm"] == pytest.approx(doc["gt"]["chamfer_cm"], rel=1e-6)

    # Nothing written is lost: a second run into the same folders refuses without --overwrite.
    assert main(["reconstruct", str(dataset), "--out", str(recon)]) == 2
    assert "use --overwrite" in capsys.readouterr().err


def test_evaluate_bad_input_names_the_problem(tmp_path, capsys) -> None:
    mesh = tmp_path / "m.ply"
    trimesh.creation.box().export(mesh)
    empty = tmp_path / "empty.ply"
    empty.write_text("ply\nformat ascii 1.0\nelement vertex 0\nproperty float x\nproperty float y\n"
                     "property float z\nend_header\n")
    cases = [
        (["evaluate", str(mesh), "--out", str(tmp_path / "a")], "give --reference, --gt or both"),
        (["evaluate", str(empty), "--gt", str(mesh), "--out", str(tmp_path / "b")], "empty.ply"),
        (["evaluate", str(mesh), "--gt", "no_such_scene", "--out", str(tmp_path / "c")], "no_such_scene"),
        (["evaluate", str(tmp_path / "missing.ply"), "--gt", str(mesh), "--out", str(tmp_path / "d")],
         "missing.ply"),
    ]
    for argv, message in cases:
        assert main(argv) == 2
        assert message in capsys.readouterr().err


def test_a_y_up_ground_truth_gives_the_metrics_of_its_z_up_twin(tmp_path, capsys) -> None:
    box = trimesh.creation.box((0.6, 0.4, 1.0))
    box.apply_translation([0.1, 0.0, 0.5])  # z up, standing on z = 0
    box.export(tmp_path / "zup.obj")
    x, y, z = box.vertices.T
    trimesh.Trimesh(np.stack([x, z, -y], axis=1), box.faces).export(tmp_path / "yup.obj")  # the same, y up
    box.apply_scale(1.02)
    box.export(tmp_path / "mesh.ply")
    docs = {}
    for name, extra in (("zup", []), ("yup", ["--up-axis", "y"]), ("yup_as_z", [])):
        gt = tmp_path / f"{name.removesuffix('_as_z')}.obj"
        assert main(["evaluate", str(tmp_path / "mesh.ply"), "--gt", str(gt), *extra, "--out",
                     str(tmp_path / name), "--metric-points", "20000", "--seed", "4"]) == 0
        docs[name] = json.loads((tmp_path / name / "metrics.json").read_text())
    assert docs["yup"]["gt"] == docs["zup"]["gt"] and docs["zup"]["gt"]["chamfer_cm"] > 0.1
    assert docs["yup"]["run"]["up_axis"] == "y" and docs["yup"]["run"]["metrics"]["seed"] == 4
    assert docs["yup_as_z"]["gt"]["chamfer_cm"] > 10 * docs["zup"]["gt"]["chamfer_cm"]  # the flag matters


def test_reconstruct_rejects_a_dataset_with_a_nan_pose(dataset, tmp_path, capsys) -> None:
    broken = tmp_path / "broken"
    broken.mkdir()
    for sub in ("images", "depth"):  # copies: the reader refuses links that leave the dataset folder
        shutil.copytree(dataset / sub, broken / sub)
    doc = json.loads((dataset / "transforms.json").read_text())
    doc["frames"][3]["transform_matrix"][0][3] = float("nan")
    (broken / "transforms.json").write_text(json.dumps(doc))
    assert main(["reconstruct", str(broken), "--out", str(tmp_path / "r")]) == 2
    err = capsys.readouterr().err
    assert "frames[3].transform_matrix" in err and "NaN" in err
