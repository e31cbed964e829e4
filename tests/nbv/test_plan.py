"""`nbv plan` end to end, tiny: views dataset, reconstruction, metrics.json, trajectory.png."""

from __future__ import annotations

import json

from PIL import Image

from nbv.cli import main
from nbv.plan import PlanConfig, compare_planners, reference_mesh
from render.dataset import read_dataset
from scenes import load_scene


def test_nbv_plan_end_to_end(tmp_path, capsys):
    reference = tmp_path / "reference.ply"
    load_scene("test_building").target_mesh().export(reference)
    out = tmp_path / "plan"
    args = ["plan", "test_building", "--planner", "circle", "--views", "6", "--width", "64", "--height", "48",
            "--spp", "1", "--reference", str(reference), "--metric-points", "3000", "--voxel-size-m", "0.01",
            "--out", str(out)]
    assert main(args) == 0
    dataset = read_dataset(out / "views")
    assert len(dataset) == 6 and dataset.meta["planner"] == "circle"
    metrics = json.loads((out / "metrics.json").read_text())
    for name in ("gt", "reference"):
        assert 0.0 < metrics[name]["coverage"] <= 1.0
        m = metrics[name]
        assert 0 < m["chamfer_cm"] <= m["hausdorff_cm"]
    plan = json.loads((out / "plan.json").read_text())
    assert plan["views"] == 6 and len(plan["viewpoints"]) == 6 and plan["gt"] == metrics["gt"]
    assert (out / "trajectory.png").stat().st_size > 10_000 and (out / "mesh.ply").is_file()
    assert '"planner": "circle"' in capsys.readouterr().out
    assert main(args) == 2  # refuses to overwrite without --overwrite


def test_nbv_plan_unknown_planner_is_a_clear_error(tmp_path, capsys):
    assert main(["plan", "test_building", "--planner", "best", "--out", str(tmp_path / "p")]) == 2
    assert "unknown planner" in capsys.readouterr().err


def test_reference_is_the_cached_full_scan_reconstruction(tmp_path):
    config = PlanConfig(scene="test_building", out=tmp_path / "plan", width=48, height=36, spp=1,
                        voxel_size_m=0.02)
    path = reference_mesh(config)
    assert path.name == "mesh.ply" and path.parent.name == "reconstruction_20mm"
    assert len(read_dataset(path.parent.parent)) == 288  # the paper's full hemisphere scan
    stamp = path.stat().st_mtime_ns
    assert reference_mesh(config) == path and path.stat().st_mtime_ns == stamp  # reused, not rebuilt


def test_compare_planners_tabulates_saved_runs(tmp_path):
    def metrics(coverage, chamfer, hausdorff):
        return {"coverage": coverage, "chamfer_cm": chamfer, "hausdorff_cm": hausdorff}

    for seed, coverage in ((0, 0.70), (1, 0.80)):  # runs already on disk are read back, not redone
        folder = tmp_path / f"random-seed{seed}"
        folder.mkdir()
        (folder / "plan.json").write_text(json.dumps({"views": 13, "gt": metrics(coverage, 0.5, 8.0),
                                                      "reference": metrics(coverage + 0.1, 0.4, 6.0)}))
    base = PlanConfig(scene="alpine_chalet", out=tmp_path)
    table = compare_planners(base, ["random"], [0, 1], tmp_path)
    row = next(line for line in table.splitlines() if line.startswith("| random"))
    assert row == ("| random (2 seeds) | 13.0 ± 0.0 | 85.00 ± 5.00 | 0.40 ± 0.00 | 6.00 ± 0.00 "
                   "| 75.00 ± 5.00 | 0.50 ± 0.00 | 8.00 ± 0.00 |")
    assert table.splitlines()[-1] == ("| paper Fig. 1 (SAC policy, vs 288-view scan) | 13 | 94.60 | 0.80 "
                                      "| 2.78 | - | - | - |")
    saved = json.loads((tmp_path / "comparison.json").read_text())
    assert [r["seed"] for r in saved["runs"]] == [0, 1] and saved["paper_fig1"]["coverage"] == 0.946
    assert (tmp_path / "comparison.md").read_text() == table
    assert Image.open(tmp_path / "comparison.png").size[0] > 500
