"""`nbv demo` end to end on a small scan: every stage's files, a table, and scan reuse."""

import json

from nbv.cli import main


def test_demo_runs_every_stage_and_reuses_its_scan(tmp_path, capsys):
    args = ["demo", "--out", str(tmp_path), "--scene", "test_building", "--width", "96", "--height", "72",
            "--spp", "2", "--end-overlap", "0.5", "--side-overlap", "0.4", "--ranges", "3", "--words", "5",
            "--voxel-size-m", "0.01", "--metric-points", "5000"]
    assert main(args) == 0
    printed = capsys.readouterr().out
    assert "| refined |" in printed and "Paper (Table 2" in printed
    results = json.loads((tmp_path / "results.json").read_text())
    assert 0 < results["views_refined"] <= results["views_full"]
    for ref in ("gt", "reference"):
        assert 0 <= results["metrics"]["refined"][ref]["coverage"] <= 1
    full, refined = results["metrics"]["full"]["gt"], results["metrics"]["refined"]["gt"]
    assert full["coverage"] >= refined["coverage"] and full["chamfer_cm"] < 3.0  # 2 cm pixels at 96x72
    for name in ("contact_sheet", "trajectory_full", "trajectory_refined", "heatmap_refined_vs_full",
                 "heatmap_full_vs_gt"):
        assert (tmp_path / f"{results['figures'][name].split('/')[-1]}").stat().st_size > 0
    for sub in ("recon_full/mesh.ply", "recon_refined/points.ply", "refined/refine.json"):
        assert (tmp_path / sub).is_file()
    stamp = (tmp_path / "full_scan" / "transforms.json").stat().st_mtime_ns
    assert main(args) == 0
    assert (tmp_path / "full_scan" / "transforms.json").stat().st_mtime_ns == stamp  # not re-rendered
