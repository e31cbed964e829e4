"""Every single-run record carries its commit, command and whole config; `--config RECORD` re-runs it."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from synthetic import write_circle_dataset

from common.provenance import git_commit
from nbv.cli import main
from scenes import load_scene

TINY = ["--width", "32", "--height", "24", "--spp", "1"]


def record(path: Path) -> dict:
    """The run record of a result file (a dataset's under `nbv`)."""
    doc = json.loads(path.read_text())
    return doc.get("nbv", doc) if "config" not in doc else doc


def rerun_matches(name: str, first: Path, again: Path, out: Path, *extra: str) -> tuple[dict, dict]:
    """Re-run the record `first` into `out`; check the new record `again` is the same run; return both."""
    assert main([name, "--config", str(first), "--out", str(out), *extra]) == 0
    a, b = record(first), record(again)
    assert a["commit"] == b["commit"] == git_commit() and a["command"] == b["command"] == f"nbv {name}"
    assert {**a["config"], "out": None} == {**b["config"], "out": None}
    assert b["config"]["out"] == str(out)
    return a, b


@pytest.fixture(scope="module")
def scan(tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("records") / "scan"
    assert main(["scan", "test_building", "circle", "--views", "2", "--elevation-deg", "20", *TINY,
                 "--seed", "3", "--out", str(out)]) == 0
    return out


def test_a_scan_rerun_from_its_record_renders_the_same_dataset(scan, tmp_path):
    a, b = rerun_matches("scan", scan / "transforms.json", tmp_path / "again" / "transforms.json",
                         tmp_path / "again")
    assert a["config"]["plan"] == {"radius": 2.0, "elevation_deg": 20.0, "views": 2, "end_overlap": 0.85}
    assert a["config"]["seed"] == 3 and a["config"]["camera"]["width"] == 32
    for image in ("images/0000.png", "images/0001.png", "depth/0001.png"):
        assert (scan / image).read_bytes() == (tmp_path / "again" / image).read_bytes()


def test_other_flags_override_the_record(scan, tmp_path):
    assert main(["scan", "--config", str(scan / "transforms.json"), "hemisphere", "--min-elevation-deg", "80",
                 "--out", str(tmp_path / "high")]) == 0
    config = record(tmp_path / "high" / "transforms.json")["config"]
    assert config["plan"]["min_elevation_deg"] == 80.0 and config["camera"]["width"] == 32
    assert config["seed"] == 3  # the rest comes from the record


def test_refine_sweep_reconstruct_and_evaluate_records_rerun(tmp_path):
    source = write_circle_dataset(tmp_path / "ds", [0, 0, 1, None, 2, 0], size=(64, 48))
    assert main(["refine", str(source), "--ranges", "2", "--words", "5", "--max-features", "40",
                 "--feature-backend", "opencv", "--seed", "2", "--out", str(tmp_path / "r1")]) == 0
    a, b = rerun_matches("refine", tmp_path / "r1" / "refine.json", tmp_path / "r2" / "refine.json",
                         tmp_path / "r2")
    assert a["config"]["bov"]["sift"]["backend"] == "opencv" and a["kept"] == b["kept"]
    assert main(["refine-sweep", str(source), "--ranges", "1", "2", "--words", "5", "--max-features", "40",
                 "--out", str(tmp_path / "s1")]) == 0
    a, b = rerun_matches("refine-sweep", tmp_path / "s1" / "sweep.json", tmp_path / "s2" / "sweep.json",
                         tmp_path / "s2")
    assert a["config"]["ranges"] == [1, 2] and a["grid"] == b["grid"]

    assert main(["reconstruct", str(source), "--voxel-size-m", "0.01", "--out", str(tmp_path / "m1")]) == 0
    a, b = rerun_matches("reconstruct", tmp_path / "m1" / "reconstruction.json",
                         tmp_path / "m2" / "reconstruction.json", tmp_path / "m2")
    assert a["config"]["recon"]["voxel_size_m"] == 0.01 and a["faces"] == b["faces"]

    mesh = tmp_path / "gt.ply"
    load_scene("test_building").target_mesh().export(mesh)
    assert main(["evaluate", str(mesh), "--gt", "test_building", "--metric-points", "500", "--seed", "4",
                 "--out", str(tmp_path / "e1")]) == 0
    a, b = rerun_matches("evaluate", tmp_path / "e1" / "metrics.json", tmp_path / "e2" / "metrics.json",
                         tmp_path / "e2")
    assert a["config"]["metrics"]["n_points"] == 500 and a["gt"] == b["gt"] and a["run"] == b["run"]


def test_a_plan_rerun_from_its_record_flies_the_same_views(tmp_path):
    args = ["plan", "test_building", "--planner", "random", "--views", "3", *TINY, "--no-full-scan",
            "--metric-points", "500", "--voxel-size-m", "0.01", "--seed", "5", "--out", str(tmp_path / "p1")]
    assert main(args) == 0
    first, again = tmp_path / "p1" / "plan.json", tmp_path / "p2" / "plan.json"
    a, b = rerun_matches("plan", first, again, tmp_path / "p2")
    assert a["config"]["planner"] == "random" and a["config"]["seed"] == 5
    assert a["viewpoints"] == b["viewpoints"] and a["gt"] == b["gt"]


def test_a_record_of_another_command_or_no_record_is_refused(scan, tmp_path, capsys):
    assert main(["plan", "--config", str(scan / "transforms.json"), "--out", str(tmp_path / "p")]) == 2
    assert "recorded by `nbv scan`, not `nbv plan`" in capsys.readouterr().err
    (tmp_path / "bare.json").write_text("{}")
    assert main(["scan", "--config", str(tmp_path / "bare.json"), "--out", str(tmp_path / "s")]) == 2
    assert "no run record" in capsys.readouterr().err
    assert main(["scan", "--config", str(tmp_path / "missing.json")]) == 2
    assert "not a readable JSON file" in capsys.readouterr().err
    assert not (tmp_path / "p").exists() and not (tmp_path / "s").exists()
