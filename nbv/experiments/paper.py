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
from typing import Annotated, Any, Literal, NamedTuple

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


class Result(NamedTuple):
    """A result `README.md` maps: its file, the JSON holding its commit and settings, what it holds, and
    the command that writes it."""

    file: str
    record: str
    what: str
    command: str


LOOKS_EVAL = "scripts/looks_eval.py (commands in the file)"
"""How the rounds of issue 26's choice were scored."""
INDEX = (
    Result("table2.md", "table2.json", "Table 2 (views kept, Hausdorff, Chamfer per N and W)", "make tables"),
    Result("fig6/", "table2.json", "Fig. 6 heat maps: the grid's corners against the full scan (first seed)",
           "make tables"),
    Result("sec7.md", "table2.json", "Sec. VII summary from our Table 2 grid, our definition", "make tables"),
    Result("fig1_fig7.md", "fig1_fig7.json", "Fig. 1 and Fig. 7: one-pass episodes of the shipped policies "
           "(ours, the paper preset's)", "make tables"),
    Result("budget/budget.md", "budget/budget.json", "coverage against view budget and metres flown, AUC",
           "make tables"),
    Result("budget_lookahead/budget.md", "budget_lookahead/budget.json", "lookahead-stereo against view "
           "budget and metres flown beside the tuned rings and random views (the budget part's settings, no "
           "oracle; before round 33, the 13 m battery at every budget)",
           "nbv tables --part budget --planners random orbit orbit2 lookahead-stereo --out OUT "
           "(OUT/budget/)"),
    Result("online/online.md", "online/online.json", "the shipped policy and the paper "
           "preset's against the baselines, 13 views, five held-out buildings, one pass",
           "nbv online (command in the file)"),
    Result("online/acceptance/online.md", "online/acceptance/online.json", "issue 26's acceptance, check by "
           "check: the shipped policies and the depth option (lookahead) against random views and the tuned "
           "orbits, with blank images, on eight held-out buildings (three of the trait family)",
           "nbv online (command in the file)"),
    Result("online/stereo/online.md", "online/stereo/online.json", "issue 26's acceptance for the "
           "image-only look-ahead (lookahead-stereo), with blank images, against random views and the tuned "
           "orbits on the same eight held-out buildings", "nbv online (command in the file)"),
    Result("ablations/README.md", "ablations/ablations.json", "rendering-quality ablations, one axis at a "
           "time", "make ablations"),
    Result("planners/README.md", "planners/comparison.json", "early planner comparison on the held-out "
           "chalet", "nbv compare (command in the file)"),
    Result("selection/selection.md", "selection/selection.json", "choice of the default training settings "
           "on validation buildings", "scripts/select_defaults.py"),
    Result("selection/members/README.md", "selection/members/selection.json", "the default command's "
           "members (--seed 0, 1, 2) on a larger validation",
           "scripts/select_defaults.py score --episodes 9"),
    Result("selection/round3/README.md", "selection/round3/selection.json", "its third round: batches "
           "of 32, learning rate 2e-4", "scripts/select_defaults.py --round 3"),
    Result("selection/round4/README.md", "selection/round4/selection.json", "its fourth round: a coverage "
           "term in the reward", "scripts/select_defaults.py --round 4"),
    Result("selection/round5/README.md", "selection/round5/results.json", "its fifth round: the Bag of "
           "Views observation and the trait family (issue 26)", LOOKS_EVAL),
    Result("selection/round6/README.md", "selection/round6/results.json", "its sixth round: orbit actions, "
           "a flight term, no poses: none looks", LOOKS_EVAL),
    Result("selection/round7/README.md", "selection/round7/results.json", "its seventh round: students of "
           "a teacher that reads the true surface", LOOKS_EVAL),
    Result("selection/round8/README.md", "selection/round8/results.json", "its eighth round: a look map "
           "of the directions flown", LOOKS_EVAL),
    Result("selection/round9/README.md", "selection/round9/results.json", "its ninth round: students "
           "without frames", LOOKS_EVAL),
    Result("selection/round10/README.md", "selection/round10/results.json", "its tenth round: a student of "
           "the teacher with orbit actions", LOOKS_EVAL),
    Result("selection/round11/README.md", "selection/round11/results.json", "its eleventh round: the "
           "imitation weight, a second seed; the re-ship", LOOKS_EVAL),
    Result("selection/round12/README.md", "selection/round12/results.json", "its twelfth round: a heavier "
           "flight term, a third training courtyard", LOOKS_EVAL),
    Result("selection/round13/README.md", "selection/round13/results.json", "its thirteenth round: round "
           "12's two changes together, two seeds", LOOKS_EVAL),
    Result("selection/round14/README.md", "selection/round14/results.json", "its fourteenth round: the "
           "default command's members trained on to 9000 frames", LOOKS_EVAL),
    Result("selection/round15/README.md", "selection/round15/results.json", "its fifteenth round: the "
           "default command on twice the training buildings", LOOKS_EVAL),
    Result("selection/round16/README.md", "selection/round16/results.json", "its sixteenth round: forward "
           "actions (the azimuth always advancing), teacher and students", LOOKS_EVAL),
    Result("selection/round17/README.md", "selection/round17/results.json", "its seventeenth round: 28 "
           "buildings, two more seeds, checkpoints chosen by the exact-render checks", LOOKS_EVAL),
    Result("selection/round18/README.md", "selection/round18/results.json", "its eighteenth round: the "
           "student fitted to its teacher's labels by supervision alone (scripts/dagger.py)", LOOKS_EVAL),
    Result("selection/round19/README.md", "selection/round19/results.json", "its nineteenth round: the "
           "teacher's near-ties as labels (--teacher-tolerance): students that look, and fly further",
           LOOKS_EVAL),
    Result("selection/round20/README.md", "selection/round20/seed2/results.json", "its twentieth round: "
           "round 19's near-tie setting over two more seeds, and a middle flight weight", LOOKS_EVAL),
    Result("selection/round21/README.md", "selection/round21/seed2/results.json", "its twenty-first round: "
           "the default setting over four more seeds, the checks counted by the script", LOOKS_EVAL),
    Result("selection/round22/README.md", "selection/round22/hinge_seed1/results.json", "its twenty-second "
           "round: a hinge on the flight term, longer training, and the frontier of coverage against metres",
           LOOKS_EVAL),
    Result("selection/round23/README.md", "selection/round23/privileged_seed1/results.json", "its "
           "twenty-third round: the teacher's knowledge in the student's state, and a student that ranks the "
           "teacher's steps", LOOKS_EVAL),
    Result("selection/round24/README.md", "selection/round24/lookahead_distinct/results.json", "its "
           "twenty-fourth round: the depth option's look-ahead never repeating a view (not adopted)",
           LOOKS_EVAL),
    Result("selection/round25/README.md", "selection/round25/lookahead_stereo/results.json", "its "
           "twenty-fifth round: the look-ahead on plane-sweep stereo from the images (lookahead-stereo), its "
           "stereo setting chosen on training buildings and its flight weight on validation ones",
           LOOKS_EVAL),
    Result("selection/round26/README.md", "selection/round26/three_frames_votes/results.json", "its "
           "twenty-sixth round: lookahead-stereo with three second frames, two-pair agreement and a voting "
           "occupancy grid (not adopted)", LOOKS_EVAL),
    Result("selection/round27/README.md", "selection/round27/next_to_free/results.json", "its "
           "twenty-seventh round: lookahead-stereo counting each ray's first unknown voxel or the unknown "
           "beside free space, a battery's hinge, patience with what stereo cannot measure and a longer "
           "horizon (not adopted), and what the courtyard loses", LOOKS_EVAL),
    Result("selection/round28/README.md", "selection/round28/forward/results.json", "its twenty-eighth "
           "round: lookahead-stereo on a pilot's forward steps (adopted: five of six checks)", LOOKS_EVAL),
    Result("selection/round29/README.md", "selection/round29/spacing0.5/results.json", "its twenty-ninth "
           "round: forward steps that never crowd a camera flown (not adopted)", LOOKS_EVAL),
    Result("selection/round30/README.md", "selection/round30/sight10/results.json", "its thirtieth round: "
           "forward steps that change their sight line, alone and under a battery's hinge (not adopted)",
           LOOKS_EVAL),
    Result("selection/round31/README.md", "selection/round31/sides1/results.json", "its thirty-first round: "
           "the look-ahead values the sides of surface it never measured from (OccupancyGrid.sides)",
           LOOKS_EVAL),
    Result("selection/round32/README.md", "selection/round32/battery20/results.json", "its thirty-second "
           "round: what a 20 m battery buys lookahead-stereo at 20 views (informational)", LOOKS_EVAL),
    Result("selection/round33/README.md", "selection/round33/batteryfollows/results.json", "its "
           "thirty-third round: a battery that follows the view budget, at 16 views (adopted)", LOOKS_EVAL),
    Result("selection/round34/README.md", "selection/round34/sides3_hinge/results.json", "its "
           "thirty-fourth round: the sides term at 3 under the battery's hinge (not adopted)", LOOKS_EVAL),
    Result("sfm/presets.md", "sfm/presets.json", "`nbv sfm` on each preset's full 288-view scan: registered "
           "share, models, centre and rotation errors",
           "python scripts/sfm_presets.py (commands in the file)"),
    Result("sfm/register_curve.md", "sfm/register_curve.json", "COLMAP registration per view count and "
           "resolution: the policy, the tuned orbit, random views", "scripts/sfm_register_curve.py"),
    Result("sfm/links/register_curve.md", "sfm/links/register_curve.json", "the same for random and greedy "
           "views kept linked by --min-matches 15", "scripts/sfm_register_curve.py --min-matches 15"),
    Result("sfm/greedy/register_curve.md", "sfm/greedy/register_curve.json", "the same for greedy views "
           "without the constraint", "scripts/sfm_register_curve.py"),
    Result("sfm/tiled/register_curve.md", "sfm/tiled/register_curve.json", "COLMAP registration per view "
           "count and resolution, on the tiled look: the policy, the tuned orbit, random views",
           "scripts/sfm_register_curve.py --scene medieval_tavern@tiled"),
    Result("sfm/demo/results.md", "sfm/demo/results.json", "`nbv demo --sfm --min-matches 15`: the full, "
           "refined and linked sets' registration, the view reductions, the online half",
           "nbv demo --sfm --min-matches 15"),
    Result("match_cosine/match_cosine.md", "match_cosine/match_cosine.json", "the match cosine c re-chosen "
           "on the detailed look: views kept per Table 2 cell for c = 0.76 to 0.8",
           "python scripts/match_cosine.py (command in the file)"),
    Result("captures/captures.md", "captures/captures.json", "the full scan as COLMAP and nerfstudio "
           "captures: kept-frame Jaccard against the scan's own", "scripts/capture_agreement.py"),
)
"""Every result `README.md` may map, in its order."""
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
