"""`nbv scene list / export / gallery`, run end to end."""

from __future__ import annotations

import numpy as np
import pytest
import trimesh
from PIL import Image

from nbv.cli import main
from scenes import load_scene


def test_list_names_presets_and_test_building(capsys):
    assert main(["scene", "list"]) == 0
    names = capsys.readouterr().out.split()
    assert names[:4] == ["medieval_tavern", "forest_ruin_house", "alpine_chalet", "imperial_temple"]
    assert "test_building" in names


def test_export_writes_the_target_mesh(tmp_path):
    assert main(["scene", "export", "random:3", "--out", str(tmp_path)]) == 0
    mesh = trimesh.load(tmp_path / "mesh.ply", process=False)
    expected = load_scene("random:3").target_mesh()
    assert len(mesh.faces) == len(expected.faces)
    assert np.allclose(mesh.bounds, expected.bounds, atol=1e-6)


def test_export_of_a_mitsuba_xml_scene_says_it_has_no_separate_target_mesh(tmp_path, capsys):
    xml = tmp_path / "scene.xml"
    xml.write_text('<scene version="3.0.0"><shape type="sphere"/></scene>')
    assert main(["scene", "export", str(xml), "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and f"{xml} is a Mitsuba XML scene" in err, err
    assert "no separate target mesh to export" in err and not (tmp_path / "out").exists()


def test_export_refuses_to_replace_a_mesh_without_overwrite(tmp_path, capsys):
    assert main(["scene", "export", "test_building", "--out", str(tmp_path)]) == 0
    (tmp_path / "mesh.ply").write_text("mine")
    assert main(["scene", "export", "test_building", "--out", str(tmp_path)]) == 2
    assert "--overwrite" in capsys.readouterr().err and (tmp_path / "mesh.ply").read_text() == "mine"
    assert main(["scene", "export", "test_building", "--out", str(tmp_path), "--overwrite"]) == 0
    assert len(trimesh.load(tmp_path / "mesh.ply").faces) > 0
    assert sorted(p.name for p in tmp_path.iterdir()) == ["mesh.ply"]  # no temporary file left


def test_unknown_action_exits_2(capsys):
    assert main(["scene", "render"]) == 2
    assert "unknown action 'render'" in capsys.readouterr().err


def test_export_honours_up_axis(tmp_path):
    trimesh.creation.box((1.0, 4.0, 2.0)).export(tmp_path / "box.obj")
    assert (
        main(["scene", "export", str(tmp_path / "box.obj"), "--up-axis", "y", "--out", str(tmp_path / "y")])
        == 0
    )
    extent = np.ptp(trimesh.load(tmp_path / "y" / "mesh.ply").vertices, axis=0)
    assert extent == pytest.approx([0.25, 0.5, 1.0])


def test_gallery_renders_four_sides_per_scene(tmp_path):
    out = tmp_path / "gallery.png"
    assert (
        main(
            [
                "scene",
                "gallery",
                "--out",
                str(out),
                "--scene",
                "test_building",
                "--scene",
                "test_building",
                "--width",
                "64",
                "--height",
                "48",
                "--spp",
                "2",
            ]
        )
        == 0
    )
    image = np.asarray(Image.open(out))
    assert image.shape == (2 * 48, 4 * 64, 3)
    assert not np.array_equal(image[:, :64], image[:, 64:128])  # four different sides


def test_unknown_scene_exits_with_a_message(tmp_path, capsys):
    assert main(["scene", "export", "castle", "--out", str(tmp_path)]) == 2
    assert "unknown scene 'castle'" in capsys.readouterr().err
