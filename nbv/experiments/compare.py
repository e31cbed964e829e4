"""`nbv compare`: planners over seeds on one (held-out) scene, beside the paper's Fig. 1.

Every run is an `nbv plan` run (`nbv.planning.plan.plan_scan`) under the same
shared settings; the table gives views, coverage, Chamfer and Hausdorff
distances against the full-scan reference and the ground truth, mean +- std
over seeds (docs/rl.md §10). Example (paper_results/planners):

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

import json
from dataclasses import dataclass, fields
from pathlib import Path
from typing import Annotated

import numpy as np
from tyro.conf import arg

from common.io import atomic_folder, write_json, write_text
from common.provenance import config_record, git_commit
from nbv.experiments.paper_numbers import FIG1_NBV
from nbv.fanout.config import ExecutorConfig
from nbv.fanout.executor import run_stages
from nbv.fanout.task import Task
from nbv.planning.config import PlanConfig, PlanSettings
from nbv.planning.plan import plan_scan, reference_mesh
from nbv.planning.registry import entry, planner_label, planner_specs
from nbv.viz.figures import plot_planner_comparison
from scenes.spec import SceneSpec

OUTPUTS = ("comparison.json", "comparison.md", "comparison.png")
"""What `nbv compare` writes into `--out` together, beside the run folders."""


@dataclass(frozen=True, kw_only=True)
class CompareConfig(PlanSettings):
    """Settings of `nbv compare`: every `nbv plan` setting but the planner and seed, which it varies."""

    scene: SceneSpec
    """The target."""
    views: int | None = None
    """Number of views; default: the policy's episode, the whole hemisphere, or 13 (paper Fig. 1)."""
    planners: Annotated[tuple[str, ...], arg(help=f"Planners to compare: {planner_specs()}.")] = (
        "random", "circle", "greedy")
    seeds: tuple[int, ...] = (0, 1, 2)
    """Seeds per planner."""
    out: Path
    """Folder of the runs (<planner label>-seed<seed>/, each an `nbv plan` output) and of
    comparison.{json,md,png}; runs already there are read back, not redone."""
    executor: ExecutorConfig = ExecutorConfig()
    """Where the runs run: this process, local workers or Ray (not recorded: it changes no number)."""

    def __post_init__(self) -> None:
        if not self.planners or not self.seeds:
            raise ValueError("a comparison needs at least one planner and one seed")
        if not self.full_scan:
            raise ValueError("a comparison scores against the full scan too: leave out --no-full-scan")
        for planner in self.planners:
            entry(planner)  # an unknown planner fails here, naming every one

    def settings(self) -> PlanSettings:
        """The plan settings every run of the comparison shares."""
        return PlanSettings(**{f.name: getattr(self, f.name) for f in fields(PlanSettings)})

    def plan_config(self, planner: str, seed: int, out: Path, overwrite: bool = False) -> PlanConfig:
        """The `nbv plan` run of one planner and seed under these settings."""
        return PlanConfig(scene=self.scene, views=self.views, planner=planner, seed=seed, out=out,
                          overwrite=overwrite, settings=self.settings())


COMPARED = (("coverage", "reference", 100.0, "coverage % (ref)"),
            ("chamfer_cm", "reference", 1.0, "Chamfer cm (ref)"),
            ("hausdorff_cm", "reference", 1.0, "Hausdorff cm (ref)"),
            ("coverage", "gt", 100.0, "coverage % (gt)"),
            ("chamfer_cm", "gt", 1.0, "Chamfer cm (gt)"),
            ("hausdorff_cm", "gt", 1.0, "Hausdorff cm (gt)"))
"""Table columns: (metric, against, display scale, header). The paper's Fig. 1 compares with the full scan
(`reference`); the same metrics against the ground-truth mesh (`gt`) follow."""


def run_folder(config: CompareConfig, planner: str, seed: int) -> Path:
    """The `nbv plan` output folder of one planner and seed: `out/<planner label>-seed<seed>`."""
    return Path(config.out) / f"{planner_label(planner)}-seed{seed}"


def comparison_tasks(config: CompareConfig) -> tuple[list[Task], list[Task]]:
    """The comparison's units, in two stages: making the full-scan reference (one unit, always run: it is
    cached), then one `plan_scan` per planner and seed, done once its `plan.json` exists."""
    # The reference depends on neither the view count nor the planner: one unit per scene and settings.
    reference = Task(f"full-scan reference of {config.scene.scene}", reference_mesh,
                     {"scene": config.scene, "settings": config.settings()})
    runs = []
    for planner in config.planners:
        for seed in config.seeds:
            folder = run_folder(config, planner, seed)
            runs.append(Task(f"{folder.name} in {folder.parent}", plan_scan,
                             {"config": config.plan_config(planner, seed, folder, overwrite=True)},
                             folder / "plan.json"))
    return [reference], runs


def compare_planners(config: CompareConfig) -> str:
    """Run `plan_scan` for every planner and seed; write comparison.{json,md,png}; return the table.

    Each run goes to `out/<label>-seed<seed>/` (`planner_label`); runs already there are read back.
    The table gives mean +- std over seeds beside the paper's Fig. 1 (13 views, SAC policy).
    """
    out = Path(config.out)
    reference, plans = comparison_tasks(config)
    if not all(task.done() for task in plans):
        run_stages([reference, plans], config.executor)
    runs = []
    for planner in config.planners:
        for seed in config.seeds:
            doc = json.loads((run_folder(config, planner, seed) / "plan.json").read_text())
            runs.append({"planner": planner_label(planner), "seed": seed,
                         **{k: doc[k] for k in ("views", "gt", "reference", "planning_s", "deciding_s")}})
    scene = config.scene.scene
    table = comparison_table(runs, scene, config.metrics.threshold_cm)
    record = config_record(config, omit=("executor",))
    with atomic_folder(out, overwrite=True, outputs=OUTPUTS) as folder:
        write_text(folder / "comparison.md", table)
        plot_planner_comparison(runs, FIG1_NBV, folder / "comparison.png",
                                f"Planners on {Path(scene).name}, {len(config.seeds)} seeds")
        write_json(folder / "comparison.json", {
            "scene": scene, "seeds": list(config.seeds), "planners": list(config.planners),
            "commit": git_commit(), "config": record, "runs": runs, "paper_fig1": FIG1_NBV})
    return table


def comparison_table(runs: list[dict], scene: str, threshold_cm: float) -> str:
    """A Markdown table, one row per planner (mean +- std over its runs), the paper's Fig. 1 last."""
    header = ["planner", "views", *(label for *_, label in COMPARED)]
    lines = [f"Planners on {scene}: mean ± std over seeds; coverage within {threshold_cm:g} cm; "
             "ref = the full 288-view scan's reconstruction, gt = the ground-truth mesh", "",
             "| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    for planner in dict.fromkeys(r["planner"] for r in runs):
        mine = [r for r in runs if r["planner"] == planner]
        cells = [f"{planner} ({len(mine)} seeds)", _mean_std([r["views"] for r in mine], "{:.1f}")]
        for metric, against, scale, _ in COMPARED:
            cells.append(_mean_std([scale * r[against][metric] for r in mine], "{:.2f}"))
        lines.append("| " + " | ".join(cells) + " |")
    paper = [f"{scale * FIG1_NBV[metric]:.2f}" if against == "reference" else "-"
             for metric, against, scale, _ in COMPARED]
    lines.append("| paper Fig. 1 (SAC policy, vs 288-view scan) | 13 | " + " | ".join(paper) + " |")
    return "\n".join(lines) + "\n"


def _mean_std(values: list[float], fmt: str) -> str:
    arr = np.asarray(values, dtype=np.float64)
    return f"{fmt.format(arr.mean())} ± {fmt.format(arr.std())}" if len(arr) > 1 else fmt.format(arr.mean())
