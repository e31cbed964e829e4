"""`nbv export`: writes a COLMAP model; bad input exits 2 naming the fault and leaves nothing behind."""

from __future__ import annotations

import os
import shutil

import pycolmap
import pytest

from nbv.cli import main


@pytest.fixture(scope="module")
def scan(tmp_path_factory):
    """A 4-view circle scan of test_building at 64x48, 1 spp, made with `nbv scan`."""
    out = tmp_path_factory.mktemp("export_cli") / "ds"
    assert main(["scan", "test_building", "circle", "--views", "4", "--width", "64",
                 "--height", "48", "--spp", "1", "--out", str(out)]) == 0
    return out


def test_export_writes_a_model_and_refuses_to_overwrite(scan, tmp_path, capsys):
    out = tmp_path / "colmap"
    assert main(["export", str(scan), "--format", "colmap", "--points-per-view", "50",
                 "--out", str(out)]) == 0
    model = pycolmap.Reconstruction(out / "sparse" / "0")
    assert model.num_images() == 4 and 0 < model.num_points3D() <= 200
    before = sorted(p.name for p in out.rglob("*"))
    assert main(["export", str(scan), "--out", str(out)]) == 2
    assert "--overwrite" in capsys.readouterr().err
    assert sorted(p.name for p in out.rglob("*")) == before
    assert main(["export", str(scan), "--no-points", "--overwrite", "--out", str(out)]) == 0
    assert pycolmap.Reconstruction(out / "sparse" / "0").num_points3D() == 0
    assert [p.name for p in tmp_path.iterdir()] == ["colmap"]  # no temporary folder left


def test_dataset_without_depth_is_refused(scan, tmp_path, capsys):
    broken = tmp_path / "ds"
    shutil.copytree(scan, broken)
    shutil.rmtree(broken / "depth")
    assert main(["export", str(broken), "--out", str(tmp_path / "colmap")]) == 2
    err = capsys.readouterr().err
    assert "depth_file_path" in err and "depth/0000.png" in err
    assert not (tmp_path / "colmap").exists()


def test_output_under_a_file_is_refused(scan, tmp_path, capsys):
    blocker = tmp_path / "a_file"
    blocker.write_text("not a folder")
    assert main(["export", str(scan), "--out", str(blocker / "colmap")]) == 2
    assert f"{blocker} is a file" in capsys.readouterr().err


@pytest.mark.skipif(os.geteuid() == 0, reason="root can write into a read-only folder")
def test_read_only_folder_is_refused(scan, tmp_path, capsys):
    locked = tmp_path / "locked"
    locked.mkdir(mode=0o500)
    assert main(["export", str(scan), "--out", str(locked / "colmap")]) == 2
    assert "not writable" in capsys.readouterr().err


def test_output_onto_the_dataset_is_refused(scan, capsys):
    assert main(["export", str(scan), "--overwrite", "--out", str(scan.parent)]) == 2
    assert "would replace the dataset" in capsys.readouterr().err
    assert (scan / "transforms.json").is_file()


def test_missing_dataset_is_refused(tmp_path, capsys):
    assert main(["export", str(tmp_path / "nothing"), "--out", str(tmp_path / "colmap")]) == 2
    assert "transforms.json" in capsys.readouterr().err
