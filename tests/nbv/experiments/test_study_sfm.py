"""--sfm in the planner studies, the demo and `nbv tables` (its budget part): the flag reaches every run a
study command makes and keys when a run counts as done; the tables gain the registration columns (from
recorded SfM results); the demo's SfM stage runs COLMAP for real on a tiny textured-box scan
(`synthetic_box`)."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest
from synthetic_box import write_box_arc

from nbv.cli.parse import parse
from nbv.experiments.budget import BudgetConfig
from nbv.experiments.compare import CompareConfig, compare_planners
from nbv.experiments.demo import DemoConfig, Stopwatch, online_study, sfm_lines, sfm_stage
from nbv.experiments.online import OnlineConfig, comparisons, run_online
from nbv.experiments.paper import PaperConfig, budget_config
from nbv.experiments.planner_study import StudyRun, plan_units
from nbv.experiments.sfm_columns import planned_sfm_table
from render.dataset import read_dataset
from scenes.spec import SceneSpec

STUDIES = {
    "compare": (CompareConfig, ["test_building", "--out", "cmp"], lambda c: plan_units(c.study())),
    "online": (OnlineConfig, ["--out", "online"],
               lambda c: [task for one in comparisons(c) for task in plan_units(one.study())]),
    "budget": (BudgetConfig, [], lambda c: plan_units(c.study(Path("runs")))),
    "demo": (DemoConfig, [], lambda c: plan_units(online_study(c, Path("demo"), "policy", c.policy, None))),
    "tables": (PaperConfig, [], lambda c: plan_units(budget_config(c).study(Path("runs")))),
}
"""Per study command: its config, the arguments it needs and the plan units it makes."""


@pytest.mark.parametrize("command", list(STUDIES))
def test_sfm_reaches_every_run_of_a_study_and_keys_when_it_is_done(command):
    cls, needed, units_of = STUDIES[command]
    plain = units_of(parse(cls, needed, command))
    assert all(not u.kwargs["config"].sfm and u.result.name == "plan.json" for u in plain)
    asked = units_of(parse(cls, [*needed, "--sfm", "--sift-max-features", "1000"], command))
    assert len(asked) == len(plain) > 0
    for unit in asked:
        config = unit.kwargs["config"]
        assert config.sfm and config.sfm_settings.sift_max_features == 1000
        assert unit.result == config.out / "sfm" / "sfm.json"


def sfm_headline(registered: int, models: int, centre_cm: float | None, views: int = 13) -> dict:
    spread = {"mean": centre_cm, "median": centre_cm, "max": centre_cm}
    pose = {"centre_error_cm": spread} if centre_cm else None
    return {"views": views, "registered": registered, "registered_share": registered / views,
            "models": models, "points": 100 * registered, "reprojection_error_px": 0.6, "pose_error": pose}


def save_run(folder: Path, sfm: dict | None, views: int = 13) -> None:
    """A finished plan run as `nbv plan` leaves it, with its SfM result when given (so it is not redone)."""
    metrics = {"coverage": 0.7, "chamfer_cm": 0.5, "hausdorff_cm": 8.0}
    doc = {"views": views, "gt": metrics, "reference": metrics, "planning_s": 1.0, "deciding_s": 0.5,
           "start_viewpoint": [2.0, 0.0, 0.5], "viewpoints": [[2.0, 0.1 * k, 0.5] for k in range(views)],
           "legs_m": [1.0] * views, "flight_m": float(views), "azimuth_reversals": 0}
    (folder / "sfm").mkdir(parents=True)
    if sfm is not None:
        doc["sfm"] = sfm
        (folder / "sfm" / "sfm.json").write_text(json.dumps(sfm))
    (folder / "plan.json").write_text(json.dumps(doc))


def test_compare_with_sfm_adds_the_registration_columns_and_redoes_runs_made_without(tmp_path):
    save_run(tmp_path / "random-seed0", sfm_headline(9, 2, 3.0))
    save_run(tmp_path / "random-seed1", sfm_headline(0, 0, None))
    config = CompareConfig(scene=SceneSpec(scene="alpine_chalet"), planners=("random",), seeds=(0, 1),
                           out=tmp_path, sfm=True)
    lines = compare_planners(config).splitlines()
    assert lines[2].endswith("| flight m | azimuth reversals | registered | models | centre error (cm) |")
    assert lines[4].endswith("| 13.0 ± 0.0 | 0.0 ± 0.0 | 9/13, 0/13 | 1.0 | 3.0 (1 run) |")
    assert lines[-1].endswith("| - | - | - | - | - |") and lines[-1].count("| - ") == 3 + 2 + 3
    assert json.loads((tmp_path / "comparison.json").read_text())["runs"][0]["sfm"] == {
        "views": 13, "registered": 9, "models": 2, "centre_error_cm": 3.0}
    save_run(tmp_path / "circle-seed0", None)  # made without --sfm: done for a plain study only
    assert not plan_units(CompareConfig(scene=SceneSpec(scene="alpine_chalet"), planners=("circle",),
                                        seeds=(0,), out=tmp_path, sfm=True).study())[0].done()
    assert plan_units(CompareConfig(scene=SceneSpec(scene="alpine_chalet"), planners=("circle",),
                                    seeds=(0,), out=tmp_path).study())[0].done()


def test_online_and_budget_reports_give_one_sfm_row_per_building_planner_and_plan(tmp_path):
    for planner, registered in (("random", 13), ("circle", 4)):
        folder = tmp_path / "test_building" / "views13" / f"{planner}-seed0"
        save_run(folder, sfm_headline(registered, 1, 1.5))
    text = run_online(OnlineConfig(out=tmp_path, scenes=("test_building",), policies=("random",),
                                   depth_options=(), baselines=("circle",), seeds=(0,), one_pass=False,
                                   sfm=True))
    assert "| test_building | random | 13/13 | 1.0 | 1.5 |" in text
    assert "| test_building | circle | 4/13 | 1.0 | 1.5 |" in text
    plan = tmp_path / "plan"
    save_run(plan, sfm_headline(5, 1, None, views=9), views=9)
    runs = [StudyRun("test_building", "random", 0, views, plan) for views in (5, 9)]  # a prefix shares it
    assert planned_sfm_table(runs).splitlines()[2:] == ["| test_building | random | 9 | 5/9 | 1.0 | - |"]


def test_the_demo_sfm_stage_reconstructs_the_full_and_the_refined_set(tmp_path):
    full = read_dataset(write_box_arc(tmp_path / "full", views=6, step_deg=15.0, size=(240, 180)))
    shutil.copytree(full.root, tmp_path / "out" / "refined")  # the refined set: here the same views
    clock = Stopwatch()
    found = sfm_stage(DemoConfig(sfm=True), full, tmp_path / "out", clock)
    assert list(clock.seconds) == ["sfm_full_s", "sfm_refined_s"]
    for name in ("full", "refined"):
        written = json.loads((tmp_path / "out" / f"sfm_{name}" / "sfm.json").read_text())
        assert written["registered"] == found[name]["registered"] == 6 and written["command"] == "nbv demo"
        assert found[name]["pose_error"]["centre_error_cm"]["max"] < 1.0
    table = sfm_lines({"sfm": found, "online": {}})
    rows = table[2].splitlines()[2:]
    assert [row.split(" | ")[:3] for row in rows] == [["| full set", "6/6", "1.0"],
                                                      ["| refined set", "6/6", "1.0"]]
    assert sfm_lines({"online": {}}) == []
    linked = sfm_lines({"sfm": {"refined_linked": found["refined"]}, "online": {}})[2].splitlines()[2]
    assert linked.startswith("| refined linked set | 6/6 |")
