"""The planner study behind `nbv compare`, `nbv online`, the budget curves and the demo's online half: its
units, every plan knob on every study command, and a registered toy planner run through all of them."""

from __future__ import annotations

import dataclasses
import json
import typing
import warnings
from dataclasses import replace
from pathlib import Path
from typing import Any, Literal

import pytest
import tyro

from nbv.cli.parse import MARKERS, parse
from nbv.experiments.budget import SETTINGS, BudgetConfig, run_budget
from nbv.experiments.compare import CompareConfig, compare_planners
from nbv.experiments.demo import DemoConfig, online_study
from nbv.experiments.online import OnlineConfig, comparisons, run_online
from nbv.experiments.paper import PaperConfig, budget_config
from nbv.experiments.planner_study import PlannerStudy, plan_units, study_runs, study_stages
from nbv.planning import registry
from nbv.planning.base import Planner
from nbv.planning.config import PlanConfig, PlanSettings
from nbv.planning.registry import PlannerEntry, entry, register
from nbv.recon.config import MetricsConfig
from render.camera import UAVCamera
from render.settings import RenderSettings
from render.viewpoint import Viewpoint
from scenes import load_scene
from scenes.spec import SceneSpec


def study(tmp_path: Path, **kwargs: Any) -> PlannerStudy:
    fields = {"scenes": ("test_building", "random:5"), "planners": ("random", "circle"), "seeds": (0, 1),
              "out": tmp_path, **kwargs}
    return PlannerStudy(**fields)


def test_a_curve_plans_sequential_planners_once_and_scores_their_prefixes(tmp_path):
    curve = study(tmp_path, budgets=(2, 5), curves=True, runs="{scene}/{planner}-v{views}-seed{seed}",
                  settings=PlanSettings(full_scan=False))
    references, plans, scores = study_stages(curve)
    assert references == []  # scored against the ground truth only: no full scan to make
    # random: one plan at 5 views per scene and seed; circle (no prefixes): one per budget
    assert len(plans) == 2 * 2 * (1 + 2) and len(scores) == len(plans)
    names = [task.name for task in plans[:6]]
    assert names == [f"{run}-seed{seed} in {tmp_path}/test_building" for run, seed in
                     (("random-v5", 0), ("random-v5", 1), ("circle-v2", 0), ("circle-v5", 0),
                      ("circle-v2", 1), ("circle-v5", 1))]
    assert scores[0].kwargs["views"] == (2, 5) and scores[2].kwargs["views"] == (2,)
    runs = study_runs(curve)  # one record per budget; random's 2-view run is its 5-view plan's prefix
    assert [(r.planner, r.views, r.folder.name) for r in runs[:4]] == [
        ("random", 2, "random-v5-seed0"), ("random", 5, "random-v5-seed0"),
        ("random", 2, "random-v5-seed1"), ("random", 5, "random-v5-seed1")]


def test_every_run_of_a_study_is_a_plan_config_of_its_settings(tmp_path):
    settings = PlanSettings(camera=UAVCamera(64, 48), candidates=3)
    compared = study(tmp_path, budgets=(None,), settings=settings, up_axis="y")
    references, plans, _ = study_stages(compared)
    assert [task.name for task in references] == ["full-scan reference of test_building",
                                                  "full-scan reference of random:5"]
    config = plans[-1].kwargs["config"]
    assert config == PlanConfig(scene=config.scene, views=None, planner="circle", seed=1,
                                out=tmp_path / "circle-seed1", overwrite=True, settings=settings)
    assert config.scene.up_axis == "y" and plans[-1].result == tmp_path / "circle-seed1" / "plan.json"


@pytest.mark.parametrize("kwargs, message", [
    ({"planners": ()}, "at least one scene, planner, seed and budget"),
    ({"planners": ("best",)}, "unknown planner 'best'"),
    ({"budgets": (0,)}, "budgets must be >= 1"),
    ({"budgets": (5, 2), "curves": True}, "distinct view counts, ascending"),
    ({"budgets": (None,), "curves": True}, "distinct view counts, ascending"),
    ({"runs": "{planner}-{building}"}, "not building"),
])
def test_a_study_refuses_what_it_cannot_run(tmp_path, kwargs, message):
    with pytest.raises(ValueError, match=message):
        study(tmp_path, **kwargs)


# --- (a) every plan knob reaches every study command --------------------------------------------------

def leaves(cls: type, prefix: tuple[str, ...] = ()) -> list[tuple[tuple[str, ...], Any, Any]]:
    """(path, default, type) of every leaf field of a (nested) config dataclass that has a flag (tyro's
    `Suppress`ed sub-seeds, set from the run's seed, have none)."""
    found, default = [], cls()
    hints = typing.get_type_hints(cls, include_extras=True)
    for field in dataclasses.fields(cls):
        value, hint = getattr(default, field.name), hints[field.name]
        if typing.get_origin(hint) is typing.Annotated:
            if any("Suppress" in repr(marker) for marker in hint.__metadata__):
                continue
            hint = typing.get_args(hint)[0]
        if dataclasses.is_dataclass(value):
            found += [(prefix + (field.name,) + path, v, t) for path, v, t in leaves(type(value))]
        else:
            found.append((prefix + (field.name,), value, hint))
    return found


def leaf(config: Any, path: tuple[str, ...]) -> Any:
    for name in path:
        config = getattr(config, name)
    return config


def flags(cls: type) -> dict[str, list[str]]:
    """The parser's option strings, by destination (nested names joined with '.', '-' for '_')."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DeprecationWarning)
        parser = tyro.extras.get_parser(cls, config=MARKERS)
    return {action.dest: action.option_strings for action in parser._actions if action.option_strings}


def other_value(default: Any, hint: Any, options: list[str]) -> list[str]:
    """Command-line tokens giving a leaf a value other than its default."""
    if hint is bool:
        return [next(o for o in options if o.startswith("--no-") == default)]
    args = [a for a in typing.get_args(hint) if a is not type(None)]
    kinds = [a for a in (*args, hint) if typing.get_origin(a) is Literal]
    if kinds:
        choice = next(c for k in kinds for c in typing.get_args(k) if c != default and c is not None)
        return [options[0], str(choice)]
    kind = args[0] if default is None and args else type(default)
    if kind is int:
        return [options[0], str(3 if default is None else default + 1)]
    if kind is float:
        return [options[0], str(0.5 if not default else default * 0.5)]
    return [options[0], "/tmp/reference.ply"]  # a path


KNOBS = leaves(PlanSettings)
"""Every leaf of the plan settings, e.g. (("camera", "width"), 320, int)."""
PLAN_FLAGS = flags(PlanConfig)
OPTIONS = {path: next(o for dest, o in PLAN_FLAGS.items() if dest.replace("-", "_").endswith(".".join(path)))
           for path, _, _ in KNOBS}
"""Each leaf's flags, as `nbv plan` spells them (the flat names every command shares)."""


def online_plans(config: OnlineConfig) -> list[PlanConfig]:
    return [task.kwargs["config"] for one in comparisons(config) for task in plan_units(one.study())]


COMMANDS = {
    "compare": (CompareConfig, ["test_building", "--out", "cmp"],
                lambda c: [t.kwargs["config"] for t in plan_units(c.study())], {("full_scan",)}),
    "online": (OnlineConfig, ["--out", "online"], online_plans, {("full_scan",)}),
    "budget": (BudgetConfig, [], lambda c: [t.kwargs["config"] for t in plan_units(c.study(Path("runs")))],
               set()),
    "tables": (PaperConfig, [], lambda c: [t.kwargs["config"] for t in
                                           plan_units(budget_config(c).study(Path("runs")))],
               {("bov", "ranges"), ("bov", "words"), ("bov", "elevation_bands"), ("reference",),
                ("full_scan",), ("links", "min_matches"), ("links", "link_neighbours"), ("blank_images",)}),
    # --ranges and --words are Table 2's grid; the curves score the truth; --min-matches and the blank-image
    # test are not tables flags
    "demo": (DemoConfig, [], lambda c: [t.kwargs["config"] for t in
                                        plan_units(online_study(c, Path("demo"), "policy", c.policy, None))],
             {path for path, _, _ in KNOBS if path[0] in ("bov", "candidates", "occupancy", "reference",
                                                          "full_scan", "links", "blank_images")}),
    # policy and random read none but the blank-image test, which the demo does not run; the demo's
    # --min-matches is its refinement's (DemoConfig.links)
}
"""Per study command: its config, the arguments it needs, the plan configs of the runs it makes, and the
plan knobs that do not apply to it."""


def takes(run: PlanConfig, path: tuple[str, ...]) -> bool:
    """Whether the run's planner reads the knob: --min-matches reaches the planners choosing among
    candidates only (a study's fixed patterns fly their views)."""
    return path[0] != "links" or "links" in entry(run.planner).settings


@pytest.mark.parametrize("command", list(COMMANDS))
def test_every_plan_knob_is_a_flag_of_every_study_command_and_reaches_its_runs(command):
    cls, needed, plans_of, excluded = COMMANDS[command]
    options = {o for group in flags(cls).values() for o in group}
    base = plans_of(parse(cls, needed, command))[0].settings
    knobs = [(path, other_value(leaf(base, path), hint, OPTIONS[path])) for path, _, hint in KNOBS
             if path not in excluded]
    assert [tokens[0] for _, tokens in knobs if tokens[0] not in options] == []
    given = [token for _, tokens in knobs for token in tokens]  # every knob off its default at once
    expected = parse(PlanConfig, ["test_building", "--out", "x", *given], "plan").settings
    runs = plans_of(parse(cls, [*needed, *given], command))
    missed = [" ".join(tokens) for path, tokens in knobs
              if leaf(expected, path) == leaf(base, path)
              or any(leaf(run.settings, path) != leaf(expected, path) for run in runs if takes(run, path))]
    assert missed == [] and len(knobs) > 15


# --- (b) a registered toy planner runs through every study ----------------------------------------------

class ToyPlanner(Planner):
    """A fixed arc of views: a planner from outside the toolkit, registered by this test."""

    name = "toy"

    def plan(self, world, views: int | None) -> list[Viewpoint]:
        return [Viewpoint(2.0, 0.7 * k, 0.5) for k in range(views or 3)]


def toy_planner(settings: PlanSettings, seed: int, checkpoint: str | None) -> ToyPlanner:
    return ToyPlanner()


@pytest.fixture
def toy():
    yield register(PlannerEntry("toy", "a fixed arc of views (a test's planner)", f"{__name__}:toy_planner"))
    registry.unregister("toy")


TINY = replace(SETTINGS, camera=UAVCamera(64, 48), render=RenderSettings(spp=1),
               metrics=MetricsConfig(n_points=3000))


@pytest.mark.slow
def test_a_registered_toy_planner_runs_through_compare_online_and_the_budget_curves(tmp_path, toy):
    reference = tmp_path / "reference.ply"  # the true mesh as the full scan: nothing to render for it
    load_scene("test_building").target_mesh().export(reference)
    scored = replace(TINY, full_scan=True, reference=reference)
    table = compare_planners(CompareConfig(scene=SceneSpec(scene="test_building"), views=3, planners=("toy",),
                                           seeds=(0,), settings=scored, out=tmp_path / "cmp"))
    assert "| toy (1 seeds) | 3.0 |" in table
    viewpoints = json.loads((tmp_path / "cmp" / "toy-seed0" / "plan.json").read_text())["viewpoints"]
    assert viewpoints == [[2.0, 0.7 * k, 0.5] for k in range(3)]
    text = run_online(OnlineConfig(out=tmp_path / "online", scenes=("test_building",), policies=("toy",),
                                   depth_options=(), baselines=("random",), seeds=(0,), views=3,
                                   settings=scored))
    assert "| test_building | " in text and "| test_building (toy) | 3.0 |" in text
    assert "toy" in BudgetConfig().planners  # a registered planner joins the budget study's defaults
    rows = run_budget(BudgetConfig(out=tmp_path / "budget", scenes=("test_building",), planners=("toy",),
                                   seeds=(0,), budgets=(2, 3), settings=TINY))
    toy_row = next(r for r in rows["visible"] if r["scene"] == "test_building")
    assert toy_row["planner"] == "toy" and len(toy_row["mean"]) == 2 and 0 < toy_row["mean"][0] <= 100
