"""Coverage against view budget: prefixes of a sequential plan are its shorter plans; the table and AUC."""

import json
from dataclasses import replace

import pytest
from PIL import Image

from common.io import cache_dir
from nbv.experiments.budget import SETTINGS, BudgetConfig, budget_rows, coverage_auc, run_budget
from nbv.experiments.budget_flight import METRES
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
    assert doc["config"]["out"] == f"ELSEWHERE/{tmp_path.name}/out"  # no machine's folders in the record
    table = (tmp_path / "out" / "budget.md").read_text()
    assert "| test_building | greedy |" in table and "| 2 views | 3 views | AUC |" in table
    with Image.open(tmp_path / "out" / "budget.png") as image:
        assert image.size[0] > 500
    check_flight(doc, table)
    with Image.open(tmp_path / "out" / "budget_metres.png") as image:
        assert image.size[0] > 500


def check_flight(doc, table):
    """Each budget's metres are its plan's first legs; coverage within M metres is the best plan that fits."""
    flight = {(r["scene"], r["planner"]): r["mean"] for r in doc["flight"]["flight_m"]}
    runs = next(cache_dir().glob("budget/*/test_building/greedy-v3-seed0")).parent  # the 2- and 3-view study
    three = json.loads((runs / "greedy-v3-seed0" / "plan.json").read_text())
    assert flight["test_building", "greedy"] == pytest.approx([sum(three["legs_m"][:2]), three["flight_m"]])
    circle = [json.loads((runs / f"circle-v{k}-seed0" / "plan.json").read_text())["flight_m"] for k in (2, 3)]
    assert flight["test_building", "circle"] == pytest.approx(circle)
    reached = {(r["scene"], r["planner"]): r["mean"] for r in doc["flight"]["within_m"]}
    coverage = {(r["scene"], r["planner"]): r["mean"] for r in doc["rows"]["coverage"]}
    for name, metres in flight.items():  # one seed: the best coverage among the plans flying <= M
        assert reached[name] == pytest.approx([max([c for c, m in zip(coverage[name], metres) if m <= limit],
                                                   default=0.0) for limit in METRES])
    assert "## Flight (m) along the viewing shell" in table and "| <= 10 m | <= 20 m | <= 40 m |" in table


def test_budgets_must_ascend():
    with pytest.raises(ValueError, match="ascending"):
        BudgetConfig(budgets=(13, 5))
    with pytest.raises(ValueError, match="metres"):
        BudgetConfig(metres=(20.0, 10.0))
