"""Coverage against view budget: prefixes of a sequential plan are its shorter plans; the table and AUC."""

import json
from dataclasses import replace

import pytest
from PIL import Image

from nbv.experiments.budget import SETTINGS, BudgetConfig, budget_rows, coverage_auc, run_budget
from nbv.recon.config import MetricsConfig
from render.camera import UAVCamera
from render.settings import RenderSettings


def test_auc_is_the_mean_coverage_over_the_budget_range():
    assert coverage_auc((5, 9, 13, 20), [50.0, 50.0, 50.0, 50.0]) == 50.0
    assert coverage_auc((5, 10, 20), [0.0, 60.0, 60.0]) == pytest.approx((150 + 600) / 15)
    assert coverage_auc((13,), [70.0]) == 70.0


def test_rows_average_seeds_then_buildings():
    curves = {("a", "random"): [[40.0, 60.0], [60.0, 80.0]], ("b", "random"): [[70.0, 90.0], [70.0, 90.0]]}
    rows = budget_rows(curves, (5, 13))
    assert rows[0] == {"scene": "a", "planner": "random", "mean": [50.0, 70.0], "std": [10.0, 10.0],
                       "auc": 60.0}
    assert rows[-1]["scene"] == "mean" and rows[-1]["mean"] == [60.0, 80.0]
    assert rows[-1]["std"] == [10.0, 10.0]


def test_a_sequential_plans_prefix_scores_as_its_shorter_plan(tmp_path):
    config = BudgetConfig(out=tmp_path / "out", scenes=("test_building",), planners=("greedy", "circle"),
                          seeds=(0,), budgets=(2, 3),
                          settings=replace(SETTINGS, camera=UAVCamera(48, 36), render=RenderSettings(spp=1),
                                           metrics=MetricsConfig(n_points=3000)))
    rows = run_budget(config)
    alone = run_budget(BudgetConfig(**{**config.__dict__, "out": tmp_path / "two", "budgets": (2,)}))
    for measure in ("coverage", "visible"):  # a prefix of greedy's 3-view plan is its 2-view plan
        greedy = next(r for r in rows[measure] if r["scene"] == "test_building" and r["planner"] == "greedy")
        assert greedy["mean"][0] == next(r for r in alone[measure] if r["planner"] == "greedy")["mean"][0]
        assert all(0 < m <= 100 for r in rows[measure] for m in r["mean"])
    doc = json.loads((tmp_path / "out" / "budget.json").read_text())
    assert set(doc["curves"]["visible"]) == {"test_building/greedy", "test_building/circle"}
    table = (tmp_path / "out" / "budget.md").read_text()
    assert "| test_building | greedy |" in table and "| 2 views | 3 views | AUC |" in table
    with Image.open(tmp_path / "out" / "budget.png") as image:
        assert image.size[0] > 500


def test_budgets_must_ascend():
    with pytest.raises(ValueError, match="ascending"):
        BudgetConfig(budgets=(13, 5))
