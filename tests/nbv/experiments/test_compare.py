"""`compare_planners`: runs already on disk are tabulated beside the paper's Fig. 1."""

from __future__ import annotations

import json

import pytest
from PIL import Image

from nbv.experiments.compare import CompareConfig, compare_planners
from scenes.spec import SceneSpec


def test_compare_planners_tabulates_saved_runs(tmp_path):
    def metrics(coverage, chamfer, hausdorff):
        return {"coverage": coverage, "chamfer_cm": chamfer, "hausdorff_cm": hausdorff}

    flights = {0: ([3.0, 3.0, 4.0], [1.0, 2.0, 3.0]), 1: ([4.0, 4.0, 4.0], [1.0, 2.0, 1.0])}  # legs, azimuths
    for seed, coverage in ((0, 0.70), (1, 0.80)):  # runs already on disk are read back, not redone
        folder = tmp_path / f"random-seed{seed}"
        folder.mkdir()
        legs, azimuths = flights[seed]
        flight = {"start_viewpoint": [2.0, 0.0, 0.5], "viewpoints": [[2.0, a, 0.5] for a in azimuths],
                  "legs_m": legs, "flight_m": sum(legs), "azimuth_reversals": seed}
        (folder / "plan.json").write_text(json.dumps({"views": 13, "gt": metrics(coverage, 0.5, 8.0),
                                                      "reference": metrics(coverage + 0.1, 0.4, 6.0),
                                                      "planning_s": 1.0, "deciding_s": 0.5, **flight}))
    config = CompareConfig(scene=SceneSpec(scene="alpine_chalet"), planners=("random",), seeds=(0, 1),
                           out=tmp_path)
    table = compare_planners(config)
    row = next(line for line in table.splitlines() if line.startswith("| random"))
    assert row == ("| random (2 seeds) | 13.0 ± 0.0 | 85.00 ± 5.00 | 0.40 ± 0.00 | 6.00 ± 0.00 "
                   "| 75.00 ± 5.00 | 0.50 ± 0.00 | 8.00 ± 0.00 | 11.0 ± 1.0 | 0.5 ± 0.5 |")
    assert table.splitlines()[-1] == ("| paper Fig. 1 (SAC policy, vs 288-view scan) | 13 | 94.60 | 0.80 "
                                      "| 2.78 | - | - | - | - | - |")
    saved = json.loads((tmp_path / "comparison.json").read_text())
    assert [r["seed"] for r in saved["runs"]] == [0, 1] and saved["paper_fig1"]["coverage"] == 0.946
    assert saved["config"]["scene"] == {"up_axis": "z", "scene": "alpine_chalet"}
    assert saved["config"]["out"] == f"ELSEWHERE/{tmp_path.parent.name}/{tmp_path.name}"  # portable
    assert (tmp_path / "comparison.md").read_text() == table
    assert Image.open(tmp_path / "comparison.png").size[0] > 500


def test_a_comparison_needs_planners_and_seeds(tmp_path):
    with pytest.raises(ValueError, match="at least one planner and one seed"):
        CompareConfig(scene=SceneSpec(scene="alpine_chalet"), planners=(), out=tmp_path)
