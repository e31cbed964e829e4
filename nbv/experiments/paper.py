"""`make tables`: every result the paper reports, measured by our code, beside the paper's numbers.

Parts, each written onto `--out` as it finishes (an interrupted run keeps the parts done):
- `table2`: Table 2 and the Fig. 6 heat maps over seeds (`nbv.experiments.table2`);
- `sec7`: the Sec. VII summary computed from that grid (`sec7.md`, `sec7.json`);
- `episodes`: Fig. 1 and Fig. 7, the shipped policies' one-pass episodes (the default's and the paper
  preset's) on the default's training building and the two held-out presets against the full scan, 5 seeds
  (`fig1_fig7.{md,json,png}`);
- `budget`: coverage against view budget for every planner on the held-out buildings (`budget/`).
Then `README.md` maps every file in `--out` to the command, seeds, settings and commit that wrote it.
"""

from __future__ import annotations

import json
import time
from collections.abc import Callable
from dataclasses import dataclass, field, fields, replace
from pathlib import Path
from typing import Annotated, Any, Literal

import numpy as np
from tyro.conf import UseAppendAction

from common.io import atomic_folder, markdown_table, write_json, write_text
from common.provenance import config_record, git_commit, portable_record, run_cache
from nbv.bov.config import BoVRule
from nbv.bov.refine import Progress
from nbv.experiments.budget import BUDGETS, SETTINGS, BudgetConfig, run_budget
from nbv.experiments.compare import CompareConfig, compare_planners
from nbv.experiments.paper_numbers import FIG1_NBV, FIG7_GENERALISATION, SEC7_SUMMARY
from nbv.experiments.planner_study import scene_folder
from nbv.experiments.results_index import INDEX
from nbv.experiments.table2 import TablesConfig, run_tables
from nbv.planning.config import PlanSettings
from nbv.planning.registry import SHIPPED_POLICIES, budget_planners, planner_label
from nbv.recon.config import MetricsConfig, OccupancyConfig
from nbv.sfm.config import SfmOption
from nbv.viz.paper import plot_episodes
from render.camera import UAVCamera
from render.scan import HemispherePlan
from scenes.spec import SceneSpec

Part = Literal["table2", "sec7", "episodes", "budget"]
"""The parts of `make tables`, in the order they run."""
PARTS: tuple[Part, ...] = ("table2", "sec7", "episodes", "budget")
"""Every part."""
EPISODE_OUTPUTS = ("fig1_fig7.md", "fig1_fig7.json", "fig1_fig7.png")
"""What the episodes part writes into `--out`."""
SEC7_OUTPUTS = ("sec7.md", "sec7.json")
"""What the Sec. VII part writes into `--out`."""


@dataclass(frozen=True, kw_only=True)
class PaperConfig(TablesConfig, SfmOption):
    """Settings of `nbv tables` (`--quick` starts from `QUICK` instead of these defaults; --sfm: the budget
    part's plans also run structure from motion, and budget.md gains the registration columns)."""

    part: Annotated[tuple[Part, ...], UseAppendAction] = ()
    """Run only these parts (repeat --part; default: all): table2, sec7 (needs table2's files), episodes,
    budget."""
    policies: tuple[str, ...] = SHIPPED_POLICIES
    """The policies of Fig. 1 and Fig. 7, rows of their own (policy: the shipped default; policy-paper: the
    paper preset's, so the paper's method stands beside ours); the first is the budget curves' `policy`."""
    fig1_scene: str = "medieval_tavern"
    """Fig. 1's building: one the policy was trained on."""
    held_out: tuple[str, ...] = ("alpine_chalet", "imperial_temple")
    """Fig. 7's buildings and the budget curves' (held out from training)."""
    episode_seeds: tuple[int, ...] = (0, 1, 2, 3, 4)
    """Seeds of the one-pass episodes (start view, renders, metric samples)."""
    budgets: tuple[int, ...] = BUDGETS
    """View budgets of the coverage curves (their seeds are `seeds`)."""
    planners: tuple[str, ...] = field(default_factory=budget_planners)
    """Planners of the coverage curves (the registry's budget planners; policy: the shipped one)."""
    candidates: int = SETTINGS.candidates
    """The coverage curves' greedy, oracle and infogain planners: candidate viewpoints per step (`nbv plan`'s
    --candidates; their Bag of Views follows --match-cosine and the other rule flags)."""
    occupancy: OccupancyConfig = SETTINGS.occupancy
    """The coverage curves' infogain occupancy grid (`nbv plan`'s)."""
    quick: bool = False
    """A small run on the test building (one seed, 96x72): the defaults of `QUICK`."""

    def __post_init__(self) -> None:
        super().__post_init__()
        if not self.policies:
            raise ValueError("nbv tables needs at least one policy (--policies), e.g. policy policy-paper")

    @property
    def parts(self) -> tuple[Part, ...]:
        """The parts to run, in order."""
        return tuple(p for p in PARTS if p in (self.part or PARTS))


QUICK = PaperConfig(quick=True, scenes=("test_building",), seeds=(0,), ranges=(5, 9), words=(10,),
                    camera=UAVCamera(64, 48), plan=HemispherePlan(end_overlap=0.3, side_overlap=0.2),
                    metrics=MetricsConfig(n_points=10_000), fig1_scene="test_building",
                    held_out=("test_building",), episode_seeds=(0,), budgets=(3, 5))
"""`nbv tables --quick`: every part on the test building, one seed, 64x48, a 20-view full scan."""


def sec7_summary(rows: list[dict[str, Any]]) -> dict[str, Any]:
    """Sec. VII from Table 2's rows: per building and on average, views saved by refinement (1 - mean kept /
    full-scan views, %) and the change of error against the ground truth (1 - mean refined Chamfer / the
    full scan's Chamfer, %; negative: the refined sets are worse), Hausdorff likewise.

    Example:
        >>> rows = [{"scene": "a", "ranges": "-", "views": 100, "gt_chamfer_cm": 1.0, "gt_hausdorff_cm": 4.0},
        ...         {"scene": "a", "ranges": 5, "views": 30, "gt_chamfer_cm": 1.2, "gt_hausdorff_cm": 3.0}]
        >>> sec7_summary(rows)["mean"]
        {'fewer_views_pct': 70.0, 'lower_chamfer_pct': -20.0, 'lower_hausdorff_pct': 25.0}
    """
    out: dict[str, Any] = {}
    for scene in dict.fromkeys(r["scene"] for r in rows):
        full = next(r for r in rows if r["scene"] == scene and r["ranges"] == "-")
        cells = [r for r in rows if r["scene"] == scene and r["ranges"] != "-"]
        out[scene] = {
            "fewer_views_pct": round(100.0 * (1.0 - np.mean([r["views"] for r in cells]) / full["views"]), 2),
            "lower_chamfer_pct": round(100.0 * (1.0 - np.mean([r["gt_chamfer_cm"] for r in cells])
                                                / full["gt_chamfer_cm"]), 2),
            "lower_hausdorff_pct": round(100.0 * (1.0 - np.mean([r["gt_hausdorff_cm"] for r in cells])
                                                  / full["gt_hausdorff_cm"]), 2)}
    keys = ("fewer_views_pct", "lower_chamfer_pct", "lower_hausdorff_pct")
    out["mean"] = {k: round(float(np.mean([v[k] for v in out.values()])), 2) for k in keys}
    return out


def write_sec7(config: PaperConfig) -> dict[str, Any]:
    """The Sec. VII part from the Table 2 rows in `--out` (sec7.md, sec7.json)."""
    table2 = json.loads((Path(config.out) / "table2.json").read_text())
    summary = sec7_summary(table2["rows"])
    rows = [[scene, f"{v['fewer_views_pct']:.1f}", f"{v['lower_chamfer_pct']:.1f}",
             f"{v['lower_hausdorff_pct']:.1f}"] for scene, v in summary.items()]
    rows.append(["paper Sec. VII", f"{SEC7_SUMMARY['fewer_views_pct']:.1f}",
                 f"{SEC7_SUMMARY['lower_error_pct']:.1f} (error, unspecified)", "-"])
    text = "\n".join([
        "# Sec. VII: refinement against the full-coverage scan", "",
        f"From `table2.json` (commit {table2['commit']}, mean over seeds). Fewer views: 1 - mean views kept "
        "over the Table 2 grid / the full scan's views. Lower error: 1 - mean Chamfer (or Hausdorff) of the "
        "refined sets' reconstructions against the ground-truth mesh / the full scan's; negative when the "
        "refined sets are worse. The paper states its figures against the full scan's reconstruction and "
        "does not define the error; ours use the ground truth, which it did not have.", "",
        markdown_table(["building", "fewer views %", "lower Chamfer (gt) %", "lower Hausdorff (gt) %"],
                       rows)])
    with atomic_folder(config.out, overwrite=True, outputs=SEC7_OUTPUTS) as out:
        write_text(out / "sec7.md", text)
        write_json(out / "sec7.json", {"commit": git_commit(), "table2_commit": table2["commit"],
                                       "summary": summary, "paper": SEC7_SUMMARY})
    return summary


def run_episodes(config: PaperConfig) -> list[dict[str, Any]]:
    """Fig. 1 and Fig. 7: each policy's one-pass episodes on `fig1_scene` and the held-out presets, against
    the full scan; writes fig1_fig7.{md,json,png}. Returns one row per building and policy."""
    keyed = ("up_axis", "camera", "render", "recon", "metrics", "policies")  # what the episodes depend on
    runs = run_cache("episodes", config, unkeyed=tuple(f.name for f in fields(config) if f.name not in keyed))
    scenes = [(config.fig1_scene, "Fig. 1 (trained on)"),
              *((s, "Fig. 7 (held out)") for s in config.held_out if s != config.fig1_scene)]
    rows = []
    for scene, role in scenes:
        folder = runs / scene_folder(scene)
        settings = PlanSettings(camera=config.camera, render=config.render, metrics=config.metrics,
                                recon=config.recon)
        compare_planners(CompareConfig(scene=SceneSpec(scene=scene), planners=config.policies,
                                       seeds=config.episode_seeds, settings=settings, out=folder,
                                       executor=config.executor))
        episodes = json.loads((folder / "comparison.json").read_text())["runs"]
        paper = FIG1_NBV if role.startswith("Fig. 1") else FIG7_GENERALISATION.get(scene, {})
        for policy in map(planner_label, config.policies):
            mine = [r for r in episodes if r["planner"] == policy]
            rows.append({"scene": scene, "role": role, "policy": policy, "seeds": list(config.episode_seeds),
                         **_episode_stats(mine), "paper": paper})
    with atomic_folder(config.out, overwrite=True, outputs=EPISODE_OUTPUTS) as out:
        write_text(out / "fig1_fig7.md", episodes_markdown(rows, config))
        plot_episodes(rows, out / "fig1_fig7.png")
        record = portable_record(config_record(config, omit=("executor",)))
        write_json(out / "fig1_fig7.json", {"commit": git_commit(), "config": record, "rows": rows})
    return rows


def _episode_stats(episodes: list[dict[str, Any]]) -> dict[str, Any]:
    """Mean and std over seeds of views and the metrics against the full scan (ref) and the truth (gt)."""
    stats = {}
    for name, get in (("views", lambda r: r["views"]),
                      ("ref_coverage", lambda r: 100.0 * r["reference"]["coverage"]),
                      ("ref_hausdorff_cm", lambda r: r["reference"]["hausdorff_cm"]),
                      ("ref_chamfer_cm", lambda r: r["reference"]["chamfer_cm"]),
                      ("gt_coverage", lambda r: 100.0 * r["gt"]["coverage"]),
                      ("deciding_s", lambda r: r["deciding_s"])):
        values = [get(r) for r in episodes]
        stats[name], stats[f"{name}_std"] = float(np.mean(values)), float(np.std(values))
    return stats


def episodes_markdown(rows: list[dict[str, Any]], config: PaperConfig) -> str:
    """Fig. 1 and Fig. 7 as a table: ours (mean ± std over seeds) with the paper's numbers beneath each."""
    def pm(row: dict[str, Any], key: str, fmt: str) -> str:
        return f"{row[key]:{fmt}} ± {row[f'{key}_std']:{fmt}}"

    def paper(value: float | None, scale: float = 1.0) -> str:
        return "-" if value is None else f"{scale * value:.2f}"

    body = []
    for i, r in enumerate(rows):
        body.append([f"{r['scene']}: {r['role']}, ours ({r['policy']})", pm(r, "views", ".1f"),
                     pm(r, "ref_coverage", ".1f"), pm(r, "ref_hausdorff_cm", ".2f"),
                     pm(r, "ref_chamfer_cm", ".2f"), pm(r, "gt_coverage", ".1f")])
        if i + 1 < len(rows) and rows[i + 1]["scene"] == r["scene"]:
            continue  # the paper's row once, after the building's last policy
        p = r["paper"]
        body.append([f"{r['scene']}: paper {r['role'].split(' (')[0]}", p.get("views", "-"),
                     paper(p.get("coverage"), 100.0), paper(p.get("hausdorff_cm")),
                     paper(p.get("chamfer_cm")), "-"])
    return "\n".join([
        f"# Fig. 1 and Fig. 7: the policies' one pass around the target (commit {git_commit()})", "",
        f"{', '.join(f'`{p}`' for p in config.policies)}"
        + (" (the paper preset's policy is `policy-paper`)" if "policy-paper" in config.policies else "")
        + ", each "
        "acting on its mode until its episode ends (one pass, its own view count), seeds "
        f"{', '.join(map(str, config.episode_seeds))}; 'ref' is the reconstruction of the full hemisphere "
        "scan, as in the paper; 'gt' the ground-truth mesh. Paper rows are the paper's own numbers "
        "(Hatami Gazani et al. 2023, Fig. 1 and Fig. 7; '-' where it gives none).", "",
        markdown_table(["episode", "views", "coverage % (ref)", "Hausdorff cm (ref)", "Chamfer cm (ref)",
                        "coverage % (gt)"], body)])


def budget_settings(config: PaperConfig) -> PlanSettings:
    """The budget part's plan settings: the tables' camera, rendering, fusion and metrics, its Bag of Views
    rule for the greedy planner's reward, its candidates and occupancy grid; the ground truth only."""
    rule = {f.name: getattr(config.rule, f.name) for f in fields(BoVRule)}
    return replace(SETTINGS, camera=config.camera, render=config.render, recon=config.recon,
                   metrics=config.metrics, bov=replace(SETTINGS.bov, **rule), candidates=config.candidates,
                   occupancy=config.occupancy)


def budget_config(config: PaperConfig) -> BudgetConfig:
    """The budget part's settings: the held-out buildings, the tables' seeds and plan settings."""
    return BudgetConfig(out=Path(config.out) / "budget", scenes=config.held_out,
                        planners=tuple(config.policies[0] if p == "policy" else p for p in config.planners),
                        seeds=config.seeds, budgets=config.budgets, settings=budget_settings(config),
                        executor=config.executor, sfm=config.sfm, sfm_settings=config.sfm_settings)


def run_paper(config: PaperConfig, progress: Progress | None = None,
              done: Callable[[str, float], None] | None = None) -> dict[str, float]:
    """Run the chosen parts in order, then write README.md; returns each part's wall seconds.

    `progress` counts Table 2 rows; `done(part, seconds)` is called as each part finishes."""
    seconds = {}
    for part in config.parts:
        start = time.perf_counter()
        if part == "table2":
            run_tables(config, progress)
        elif part == "sec7":
            write_sec7(config)
        elif part == "episodes":
            run_episodes(config)
        else:
            run_budget(budget_config(config))
        seconds[part] = round(time.perf_counter() - start, 1)
        if done is not None:
            done(part, seconds[part])
    write_index(Path(config.out), seconds)
    return seconds


TIMINGS_JSON = "timings.json"
"""Each part's last wall seconds and commit (`part_timings`), kept beside README.md."""
SEED_KEYS = ("episode_seeds", "seeds")
"""Where a result's seeds are recorded: its config's first key present (`episode_seeds` for Fig. 1/7)."""


def _provenance(doc: dict[str, Any], file: str) -> tuple[str, str]:
    """(commit, seeds) recorded in a result's JSON document."""
    config = doc.get("config", {})
    keys = SEED_KEYS if file.startswith("fig1") else SEED_KEYS[1:]
    seeds = next((config[k] for k in keys if config.get(k)), None) or doc.get("seeds")
    return str(doc.get("commit", "-")), ", ".join(map(str, seeds)) if seeds else "-"


def part_timings(out: Path, seconds: dict[str, float]) -> dict[str, dict]:
    """Each part's wall seconds and commit, as last run: `out/timings.json` updated with this run's parts
    (a run of some parts keeps the others' last figures; a `note` kept by hand goes with its part's next
    run)."""
    path = out / TIMINGS_JSON
    timings = json.loads(path.read_text()) if path.is_file() else {}
    timings |= {part: {"seconds": s, "commit": git_commit()} for part, s in seconds.items()}
    write_json(path, timings)
    return timings


def write_index(out: Path, seconds: dict[str, float]) -> Path:
    """`out/README.md`: each result present in `out`, what it holds, the command, seeds and commit."""
    rows = []
    for result in INDEX:
        if (out / result.file.rstrip("/")).exists() and (out / result.record).is_file():
            commit, seeds = _provenance(json.loads((out / result.record).read_text()), result.file)
            rows.append([f"`{result.file}`", result.what, f"`{result.command}`", seeds, commit])
    timing = ", ".join(f"{part} {doc['seconds']:.0f} s (at {doc['commit']}"
                       + (f"; {doc['note']}" if "note" in doc else "") + ")"
                       for part, doc in part_timings(out, seconds).items())
    text = "\n".join([
        "# Results measured by this toolkit, beside the paper's", "",
        "Every number here was measured by our code in the run that wrote its file, at the commit given "
        "(the JSON beside each file holds every setting); the paper's numbers stand beside ours, labelled "
        "'paper'. `make tables` writes the first five rows in one run (`nbv tables --out paper_results`); "
        f"each part's last run took (2 shared cores): {timing}.", "",
        markdown_table(["file", "what", "written by", "seeds", "commit"], rows)])
    return write_text(out / "README.md", text)
