"""`nbv scan`, `nbv scene` and `nbv demo` run end to end; bad input exits 2 naming the fault."""


import pytest

from nbv.cli import main
from render.dataset import read_dataset


def test_scan_circle_writes_a_readable_dataset(tmp_path):
    out = tmp_path / "ds"
    assert main(["scan", "test_building", "--plan", "circle", "--views", "4", "--elevation", "20",
                 "--width", "48", "--height", "36", "--spp", "2", "--out", str(out)]) == 0
    ds = read_dataset(out)
    assert len(ds) == 4 and ds.camera.width == 48
    assert ds.meta["scene"] == "test_building" and ds.meta["plan"]["name"] == "circle"
    assert [round(f.viewpoint.elevation, 6) for f in ds.frames] == [round(0.349066, 6)] * 4


def test_scene_list_and_export(tmp_path, capsys):
    assert main(["scene", "list"]) == 0
    assert "test_building" in capsys.readouterr().out.split()
    assert main(["scene", "export", "test_building", "--out", str(tmp_path)]) == 0
    assert (tmp_path / "mesh.ply").stat().st_size > 0


@pytest.mark.parametrize("args, message", [
    (["no_such_scene"], "unknown scene"),
    (["test_building", "--width", "0"], "width"),
    (["test_building", "--focal-mm", "-3"], "focal_mm"),
    (["test_building", "--plan", "circle", "--views", "0"], "views"),
])
def test_bad_scan_input_exits_2_with_a_message(tmp_path, capsys, args, message):
    assert main(["scan", *args, "--out", str(tmp_path / "ds")]) == 2
    assert message in capsys.readouterr().err
    assert not (tmp_path / "ds").exists()
