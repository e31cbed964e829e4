"""One planner study: planners x seeds x buildings x view budgets, under one set of plan settings.

`nbv compare`, `nbv online`, the budget curves of `nbv tables` and the demo's online half are presets of
`PlannerStudy`: each command keeps its own flags and output files, and every run it makes is an `nbv plan`
run (`plan_scan`) built here from the study's one nested `PlanSettings`, so a knob added there reaches all
of them. Planner names, labels and whether a planner's shorter plans are prefixes of its longer ones come
from the registry (`nbv.planning.registry`).

The study's units run in stages (`study_stages`, through `nbv.fanout.run_stages`, so `--workers` and `--ray`
spread them): each building's full-scan reference first, when the runs are scored against it (one unit per
building, always run: it is cached); then the plan runs (`plan_units`), one per building, planner, seed and
planned budget, each done once its `plan.json` exists; then, for a budget curve (`curves`), the scoring of
each run at its budgets (`score_run`). On a curve a sequential planner (its entry's `prefixes`) is planned
once, at the largest budget, and its prefixes are scored as its shorter plans; the others are planned
afresh at every budget. `study_runs` reads the runs back, one `StudyRun` per building, planner, seed and
budget.
"""

from __future__ import annotations

import json
import string
from collections.abc import Sequence
from dataclasses import dataclass, replace
from pathlib import Path

from common.io import write_json
from nbv.fanout.config import ExecutorConfig
from nbv.fanout.executor import run_stages
from nbv.fanout.task import Task
from nbv.planning.config import PlanConfig, PlanSettings
from nbv.planning.plan import plan_scan, reference_mesh, reference_settings
from nbv.planning.registry import entry, planner_label
from nbv.recon.fused_coverage import as_stored
from nbv.recon.metrics import evaluate_surfaces, load_geometry
from nbv.recon.tsdf import reconstruct_dataset
from nbv.recon.visibility import scene_visibility
from nbv.sfm.config import LinkSettings, SfmOption
from render.dataset import read_dataset
from render.viewpoint import Viewpoint, viewpoint_to_c2w
from scenes.spec import MeshOrientation, SceneSpec

OWN_COUNT = None
"""A budget meaning the planner's own view count: a policy's one pass, the whole hemisphere, else 13."""
RUN_FIELDS = ("scene", "planner", "views", "seed")
"""The placeholders of a study's `runs` template."""


@dataclass(frozen=True, kw_only=True)
class PlannerStudy(MeshOrientation, SfmOption):
    """Planners x seeds x buildings x view budgets, every run under the same plan settings (with --sfm
    every plan run also runs structure from motion on its views: `SfmOption`)."""

    scenes: tuple[str, ...]
    """Buildings: built-in names, random:SEED or mesh files (read with `up_axis`)."""
    planners: tuple[str, ...]
    """Planner specs (`nbv.planning.registry`), e.g. random, greedy, policy:CHECKPOINT."""
    seeds: tuple[int, ...]
    """Seeds per planner and building (planner, start view, renders, metric samples)."""
    budgets: tuple[int | None, ...] = (OWN_COUNT,)
    """View counts; `OWN_COUNT` (None) for the planner's own count (a policy's one pass)."""
    curves: bool = False
    """Score every run at its budgets (scores.json: coverage as reconstructed and as seen), planning a
    sequential planner once at the largest budget and scoring its prefixes."""
    settings: PlanSettings = PlanSettings()
    """What every run shares: camera, rendering, Bag of Views, candidates, grid, references, scoring."""
    out: Path
    """Folder of the runs."""
    runs: str = "{planner}-seed{seed}"
    """A run's folder under `out`: a template of {scene} (file-name safe), {planner} (its label), {views}
    ('own' for the planner's own count) and {seed}."""
    executor: ExecutorConfig = ExecutorConfig()
    """Where the units run (it changes no number)."""

    def __post_init__(self) -> None:
        if not (self.scenes and self.planners and self.seeds and self.budgets):
            raise ValueError("a planner study needs at least one scene, planner, seed and budget")
        for planner in self.planners:
            entry(planner)  # an unknown planner fails here, naming every one
        if any(views is not None and views < 1 for views in self.budgets):
            raise ValueError(f"budgets must be >= 1 (or None: the planner's own count), got {self.budgets}")
        if self.curves and (None in self.budgets or list(self.budgets) != sorted(set(self.budgets))):
            raise ValueError(f"a budget curve's budgets must be distinct view counts, ascending, got "
                             f"{self.budgets}")
        unknown = {name for _, name, _, _ in string.Formatter().parse(self.runs) if name} - set(RUN_FIELDS)
        if unknown:
            raise ValueError(f"runs may name {', '.join(RUN_FIELDS)}, not {', '.join(sorted(unknown))}")


@dataclass(frozen=True)
class StudyRun:
    """One run's record: building, planner spec, seed and budget, and the folder of the plan holding it."""

    scene: str
    planner: str
    seed: int
    views: int | None
    folder: Path

    @property
    def label(self) -> str:
        """The planner's file-name-safe label (`planner_label`)."""
        return planner_label(self.planner)

    def plan(self) -> dict:
        """The run's `plan.json` document (its views, metrics against `gt` and `reference`, timings)."""
        return json.loads((self.folder / "plan.json").read_text())

    def score(self, measure: str) -> float:
        """A measure of `score_run` (`coverage` or `visible`, fractions) at this run's budget."""
        return json.loads((self.folder / "scores.json").read_text())[str(self.views)][measure]


def scene_folder(scene: str) -> str:
    """A file-name-safe folder name of a scene (random:5 -> random_5)."""
    return Path(scene.replace(":", "_")).name


def run_folder(study: PlannerStudy, scene: str, planner: str, seed: int, views: int | None) -> Path:
    """The `nbv plan` output folder of one run: `out / runs` with the run's fields filled in."""
    name = study.runs.format(scene=scene_folder(scene), planner=planner_label(planner),
                             views="own" if views is None else views, seed=seed)
    return Path(study.out) / name


def planned_budgets(study: PlannerStudy, planner: str) -> tuple[int | None, ...]:
    """The budgets `planner` is planned at: on a curve a sequential planner's largest only, else all."""
    return study.budgets[-1:] if study.curves and entry(planner).prefixes else study.budgets


def scene_spec(study: PlannerStudy, scene: str) -> SceneSpec:
    """A building of the study, read with its up axis."""
    return SceneSpec(scene=scene, up_axis=study.up_axis)


def planner_settings(settings: PlanSettings, planner: str) -> PlanSettings:
    """`settings` for one planner: `--min-matches` reaches the planners that choose among candidates only
    (fixed patterns fly their views, and `nbv plan` refuses them the flag)."""
    return settings if "links" in entry(planner).settings else replace(settings, links=LinkSettings())


def plan_config(study: PlannerStudy, scene: str, planner: str, seed: int, views: int | None) -> PlanConfig:
    """The `nbv plan` run of one building, planner, seed and budget under the study's settings
    (`planner_settings`)."""
    settings = planner_settings(study.settings, planner)
    return PlanConfig(scene=scene_spec(study, scene), views=views, planner=planner, seed=seed,
                      out=run_folder(study, scene, planner, seed, views), overwrite=True,
                      settings=settings, sfm=study.sfm, sfm_settings=study.sfm_settings)


def reference_units(study: PlannerStudy) -> list[Task]:
    """Each building's full-scan reference (cached, so always run), when the runs are scored against it; one
    task for every study with the settings it reads (`reference_settings`)."""
    if not study.settings.full_scan:
        return []
    settings = reference_settings(study.settings)
    return [Task(f"full-scan reference of {scene}", reference_mesh,
                 {"scene": scene_spec(study, scene), "settings": settings}) for scene in study.scenes]


def plan_result(config: PlanConfig) -> Path:
    """The file whose presence marks a plan run done: its plan.json, or with --sfm its sfm/sfm.json (written
    with it), so a run made without SfM is redone with it."""
    return config.out / "sfm" / "sfm.json" if config.sfm else config.out / "plan.json"


def plan_units(study: PlannerStudy) -> list[Task]:
    """One `plan_scan` per building, planner, seed and planned budget, done once its `plan_result` exists."""
    units = []
    for scene in study.scenes:
        for planner in study.planners:
            for seed in study.seeds:
                for views in planned_budgets(study, planner):
                    config = plan_config(study, scene, planner, seed, views)
                    units.append(Task(f"{config.out.name} in {config.out.parent}", plan_scan,
                                      {"config": config}, plan_result(config)))
    return units


def score_units(study: PlannerStudy) -> list[Task]:
    """On a budget curve, each plan run's scoring at the budgets it holds (`score_run`)."""
    if not study.curves:
        return []
    units = []
    for plan in plan_units(study):
        config = plan.kwargs["config"]
        views = study.budgets if entry(config.planner).prefixes else (config.views,)
        units.append(Task(f"scores of {config.out.name} in {config.out.parent}", score_run,
                          {"folder": config.out, "views": views, "settings": study.settings,
                           "scene": config.scene, "seed": config.seed}, config.out / "scores.json"))
    return units


def study_stages(study: PlannerStudy) -> list[list[Task]]:
    """The study's units in the order they must run: references, plan runs, prefix scores."""
    return [reference_units(study), plan_units(study), score_units(study)]


def run_studies(studies: Sequence[PlannerStudy], executor: ExecutorConfig = ExecutorConfig()) -> None:
    """Run the units of several studies at once, stage by stage (their shared references once); nothing
    runs when every plan and score is already on disk."""
    stages = [[task for study in studies for task in study_stages(study)[k]] for k in range(3)]
    if not all(task.done() for stage in stages[1:] for task in stage):
        run_stages(stages, executor)


def study_runs(study: PlannerStudy) -> list[StudyRun]:
    """Every run's record, by building, planner, seed and budget (a prefix points at the plan holding it)."""
    runs = []
    for scene in study.scenes:
        for planner in study.planners:
            planned = planned_budgets(study, planner)
            for seed in study.seeds:
                for views in study.budgets:
                    plan = views if views in planned else planned[-1]
                    runs.append(StudyRun(scene, planner, seed, views,
                                         run_folder(study, scene, planner, seed, plan)))
    return runs


def run_study(study: PlannerStudy) -> list[StudyRun]:
    """Run (or read back) every unit of `study` on its executor; return its runs' records."""
    run_studies([study], study.executor)
    return study_runs(study)


def score_run(folder: Path, views: tuple[int, ...], settings: PlanSettings, scene: SceneSpec,
              seed: int) -> None:
    """Write `folder/scores.json`: for each k in `views`, the coverage of the true surface by the first k
    views of the run in `folder`, as reconstructed (TSDF, within the metric threshold; the run's own score
    at its full length) and as seen (an ideal sensor: the share of true-surface samples some view
    sees, `nbv.recon.visibility`)."""
    plan = json.loads((folder / "plan.json").read_text())
    target = scene.load()
    poses = [viewpoint_to_c2w(Viewpoint(*v), target.center()) for v in plan["viewpoints"]]
    visibility = scene_visibility(target, settings.camera, seed=seed)
    dataset, gt = read_dataset(folder / "views"), load_geometry(folder / "gt.ply", "gt")
    metrics, scores = replace(settings.metrics, seed=seed), {}
    for k in views:
        if k == len(poses):
            covered = plan["gt"]["coverage"]
        else:
            # scored as its mesh.ply would be (float32), as `nbv plan` scores the full run
            mesh = as_stored(reconstruct_dataset(dataset, settings.recon, range(k)).mesh)
            covered = evaluate_surfaces(mesh, {"gt": gt}, metrics)["gt"].coverage
        scores[str(k)] = {"coverage": covered, "visible": visibility.coverage(poses[:k])}
    write_json(folder / "scores.json", scores)
