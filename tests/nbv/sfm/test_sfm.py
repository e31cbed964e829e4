"""`nbv sfm` end to end on a case whose answer is known: an arc of six views of a textured box (ray-cast
in NumPy, exact poses) registers whole, its camera centres within millimetres of the truth after the
similarity fit, with the intrinsics held at the dataset's; GNSS priors put the model in the world
frame (through `nbv plan --sfm`'s summary); featureless views give no model, said so; bad inputs are
named errors."""

from __future__ import annotations

import json
import shutil
import struct

import pytest
from synthetic import write_circle_dataset
from synthetic_box import write_box_arc

from common.io import atomic_folder
from common.provenance import recorded_config, run_record
from nbv.cli import main
from nbv.cli.sfm import summary_line
from nbv.planning.config import PlanConfig
from nbv.sfm.check import sfm_summary
from nbv.sfm.config import SfmConfig, SfmSettings
from nbv.sfm.pipeline import pinhole_params
from render.dataset import read_dataset
from scenes.spec import SceneSpec

ARC = {"views": 6, "step_deg": 15.0, "size": (240, 180)}
"""The smallest arc measured to register reliably: at 160 x 120 the same arc folds."""


@pytest.fixture(scope="module")
def arc(tmp_path_factory):
    return write_box_arc(tmp_path_factory.mktemp("box") / "arc", **ARC)


@pytest.fixture(scope="module")
def result(arc, tmp_path_factory):
    out = tmp_path_factory.mktemp("sfm") / "out"
    assert main(["sfm", str(arc), "--out", str(out)]) == 0
    return out, json.loads((out / "sfm.json").read_text())


def test_the_arc_registers_whole_with_centres_within_millimetres(result):
    _, report = result
    assert (report["views"], report["registered"], report["models"]) == (6, 6, 1)
    assert report["points"] > 100 and report["reprojection_error_px"] < 0.5
    error = report["pose_error"]
    assert error["views"] == 6
    assert error["centre_error_cm"]["max"] < 0.5 and error["centre_error_pct_radius"]["max"] < 0.25
    assert error["rotation_error_deg"]["max"] < 1.0
    assert error["relative_rotation_error_deg"]["max"] < 0.5
    line = summary_line(report)
    assert line.startswith("6 of 6 views registered in the largest of 1 model(s)")
    assert f"mean {error['centre_error_cm']['mean']:.2f} cm" in line


def test_the_model_reads_back_with_the_dataset_intrinsics_held(result, arc):
    out, report = result
    data = (out / "sparse" / "0" / "cameras.bin").read_bytes()
    count, _, model_id, width, height = struct.unpack_from("<QIiQQ", data)
    params = struct.unpack_from("<4d", data, struct.calcsize("<QIiQQ"))
    camera = read_dataset(arc).camera
    assert (count, model_id, width, height) == (1, 1, camera.width, camera.height)  # 1: PINHOLE
    assert params == pytest.approx(pinhole_params(camera), abs=1e-9)
    names = (out / "sparse" / "0" / "images.bin").read_bytes()
    assert all(f"{i:04d}.png".encode() + b"\0" in names for i in range(6))
    assert sorted(p.name for p in (out / "images").iterdir()) == [f"{i:04d}.png" for i in range(6)]
    assert not (out / "sparse" / "1").exists() and not list(out.glob("*.db"))
    assert report["command"] == "nbv sfm" and report["pycolmap"] == "4.2.1"
    assert recorded_config(SfmConfig, out / "sfm.json", "nbv sfm").dataset == arc


def test_featureless_views_give_no_model_and_say_so(tmp_path, capsys):
    data = write_circle_dataset(tmp_path / "grey", [None] * 4)
    assert main(["sfm", str(data), "--out", str(tmp_path / "out")]) == 0
    assert "no model: 0 of 4 views registered" in capsys.readouterr().out
    report = json.loads((tmp_path / "out" / "sfm.json").read_text())
    assert (report["registered"], report["models"], report["pose_error"]) == (0, 0, None)
    assert not (tmp_path / "out" / "sparse").exists()


def _no_images(data):
    shutil.rmtree(data / "images")


def _no_intrinsics(data):
    doc = json.loads((data / "transforms.json").read_text())
    del doc["fl_x"]
    (data / "transforms.json").write_text(json.dumps(doc))


def _one_view(data):
    doc = json.loads((data / "transforms.json").read_text())
    doc["frames"] = doc["frames"][:1]
    (data / "transforms.json").write_text(json.dumps(doc))


@pytest.mark.parametrize("spoil, extra, message", [
    (_no_images, [], "names a missing file"),
    (_no_intrinsics, [], "field fl_x is missing"),
    (_one_view, [], "1 view(s); structure from motion needs at least 2"),
    (None, ["--gnss-noise-m", "-1"], "gnss_noise_m must be a positive number"),
])
def test_bad_inputs_are_one_line_errors(tmp_path, capsys, spoil, extra, message):
    data = write_circle_dataset(tmp_path / "data", [1, 2, 3])
    if spoil is not None:
        spoil(data)
    assert main(["sfm", str(data), "--out", str(tmp_path / "out"), *extra]) == 2
    err = capsys.readouterr().err
    assert err.startswith("nbv sfm: error: ") and message in err and len(err.strip().splitlines()) == 1
    assert not (tmp_path / "out").exists()


def test_an_output_inside_the_dataset_is_refused(tmp_path, capsys):
    data = write_circle_dataset(tmp_path / "data", [1, 2, 3])
    assert main(["sfm", str(data), "--out", str(data / "sfm")]) == 2
    assert "must not be the input folder" in capsys.readouterr().err


def test_a_plan_with_sfm_and_gnss_priors_keeps_the_world_frame_headline(arc, tmp_path):
    """Position priors put the model in the world frame (scale 1, centres near the truth without a fit);
    the relative image links of a plan's out/sfm survive the output folder's swap into place."""
    gnss = SfmSettings(gnss_noise_m=0.01, matching="spatial")
    config = PlanConfig(scene=SceneSpec(scene="test_building"), out=tmp_path / "plan", sfm=True,
                        sfm_settings=gnss)
    with atomic_folder(config.out) as folder:  # as `nbv plan --sfm` does, inside its output folder
        shutil.copytree(arc, folder / "views")
        summary = sfm_summary(read_dataset(folder / "views"), config.sfm_settings, config.seed,
                              folder / "sfm", run_record("nbv plan", config))
    assert (summary["views"], summary["registered"], summary["models"]) == (6, 6, 1)
    assert summary["pose_error"]["scale"] == pytest.approx(1.0, abs=0.03)
    assert summary["centre_error_world_cm"]["max"] < 3.0
    assert "model_summaries" not in summary
    links = sorted((config.out / "sfm" / "images").iterdir())
    assert len(links) == 6 and all(link.resolve().is_file() for link in links)
    doc = json.loads((config.out / "sfm" / "sfm.json").read_text())
    assert doc["command"] == "nbv plan" and doc["config"]["sfm_settings"]["gnss_noise_m"] == 0.01
