"""`nbv tables` end to end on a tiny grid; the paper's numbers land in their own columns."""

import csv
import json

from nbv.experiments.table2 import TablesConfig, paper_cell, run_tables
from nbv.recon.config import MetricsConfig, ReconstructionConfig
from render.camera import UAVCamera
from render.scan import HemispherePlan
from render.settings import RenderSettings


def test_paper_cells_are_the_papers_table2():
    assert paper_cell("medieval_tavern", 5, 10) == {
        "views": 143,
        "hausdorff_cm": 2.1509,
        "chamfer_cm": 0.1183,
    }
    assert paper_cell("forest_ruin_house", 11, 30)["views"] == 36
    assert paper_cell("medieval_tavern", 4, 10) == {} and paper_cell("test_building", 5, 10) == {}


def test_tables_on_a_tiny_grid(tmp_path):
    config = TablesConfig(
        out=tmp_path,
        scenes=("test_building",),
        ranges=(2, 5),
        words=(5,),
        camera=UAVCamera(96, 72),
        render=RenderSettings(spp=1),
        plan=HemispherePlan(end_overlap=0.5, side_overlap=0.4),
        recon=ReconstructionConfig(voxel_size_m=0.01, truncation_m=0.04),
        metrics=MetricsConfig(n_points=3000),
        seeds=(0, 1),
    )
    rows = run_tables(config)
    assert [(r["ranges"], r["words"]) for r in rows] == [("-", "-"), (2, 5), (5, 5)]
    assert all(0 < r["views"] <= rows[0]["views"] for r in rows[1:])
    with open(tmp_path / "table2.csv") as handle:
        assert len(list(csv.DictReader(handle))) == 3
    doc = json.loads((tmp_path / "table2.json").read_text())
    assert doc["config"]["ranges"] == [2, 5] and doc["commit"]
    assert [r["seed"] for r in doc["seed_rows"]] == [0, 0, 0, 1, 1, 1]  # each seed renders its own scan
    for row in rows:  # the mean and std over the two seeds' rows of the cell
        cell = (row["ranges"], row["words"])
        mine = [r["views"] for r in doc["seed_rows"] if (r["ranges"], r["words"]) == cell]
        assert row["views"] == sum(mine) / 2 and row["views_std"] == abs(mine[0] - mine[1]) / 2
        assert row["seeds"] == [0, 1]
    assert "| test_building | 2 | 5 |" in (tmp_path / "table2.md").read_text()
    assert (tmp_path / "table2.png").stat().st_size > 0
    assert sorted(p.name for p in (tmp_path / "fig6").glob("*.png")) == [
        "fig6_test_building_N2_W5.png",
        "fig6_test_building_N5_W5.png",
    ]


def test_tables_on_local_workers_give_the_rows_measured_in_process(tmp_path):
    from dataclasses import replace

    from nbv.fanout.config import ExecutorConfig

    config = TablesConfig(out=tmp_path / "here", scenes=("test_building",), ranges=(3,), words=(5,),
                          camera=UAVCamera(64, 48), render=RenderSettings(spp=1),
                          plan=HemispherePlan(end_overlap=0.3, side_overlap=0.2),
                          recon=ReconstructionConfig(voxel_size_m=0.01, truncation_m=0.04),
                          metrics=MetricsConfig(n_points=2000), seeds=(0,))
    here = run_tables(config)
    ticks = []
    workers = replace(config, out=tmp_path / "there", executor=ExecutorConfig(workers=2))
    there = run_tables(workers, ticks.append)
    assert there == here and ticks == [2]  # the building's two rows, once it is done
    docs = [json.loads((tmp_path / out / "table2.json").read_text()) for out in ("here", "there")]
    assert docs[0]["rows"] == docs[1]["rows"] and "executor" not in docs[1]["config"]
    assert docs[1]["config"]["out"] == f"ELSEWHERE/{tmp_path.name}/there"  # no machine's folders
    assert [p.name for p in (tmp_path / "there" / "fig6").glob("*.png")] == ["fig6_test_building_N3_W5.png"]
