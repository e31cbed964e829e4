"""Coverage against view budget: every planner at 5, 9, 13 and 20 views on the held-out buildings.

A sequential planner's plan for the largest budget holds its shorter plans (each
view depends only on the views before it): random, greedy, information gain and
the policy plan once, at the largest budget, and every prefix is fused and
scored. The circle spreads its views over the whole ring and the oracle swaps
views to better the whole set, so they plan afresh at every budget. Runs are
`nbv plan` folders scored against the ground truth only (no full scan), kept in
a cache folder keyed by the settings and the commit (an interrupted run
resumes; a new commit measures afresh). Each plan, then each plan's prefix
scoring, is a unit of work (`nbv.fanout`), so `--workers` / `--ray` spread them.
The area under each curve is the mean coverage over the budget range
(trapezoid rule, `coverage_auc`).
"""

from __future__ import annotations

import json
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import numpy as np

from common.io import atomic_folder, markdown_table, write_json, write_text
from common.provenance import config_record, git_commit, run_cache
from nbv.experiments.online import scene_folder
from nbv.fanout.config import ExecutorConfig
from nbv.fanout.executor import run_stages
from nbv.fanout.task import Task
from nbv.planning.config import PlanConfig, PlanSettings
from nbv.planning.plan import plan_scan
from nbv.planning.registry import budget_planners, planner_label, replanned
from nbv.recon.config import MetricsConfig, ReconstructionConfig
from render.camera import UAVCamera
from render.settings import RenderSettings
from scenes.spec import SceneSpec

BUDGETS = (5, 9, 13, 20)
"""View budgets of the curve (the paper's Fig. 1 count, 13, among them)."""
PLANNERS = budget_planners()
"""Every planner of the harness (policy: the shipped one; the registry's `budget` entries); the oracle is
an upper bound."""
REPLANNED = tuple(name for name in replanned() if name in PLANNERS)
"""Planners whose shorter plans are not prefixes of their longer ones: planned at every budget."""
OUTPUTS = ("budget.md", "budget.json", "budget.png")
"""What a budget study writes into its `out` together."""


@dataclass(frozen=True, kw_only=True)
class BudgetConfig:
    """Settings of the coverage-against-budget study."""

    out: Path = Path("paper_results/budget")
    """Folder for budget.{md,json,png}."""
    scenes: tuple[str, ...] = ("alpine_chalet", "imperial_temple")
    """Buildings (held out from training: nothing here tunes anything)."""
    planners: tuple[str, ...] = PLANNERS
    """Planners to compare (policy:CHECKPOINT for a policy other than the shipped one)."""
    seeds: tuple[int, ...] = (0, 1, 2)
    """Seeds per planner and building."""
    budgets: tuple[int, ...] = BUDGETS
    """View budgets, ascending."""
    camera: UAVCamera = UAVCamera()
    """The camera of the captured views."""
    render: RenderSettings = RenderSettings()
    """How views are rendered."""
    recon: ReconstructionConfig = ReconstructionConfig()
    """TSDF fusion of every plan and prefix."""
    metrics: MetricsConfig = MetricsConfig(n_points=200_000)
    """How reconstructions are scored against the ground truth."""
    executor: ExecutorConfig = ExecutorConfig()
    """Where the runs run: this process, local workers or Ray (it changes no number)."""

    def __post_init__(self) -> None:
        if not (self.scenes and self.planners and self.seeds and self.budgets):
            raise ValueError("a budget study needs at least one scene, planner, seed and budget")
        if list(self.budgets) != sorted(set(self.budgets)) or self.budgets[0] < 1:
            raise ValueError(f"budgets must be distinct, ascending and >= 1, got {self.budgets}")


def coverage_auc(budgets: tuple[int, ...], coverage: list[float]) -> float:
    """Mean coverage over [first, last budget]: the trapezoid area under the curve over its width (the one
    value when there is one budget).

    Example:
        >>> coverage_auc((5, 9, 13), [40.0, 60.0, 80.0])
        60.0
    """
    if len(budgets) == 1:
        return float(coverage[0])
    b, c = np.asarray(budgets, dtype=float), np.asarray(coverage, dtype=float)
    return float(np.sum((c[1:] + c[:-1]) * np.diff(b)) / 2.0 / (b[-1] - b[0]))


def plan_config(config: BudgetConfig, scene: str, planner: str, seed: int, views: int, folder: Path):
    """The `nbv plan` run of one planner, seed and budget, into `folder`, scored against the truth only."""
    settings = PlanSettings(camera=config.camera, render=config.render, full_scan=False,
                            metrics=config.metrics, recon=config.recon)
    return PlanConfig(scene=SceneSpec(scene=scene), views=views, planner=planner, seed=seed, out=folder,
                      overwrite=True, settings=settings)


def score_run(folder: Path, views: tuple[int, ...], config: BudgetConfig, scene: str, seed: int) -> None:
    """Write `folder/scores.json`: for each k in `views`, the coverage of the true surface by the first k
    views of the run in `folder`, as reconstructed (TSDF, within the metric threshold; the run's own score
    at its full length) and as seen (the oracle's measure: the share of true-surface samples some view
    sees, `nbv.recon.visibility`)."""
    from nbv.recon.metrics import evaluate_surfaces, load_geometry
    from nbv.recon.tsdf import reconstruct_dataset
    from nbv.recon.visibility import scene_visibility
    from render.dataset import read_dataset
    from render.viewpoint import Viewpoint, viewpoint_to_c2w

    plan = json.loads((folder / "plan.json").read_text())
    target = SceneSpec(scene=scene).load()
    poses = [viewpoint_to_c2w(Viewpoint(*v), target.center()) for v in plan["viewpoints"]]
    visibility = scene_visibility(target, config.camera, seed=seed)
    dataset, gt = read_dataset(folder / "views"), load_geometry(folder / "gt.ply", "gt")
    metrics, scores = replace(config.metrics, seed=seed), {}
    for k in views:
        if k == len(poses):
            covered = plan["gt"]["coverage"]
        else:
            mesh = reconstruct_dataset(dataset, config.recon, range(k)).mesh
            covered = evaluate_surfaces(mesh, {"gt": gt}, metrics)["gt"].coverage
        scores[str(k)] = {"coverage": covered, "visible": visibility.coverage(poses[:k])}
    write_json(folder / "scores.json", scores)


def _folder(runs: Path, scene: str, planner: str, seed: int, views: int) -> Path:
    return runs / scene_folder(scene) / f"{planner_label(planner)}-v{views}-seed{seed}"


def budget_tasks(config: BudgetConfig, runs: Path) -> tuple[list[Task], list[Task]]:
    """The study's units in two stages: every `nbv plan` run (replanned planners at every budget, the
    others at the largest), then the scoring of each run at its budgets (a sequential plan's prefixes)."""
    plans, scores = [], []
    for scene in config.scenes:
        for planner in config.planners:
            for seed in config.seeds:
                replanned = planner in REPLANNED
                for views in (config.budgets if replanned else config.budgets[-1:]):
                    folder = _folder(runs, scene, planner, seed, views)
                    plans.append(Task(f"{folder.name} on {scene}", plan_scan,
                                      {"config": plan_config(config, scene, planner, seed, views, folder)},
                                      folder / "plan.json"))
                    scores.append(Task(f"scores of {folder.name} on {scene}", score_run,
                                       {"folder": folder, "views": (views,) if replanned else config.budgets,
                                        "config": config, "scene": scene, "seed": seed},
                                       folder / "scores.json"))
    return plans, scores


def planner_curve(config: BudgetConfig, scene: str, planner: str, seed: int, runs: Path,
                  measure: str = "coverage") -> list[float]:
    """One measure (`coverage` or `visible`, fractions) at each budget of one planner and seed on one
    building, read back from its runs."""
    def scores(views: int) -> dict[str, dict[str, float]]:
        return json.loads((_folder(runs, scene, planner, seed, views) / "scores.json").read_text())

    if planner in REPLANNED:
        return [scores(b)[str(b)][measure] for b in config.budgets]
    top = scores(config.budgets[-1])
    return [top[str(b)][measure] for b in config.budgets]


MEASURES = (("coverage", "Coverage (%) of the true surface by the TSDF reconstruction"),
            ("visible", "Visible coverage (%): true-surface samples some view sees (the oracle's measure)"))
"""The study's measures: (key in scores.json, what it is)."""


def run_budget(config: BudgetConfig) -> dict[str, list[dict[str, Any]]]:
    """Every planner's curves on every building and seed; writes budget.{md,json,png}; returns the rows per
    measure (building, planner, per-budget mean and std in %, AUC)."""
    from nbv.viz.paper import plot_budget_curves

    runs = run_cache("budget", config, unkeyed=("out", "scenes", "planners", "seeds", "executor"))
    run_stages(budget_tasks(config, runs), config.executor)
    curves = {measure: {(scene, planner_label(p)): [[100.0 * c for c in planner_curve(config, scene, p, seed,
                                                                                     runs, measure)]
                                                    for seed in config.seeds]
                        for scene in config.scenes for p in config.planners}
              for measure, _ in MEASURES}
    rows = {measure: budget_rows(curves[measure], config.budgets) for measure, _ in MEASURES}
    record = config_record(config, omit=("executor",))
    with atomic_folder(config.out, overwrite=True, outputs=OUTPUTS) as out:
        write_text(out / "budget.md", budget_markdown(rows, config))
        plot_budget_curves(rows, config.budgets, out / "budget.png")
        write_json(out / "budget.json", {
            "commit": git_commit(), "config": record, "rows": rows,
            "curves": {m: {f"{s}/{p}": c for (s, p), c in by.items()} for m, by in curves.items()}})
    return rows


def budget_rows(curves: dict[tuple[str, str], list[list[float]]], budgets: tuple[int, ...]) -> list[dict]:
    """Per building and planner, then per planner over all buildings ('mean'): coverage mean and std (over
    seeds, then over buildings' seed means) at each budget, and the AUC of the mean curve."""
    rows = []
    for (scene, planner), seeds in curves.items():
        values = np.asarray(seeds)
        rows.append({"scene": scene, "planner": planner, "mean": values.mean(0).tolist(),
                     "std": values.std(0).tolist()})
    for planner in dict.fromkeys(p for _, p in curves):
        means = np.asarray([r["mean"] for r in rows if r["planner"] == planner])
        rows.append({"scene": "mean", "planner": planner, "mean": means.mean(0).tolist(),
                     "std": means.std(0).tolist()})
    for row in rows:
        row["auc"] = coverage_auc(budgets, row["mean"])
    return rows


def budget_markdown(rows: dict[str, list[dict]], config: BudgetConfig) -> str:
    """The tables, one per measure: each planner at each budget (mean ± std) with the AUC."""
    lines = [f"# Coverage against view budget (commit {git_commit()})", "",
             f"Mean ± std over seeds {', '.join(map(str, config.seeds))} (the 'mean' rows: over buildings); "
             f"coverage within {config.metrics.threshold_cm:g} cm. Sequential planners are scored on "
             f"prefixes of their {config.budgets[-1]}-view plan; {', '.join(REPLANNED)} plan afresh at every "
             "budget. AUC: mean over the budget range (trapezoid rule). The oracle uses the true mesh and "
             "maximises visible coverage: an upper bound of that measure, not a planner a user has."]
    for measure, title in MEASURES:
        body = [[r["scene"], r["planner"], *(f"{m:.1f} ± {s:.1f}" for m, s in zip(r["mean"], r["std"])),
                 f"{r['auc']:.1f}"] for r in rows[measure]]
        lines += ["", f"## {title}", "",
                  markdown_table(["building", "planner", *(f"{b} views" for b in config.budgets), "AUC"],
                                 body)]
    return "\n".join(lines)
