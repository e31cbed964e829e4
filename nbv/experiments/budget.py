"""Coverage against view budget: every planner at 5, 9, 13 and 20 views on the held-out buildings.

A sequential planner's plan for the largest budget holds its shorter plans (each
view depends only on the views before it): random, greedy, information gain and
the policy plan once, at the largest budget, and every prefix is fused and
scored. The circle spreads its views over the whole ring and the oracle swaps
views to better the whole set, so they plan afresh at every budget (the
registry's `prefixes`). The study is a `PlannerStudy` with `curves`
(`nbv.experiments.planner_study`) under one nested `PlanSettings`: its runs are
`nbv plan` folders, by default scored against the ground truth only (no full
scan), kept in a cache folder keyed by the settings and the commit (an
interrupted run resumes; a new commit measures afresh). Each plan, then each
plan's prefix scoring, is a unit of work (`nbv.fanout`), so `--workers` /
`--ray` spread them.
The area under each curve is the mean coverage over the budget range
(trapezoid rule, `coverage_auc`). Beside coverage: the metres flown and the
azimuth reversals at each budget, the coverage within each flight budget in
metres, and coverage against metres (`nbv.experiments.budget_flight`,
budget_metres.png).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Annotated, Any

import numpy as np
from tyro.conf import arg

from common.io import atomic_folder, markdown_table, write_json, write_text
from common.provenance import config_record, git_commit, portable_record, run_cache
from nbv.experiments.budget_flight import METRES, flight_markdown, flight_tables, seed_rows
from nbv.experiments.planner_study import PlannerStudy, StudyRun, run_study
from nbv.experiments.sfm_columns import planned_sfm_table
from nbv.fanout.config import ExecutorConfig
from nbv.planning.config import PlanSettings
from nbv.planning.registry import budget_planners, replanned
from nbv.recon.config import MetricsConfig
from nbv.sfm.config import SfmOption
from nbv.viz.paper import plot_budget_curves, plot_coverage_metres

BUDGETS = (5, 9, 13, 20)
"""View budgets of the curve (the paper's Fig. 1 count, 13, among them)."""
PLANNERS = budget_planners()
"""Every planner of the harness (policy: the shipped one; the registry's `budget` entries at import: the
config's default is read when it is made, so a planner registered later joins it); the oracle is an upper
bound."""
REPLANNED = tuple(name for name in replanned() if name in PLANNERS)
"""Planners whose shorter plans are not prefixes of their longer ones: planned at every budget."""
OUTPUTS = ("budget.md", "budget.json", "budget.png", "budget_metres.png")
"""What a budget study writes into its `out` together."""
RUNS = "{scene}/{planner}-v{views}-seed{seed}"
"""A budget run's folder in the study's cache folder."""
SETTINGS = PlanSettings(full_scan=False, metrics=MetricsConfig(n_points=200_000))
"""The plan settings of the budget curves: scored against the ground truth only, on 200k points."""


@dataclass(frozen=True, kw_only=True)
class BudgetConfig(SfmOption):
    """Settings of the coverage-against-budget study (--sfm: every plan also runs structure from motion)."""

    out: Path = Path("paper_results/budget")
    """Folder for budget.{md,json,png}."""
    scenes: tuple[str, ...] = ("alpine_chalet", "imperial_temple")
    """Buildings (held out from training: nothing here tunes anything)."""
    planners: tuple[str, ...] = field(default_factory=budget_planners)
    """Planners to compare (the registry's budget planners; policy:CHECKPOINT for a policy other than the
    shipped one)."""
    seeds: tuple[int, ...] = (0, 1, 2)
    """Seeds per planner and building."""
    budgets: tuple[int, ...] = BUDGETS
    """View budgets, ascending."""
    metres: tuple[float, ...] = METRES
    """Flight budgets, metres along the viewing shell, ascending: the coverage reached within each."""
    settings: Annotated[PlanSettings, arg(name="")] = SETTINGS
    """What every plan shares (`nbv plan`'s settings; fusion and scoring of every plan and prefix too)."""
    executor: ExecutorConfig = ExecutorConfig()
    """Where the runs run: this process, local workers or Ray (it changes no number)."""

    def __post_init__(self) -> None:
        if not (self.scenes and self.planners and self.seeds and self.budgets):
            raise ValueError("a budget study needs at least one scene, planner, seed and budget")
        if list(self.budgets) != sorted(set(self.budgets)) or self.budgets[0] < 1:
            raise ValueError(f"budgets must be distinct, ascending and >= 1, got {self.budgets}")
        if not self.metres or list(self.metres) != sorted(set(self.metres)) or self.metres[0] <= 0:
            raise ValueError(f"metres (flight budgets) must be distinct, ascending, > 0, got {self.metres}")

    def study(self, runs: Path) -> PlannerStudy:
        """The budget curves as a planner study whose runs live in `runs` (`RUNS`)."""
        return PlannerStudy(scenes=self.scenes, planners=self.planners, seeds=self.seeds,
                            budgets=self.budgets, curves=True, settings=self.settings, out=runs, runs=RUNS,
                            executor=self.executor, sfm=self.sfm, sfm_settings=self.sfm_settings)


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


MEASURES = (("coverage", "Coverage (%) of the true surface by the TSDF reconstruction"),
            ("visible", "Visible coverage (%): true-surface samples some view sees (an ideal sensor)"))
"""The study's measures: (key in scores.json, what it is)."""


def study_curves(runs: list[StudyRun], measure: str) -> dict[tuple[str, str], list[list[float]]]:
    """One measure (`coverage` or `visible`) in % per building and planner label: a curve over the budgets
    per seed, read back from the study's runs."""
    curves: dict[tuple[str, str], dict[int, list[float]]] = {}
    for run in runs:
        seeds = curves.setdefault((run.scene, run.label), {})
        seeds.setdefault(run.seed, []).append(100.0 * run.score(measure))
    return {key: list(seeds.values()) for key, seeds in curves.items()}


def run_budget(config: BudgetConfig) -> dict[str, list[dict[str, Any]]]:
    """Every planner's curves on every building and seed; writes budget.{md,json,png} and budget_metres.png;
    returns the rows per measure (building, planner, per-budget mean and std in %, AUC)."""
    cache = run_cache("budget", config, unkeyed=("out", "scenes", "planners", "seeds", "executor", "metres"))
    runs = run_study(config.study(cache))
    curves = {measure: study_curves(runs, measure) for measure, _ in MEASURES}
    rows = {measure: budget_rows(curves[measure], config.budgets) for measure, _ in MEASURES}
    flight = flight_tables(runs, curves["coverage"], config.metres)
    record = portable_record(config_record(config, omit=("executor",)))
    with atomic_folder(config.out, overwrite=True, outputs=OUTPUTS) as out:
        write_text(out / "budget.md", budget_markdown(rows, config)
                   + flight_markdown(flight, config.budgets, config.metres) + budget_sfm(runs, config))
        plot_budget_curves(rows, config.budgets, out / "budget.png")
        plot_coverage_metres(rows["coverage"], flight["flight_m"], out / "budget_metres.png")
        write_json(out / "budget.json", {
            "commit": git_commit(), "config": record, "rows": rows, "flight": flight,
            "curves": {m: {f"{s}/{p}": c for (s, p), c in by.items()} for m, by in curves.items()}})
    return rows


def budget_sfm(runs: list[StudyRun], config: BudgetConfig) -> str:
    """With --sfm, the structure-from-motion section of budget.md: one row per plan (a sequential
    planner's largest one only: its prefixes are not reconstructed); else nothing."""
    if not config.sfm:
        return ""
    return ("\n\n## Structure from motion (COLMAP) on each plan's views: views registered in the largest "
            "model per seed, models, its mean camera-centre error after a similarity fit\n\n"
            + planned_sfm_table(runs) + "\n")


def budget_rows(curves: dict[tuple[str, str], list[list[float]]], budgets: tuple[int, ...]) -> list[dict]:
    """Per building and planner, then per planner over all buildings ('mean'): coverage mean and std (over
    seeds, then over buildings' seed means) at each budget, and the AUC of the mean curve."""
    rows = seed_rows(curves)
    for row in rows:
        row["auc"] = coverage_auc(budgets, row["mean"])
    return rows


def budget_markdown(rows: dict[str, list[dict]], config: BudgetConfig) -> str:
    """The tables, one per measure: each planner at each budget (mean ± std) with the AUC."""
    lines = [f"# Coverage against view budget (commit {git_commit()})", "",
             f"Mean ± std over seeds {', '.join(map(str, config.seeds))} (the 'mean' rows: over buildings); "
             f"coverage within {config.settings.metrics.threshold_cm:g} cm. Sequential planners are scored "
             f"on prefixes of their {config.budgets[-1]}-view plan; {', '.join(REPLANNED)} plan afresh at "
             "every budget. AUC: mean over the budget range (trapezoid rule). The oracle uses the true mesh: "
             "the best, on the TSDF coverage, of the other planners' sets and its own pick (at least each "
             "of them there, by construction), not a planner a user has."]
    for measure, title in MEASURES:
        body = [[r["scene"], r["planner"], *(f"{m:.1f} ± {s:.1f}" for m, s in zip(r["mean"], r["std"])),
                 f"{r['auc']:.1f}"] for r in rows[measure]]
        lines += ["", f"## {title}", "",
                  markdown_table(["building", "planner", *(f"{b} views" for b in config.budgets), "AUC"],
                                 body)]
    return "\n".join(lines)
