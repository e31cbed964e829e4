"""`nbv compare`: planners over seeds on one (held-out) scene, beside the paper's Fig. 1.

A `PlannerStudy` preset (`nbv.experiments.planner_study`: one building, one
view budget): every run is an `nbv plan` run (`nbv.planning.plan.plan_scan`)
under the same nested `PlanSettings`, so every `nbv plan` knob is a flag; the
table gives views, coverage, Chamfer and Hausdorff distances against the
full-scan reference and the ground truth, mean +- std over seeds (docs/rl.md
§10), then the metres flown and the azimuth reversals (`nbv.flight`). Example (paper_results/planners):

    nbv compare alpine_chalet --views 13 --planners policy:runs/policy/checkpoint.pt random circle greedy \\
        --seeds 0 1 2 --out cmp

Each run is its own `nbv plan` output folder, written atomically as it finishes
(an interrupted comparison keeps the runs done). The runs are independent units
(`comparison_tasks`): `--workers N` runs them on N local processes, `--ray auto`
or `--ray ADDRESS` on Ray (`nbv.fanout`), with the same files and numbers as in
this process. The full-scan reference of the scene is made first, once, so the
runs never render it side by side. The comparison files
(`OUTPUTS`) are swapped onto `--out` together at the end (`common.io.atomic_folder`),
the run folders carried over as hard links, so they always describe the same runs.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Annotated

import numpy as np
from tyro.conf import arg

from common.io import atomic_folder, write_json, write_text
from common.provenance import config_record, git_commit, portable_record
from nbv.experiments.paper_numbers import FIG1_NBV
from nbv.experiments.planner_study import PlannerStudy, plan_units, reference_units, run_study
from nbv.experiments.sfm_columns import SFM_HEADER, sfm_cells, sfm_entry
from nbv.fanout.config import ExecutorConfig
from nbv.fanout.task import Task
from nbv.flight import prefix_flight
from nbv.planning.config import PlanSettings
from nbv.planning.registry import compared_planners, entries, planner_specs
from nbv.sfm.config import SfmOption
from nbv.viz.figures import plot_planner_comparison
from scenes.spec import SceneSpec

OUTPUTS = ("comparison.json", "comparison.md", "comparison.png")
"""What `nbv compare` writes into `--out` together, beside the run folders."""


def planners_help() -> str:
    """The `--planners` help text, from the registry."""
    bounds = ", ".join(e.name for e in entries() if e.reads_truth)
    return f"Planners to compare: {planner_specs()} ({bounds}: an upper bound, it uses the true mesh)."


@dataclass(frozen=True, kw_only=True)
class CompareConfig(SfmOption):
    """Settings of `nbv compare`: every `nbv plan` setting but the planner and seed, which it varies
    (--sfm: every run also runs structure from motion, its registration in the table)."""

    scene: SceneSpec
    """The target."""
    views: int | None = None
    """Number of views; default: the policy's episode, the whole hemisphere, or 13 (paper Fig. 1)."""
    planners: Annotated[tuple[str, ...], arg(help=planners_help())] = field(default_factory=compared_planners)
    seeds: tuple[int, ...] = (0, 1, 2)
    """Seeds per planner."""
    out: Path
    """Folder of the runs (<planner label>-seed<seed>/, each an `nbv plan` output) and of
    comparison.{json,md,png}; runs already there are read back, not redone."""
    settings: Annotated[PlanSettings, arg(name="")] = PlanSettings()
    """What every run shares (`nbv plan`'s settings)."""
    executor: ExecutorConfig = ExecutorConfig()
    """Where the runs run: this process, local workers or Ray (not recorded: it changes no number)."""

    def __post_init__(self) -> None:
        if not self.planners or not self.seeds:
            raise ValueError("a comparison needs at least one planner and one seed")
        if self.views is not None and self.views < 1:
            raise ValueError(f"views must be >= 1 (or left out for the planner's default), got {self.views}")
        if not self.settings.full_scan:
            raise ValueError("a comparison scores against the full scan too: leave out --no-full-scan")
        self.study()  # an unknown planner fails here, naming every one

    def study(self) -> PlannerStudy:
        """The comparison as a planner study: one building, one budget, every run under `out`."""
        return PlannerStudy(scenes=(self.scene.scene,), up_axis=self.scene.up_axis, planners=self.planners,
                            seeds=self.seeds, budgets=(self.views,), settings=self.settings, out=self.out,
                            executor=self.executor, sfm=self.sfm, sfm_settings=self.sfm_settings)


COMPARED = (("coverage", "reference", 100.0, "coverage % (ref)"),
            ("chamfer_cm", "reference", 1.0, "Chamfer cm (ref)"),
            ("hausdorff_cm", "reference", 1.0, "Hausdorff cm (ref)"),
            ("coverage", "gt", 100.0, "coverage % (gt)"),
            ("chamfer_cm", "gt", 1.0, "Chamfer cm (gt)"),
            ("hausdorff_cm", "gt", 1.0, "Hausdorff cm (gt)"))
"""Table columns: (metric, against, display scale, header). The paper's Fig. 1 compares with the full scan
(`reference`); the same metrics against the ground-truth mesh (`gt`) follow."""
FLOWN = (("flight_m", "{:.1f}", "flight m"), ("azimuth_reversals", "{:.1f}", "azimuth reversals"))
"""The flight columns after them: (run key, format, header); `nbv.flight`, from the start view."""


def comparison_tasks(config: CompareConfig) -> tuple[list[Task], list[Task]]:
    """The comparison's units, in two stages: making the full-scan reference (one unit, always run: it is
    cached), then one `plan_scan` per planner and seed, done once its `plan.json` exists."""
    study = config.study()
    return reference_units(study), plan_units(study)


def compare_planners(config: CompareConfig) -> str:
    """Run `plan_scan` for every planner and seed; write comparison.{json,md,png}; return the table.

    Each run goes to `out/<label>-seed<seed>/` (`planner_label`); runs already there are read back.
    The table gives mean +- std over seeds beside the paper's Fig. 1 (13 views, SAC policy).
    """
    runs = []
    for run in run_study(config.study()):
        doc = run.plan()
        runs.append({"planner": run.label, "seed": run.seed,
                     **{k: doc[k] for k in ("views", "gt", "reference", "planning_s", "deciding_s",
                                             "viewpoints")},
                     **prefix_flight(doc), **({"sfm": sfm_entry(doc["sfm"])} if config.sfm else {})})
    scene = config.scene.scene
    table = comparison_table(runs, scene, config.settings.metrics.threshold_cm)
    record = portable_record(config_record(config, omit=("executor",)))
    with atomic_folder(Path(config.out), overwrite=True, outputs=OUTPUTS) as folder:
        write_text(folder / "comparison.md", table)
        plot_planner_comparison(runs, FIG1_NBV, folder / "comparison.png",
                                f"Planners on {Path(scene).name}, {len(config.seeds)} seeds")
        write_json(folder / "comparison.json", {
            "scene": scene, "seeds": list(config.seeds), "planners": list(config.planners),
            "commit": git_commit(), "config": record, "runs": runs, "paper_fig1": FIG1_NBV})
    return table


def comparison_table(runs: list[dict], scene: str, threshold_cm: float) -> str:
    """A Markdown table, one row per planner (mean +- std over its runs), the paper's Fig. 1 last; runs
    with an `sfm` entry (--sfm) add the `SFM_HEADER` columns."""
    sfm = SFM_HEADER if runs and "sfm" in runs[0] else ()
    header = ["planner", "views", *(label for *_, label in COMPARED), *(label for *_, label in FLOWN), *sfm]
    lines = [f"Planners on {scene}: mean ± std over seeds; coverage within {threshold_cm:g} cm; "
             "ref = the full 288-view scan's reconstruction, gt = the ground-truth mesh; flight: metres "
             "along the viewing shell from the start view through the views in order", "",
             "| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    for planner in dict.fromkeys(r["planner"] for r in runs):
        mine = [r for r in runs if r["planner"] == planner]
        cells = [f"{planner} ({len(mine)} seeds)", _mean_std([r["views"] for r in mine], "{:.1f}")]
        for metric, against, scale, _ in COMPARED:
            cells.append(_mean_std([scale * r[against][metric] for r in mine], "{:.2f}"))
        cells += [_mean_std([r[key] for r in mine], fmt) for key, fmt, _ in FLOWN]
        cells += sfm_cells([r["sfm"] for r in mine]) if sfm else []
        lines.append("| " + " | ".join(cells) + " |")
    paper = [f"{scale * FIG1_NBV[metric]:.2f}" if against == "reference" else "-"
             for metric, against, scale, _ in COMPARED]
    paper += ["-"] * (len(FLOWN) + len(sfm))  # the paper counts no flight, runs no SfM
    lines.append("| paper Fig. 1 (SAC policy, vs 288-view scan) | 13 | " + " | ".join(paper) + " |")
    return "\n".join(lines) + "\n"


def _mean_std(values: list[float], fmt: str) -> str:
    arr = np.asarray(values, dtype=np.float64)
    return f"{fmt.format(arr.mean())} ± {fmt.format(arr.std())}" if len(arr) > 1 else fmt.format(arr.mean())
