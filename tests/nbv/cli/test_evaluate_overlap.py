"""`nbv evaluate` refuses surfaces that cannot be one object (issue 27): a raw scene file given where the
normalised target was meant is a named error, not a Chamfer of metres; normalised, it evaluates."""

from __future__ import annotations

import json

import numpy as np
import trimesh

from nbv.cli import main

POINTS = ["--metric-points", "2000"]


def write_raw_y_up_building(folder):
    """A 22 m tall building modelled Y up, off the origin, as a user's scene file is."""
    box = trimesh.creation.box((8.0, 22.0, 6.0))
    box.apply_translation([30.0, 11.0, -12.0])
    path = folder / "building.obj"
    box.export(path)
    return path


def test_a_raw_y_up_scene_file_as_gt_is_refused_and_normalised_it_evaluates(tmp_path, capsys):
    raw = write_raw_y_up_building(tmp_path)
    normalised = trimesh.creation.box((8.0 / 22.0, 6.0 / 22.0, 1.0))  # by hand: z up, base on z = 0, 1 m
    normalised.apply_translation([0.0, 0.0, 0.5])
    normalised.export(tmp_path / "normalised.ply")
    recon = normalised.copy()
    recon.apply_scale(1.01)
    recon.export(tmp_path / "mesh.ply")

    assert main(["evaluate", str(tmp_path / "mesh.ply"), "--gt", str(raw), "--up-axis", "y",
                 "--out", str(tmp_path / "raw"), *POINTS]) == 2
    err = capsys.readouterr().err
    assert f"--gt {raw} spans 22 m" in err and "sizes 21.8x apart" in err
    assert "--normalise-gt" in err and "nbv scene export" in err and len(err.strip().splitlines()) == 1
    assert not (tmp_path / "raw" / "metrics.json").exists()

    docs = {}
    for name, gt in (("flag", [str(raw), "--up-axis", "y", "--normalise-gt"]),
                     ("by_hand", [str(tmp_path / "normalised.ply")])):
        assert main(["evaluate", str(tmp_path / "mesh.ply"), "--gt", *gt, "--out", str(tmp_path / name),
                     *POINTS]) == 0
        docs[name] = json.loads((tmp_path / name / "metrics.json").read_text())["gt"]
    for doc in docs.values():  # 1 % larger than the truth: about 0.5 cm, plus the sampling's spacing
        assert doc["chamfer_cm"] < 2.0 and doc["coverage"] > 0.3

    recon.apply_translation([3.0, 0.0, 0.0])  # normalised, but another place: not the flag's fault
    recon.export(tmp_path / "moved.ply")
    assert main(["evaluate", str(tmp_path / "moved.ply"), "--gt", str(raw), "--up-axis", "y",
                 "--normalise-gt", "--out", str(tmp_path / "moved"), *POINTS]) == 2
    err = capsys.readouterr().err
    assert "bounding boxes do not overlap" in err and "The ground truth is normalised" in err


def test_disjoint_bounds_are_refused_for_gt_and_reference(tmp_path, capsys):
    box = trimesh.creation.box((0.6, 0.4, 1.0))
    box.export(tmp_path / "mesh.ply")
    moved = box.copy()
    moved.apply_translation([2.0, 0.0, 0.0])  # the same size, beside it
    moved.export(tmp_path / "moved.ply")
    for flag in ("--gt", "--reference"):
        assert main(["evaluate", str(tmp_path / "mesh.ply"), flag, str(tmp_path / "moved.ply"),
                     "--out", str(tmp_path / flag.strip("-")), *POINTS]) == 2
        err = capsys.readouterr().err
        assert f"{flag} {tmp_path / 'moved.ply'} spans 1 m" in err and "bounding boxes do not overlap" in err


def test_half_size_overlapping_surfaces_still_evaluate(tmp_path):
    box = trimesh.creation.box((1.0, 1.0, 1.0))
    box.export(tmp_path / "gt.ply")
    part = trimesh.creation.box((0.25, 0.25, 0.25))
    part.apply_translation(np.array([0.4, 0.4, 0.4]))
    part.export(tmp_path / "mesh.ply")  # a fragment 4x smaller, inside the bounds: a poor reconstruction
    assert main(["evaluate", str(tmp_path / "mesh.ply"), "--gt", str(tmp_path / "gt.ply"),
                 "--out", str(tmp_path / "ev"), *POINTS]) == 0
    assert json.loads((tmp_path / "ev" / "metrics.json").read_text())["gt"]["coverage"] < 0.3
