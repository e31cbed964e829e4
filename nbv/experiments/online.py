"""`nbv online`: the paper's online half on held-out buildings, the shipped policy against the baselines.

Two protocols per building, each an `nbv compare` folder (runs already there are read back):
- `views13/`: every planner captures 13 views (the paper's Fig. 1 count), one run per seed
  (start view, renders, random draws);
- `onepass/`: each policy stops after one pass around the target, its own view count, as in
  the paper, scored against the full scan beside Fig. 1 and Fig. 7;
- `views13-blank/` (`--blank`, on by default): each policy's 13 views again with every captured image
  replaced by a blank one, for the acceptance's test that the policy looks.

`online.md` gives, per building and overall, the mean coverage of the true surface at 13 views
and the policy's margins over random, circle and greedy Bag of Views with its planning speed-up
over greedy (issue 11's acceptance figures), the metres each planner flies and its azimuth
reversals (`nbv.flight`), then the one-pass table and issue 26's acceptance table
(`nbv.experiments.online_acceptance`). The buildings default to the held-out ones: nothing here
trains or tunes anything.

Every comparison is a `PlannerStudy` preset (`nbv.experiments.planner_study`) under the one nested
`PlanSettings`, so every `nbv plan` knob is an `nbv online` flag. Every (planner, seed, building, protocol)
run is an independent unit: all of them are handed to the executor at once (`--workers N`,
`--ray auto|ADDRESS`; `nbv.fanout`), after each building's full-scan reference, so the buildings run side
by side as well as the seeds.
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Annotated

import numpy as np
from tyro.conf import arg

from common.io import atomic_folder, markdown_table, write_json, write_text
from common.provenance import config_record, git_commit, portable_record, portable_text
from nbv.experiments.compare import CompareConfig, compare_planners
from nbv.experiments.online_acceptance import (
    acceptance_checks,
    acceptance_section,
    building_mean,
    mean_coverage,
    per_building,
)
from nbv.experiments.paper_numbers import FIG1_NBV, FIG7_GENERALISATION
from nbv.experiments.planner_study import run_studies, scene_folder
from nbv.experiments.sfm_columns import sfm_table
from nbv.fanout.config import ExecutorConfig
from nbv.planning.config import PlanSettings
from nbv.planning.registry import (
    SHIPPED_POLICIES,
    compared_planners,
    depth_planners,
    entry,
    image_planners,
    planner_label,
)
from nbv.recon.config import MetricsConfig
from nbv.sfm.config import SfmOption
from nbv.viz.figures import plot_seed_scores
from scenes.spec import SceneSpec

HELD_OUT = ("alpine_chalet", "imperial_temple", "random:0", "random:5", "random:10", "family:0", "family:5",
            "family:15")
"""The evaluation buildings: both held-out presets, three test-split random buildings and three test-split
family buildings (`scenes.family_splits`): the first of the held-out trait (a walled compound) and the first
of two seen traits whose best orbits differ most (a tower, a courtyard)."""
OUTPUTS = ("online.md", "online.json", "online.png")
"""What `nbv online` writes into `--out` together, beside the per-building folders."""


@dataclass(frozen=True, kw_only=True)
class OnlineConfig(SfmOption):
    """Settings of `nbv online` (--sfm: every run also runs structure from motion, reported per run)."""

    out: Path
    """Folder of the per-building comparisons and of online.{md,json,png}."""
    scenes: tuple[str, ...] = HELD_OUT
    """Buildings to plan for (held out from training)."""
    policies: tuple[str, ...] = (*SHIPPED_POLICIES, *image_planners())
    """Policies to evaluate on their mode (policy: the shipped default; policy-paper: the paper preset's, so
    the paper's method stands beside ours; policy:CHECKPOINT for others), and planners that read only images
    and poses (the registry's: `lookahead-stereo`); the first is the one the margins describe. Each
    learnt policy flies the one-pass protocol too."""
    depth_options: tuple[str, ...] = field(default_factory=depth_planners)
    """Issue 26's named depth options (the registry's: `lookahead`), flown at the fixed budget and held to the
    policies' checks in columns of their own, reported apart from the policies (which read only images and
    poses); none with `--depth-options` alone."""
    baselines: tuple[str, ...] = field(default_factory=compared_planners)
    """Baseline planners at the same view count (the registry's compared ones: random, circle, the tuned
    orbits, greedy)."""
    seeds: tuple[int, ...] = (0, 1, 2, 3, 4)
    """Evaluation seeds per planner and building."""
    views: int = 13
    """The fixed view budget."""
    one_pass: bool = True
    """Also run the paper's protocol: the first policy's own episode (one pass), against the full scan."""
    blank: bool = True
    """Also fly each policy's fixed budget with every captured image blank (does the policy look?); planners
    that read no image (`--policies random`, say) are not flown again."""
    settings: Annotated[PlanSettings, arg(name="")] = PlanSettings(metrics=MetricsConfig(n_points=200_000))
    """What every run shares (`nbv plan`'s settings; reconstructions scored on 200k points per surface, as
    `nbv demo` and `nbv tables`)."""
    executor: ExecutorConfig = ExecutorConfig()
    """Where the runs run: this process, local workers or Ray (not recorded: it changes no number)."""

    def __post_init__(self) -> None:
        if not (self.scenes and self.policies and self.seeds):
            raise ValueError("nbv online needs at least one scene, one policy and one seed")
        if self.views < 1:
            raise ValueError(f"views must be >= 1, got {self.views}")


def comparisons(config: OnlineConfig) -> list[CompareConfig]:
    """The `nbv compare` runs of the evaluation: per building, the fixed budget, then one pass if asked."""
    found = []
    for scene in config.scenes:
        common = {"scene": SceneSpec(scene=scene), "settings": config.settings, "seeds": config.seeds,
                  "executor": config.executor, "sfm": config.sfm, "sfm_settings": config.sfm_settings}
        folder = Path(config.out) / scene_folder(scene)
        found.append(CompareConfig(**common, views=config.views, out=folder / f"views{config.views}",
                                   planners=(*config.policies, *config.depth_options, *config.baselines)))
        learnt = tuple(p for p in config.policies if not entry(p).image_option)  # the ones with a stop rule
        if config.one_pass and learnt:
            found.append(CompareConfig(**common, planners=learnt, out=folder / "onepass"))
        seeing = tuple(p for p in config.policies if "blank_images" in entry(p).settings)
        if config.blank and seeing:
            blank = replace(config.settings, blank_images=True)
            found.append(CompareConfig(**(common | {"settings": blank}), views=config.views, planners=seeing,
                                       out=folder / f"views{config.views}-blank"))
    return found


def run_online(config: OnlineConfig) -> str:
    """Run (or read back) every comparison; write online.{md,json,png}; return the Markdown."""
    out = Path(config.out)
    compared = comparisons(config)
    run_studies([comparison.study() for comparison in compared], config.executor)
    budget, one_pass, blank = {}, {}, {}
    for comparison in compared:
        compare_planners(comparison)
        found = (blank if comparison.settings.blank_images else budget if comparison.views is not None
                 else one_pass)
        found[comparison.scene.scene] = _runs(comparison.out)
    policy = planner_label(config.policies[0])
    checks = acceptance_checks(budget, blank or None, [planner_label(spec) for spec in config.policies],
                               depth_labels(config))
    coverage = {label: mean_coverage(budget, label) for label in next(iter(budget.values()))}
    text = online_report(budget, coverage, one_pass, policy, config, checks)
    record = portable_record(config_record(config, omit=("executor",)))
    with atomic_folder(out, overwrite=True, outputs=OUTPUTS) as folder:
        write_text(folder / "online.md", text)
        plot_seed_scores({label: list(by.values()) for label, by in coverage.items()}, folder / "online.png",
                         f"coverage % of the true surface, {config.views} views",
                         f"mean over {len(config.seeds)} seeds; one dot per building")
        write_json(folder / "online.json", {"commit": git_commit(), "config": record, "budget": budget,
                                            "one_pass": one_pass, "blank": blank, "acceptance": checks})
    return text


def depth_labels(config: OnlineConfig) -> list[str]:
    """The depth options' planner labels, as the runs and the acceptance name them."""
    return [planner_label(spec) for spec in config.depth_options]


def rerun_command(config: OnlineConfig) -> str:
    """The `nbv online` command line that re-runs `config`'s evaluation (its output folder left as DIR, paths
    portable: `portable_text`)."""
    return portable_text(
        f"nbv online --scenes {' '.join(config.scenes)} --policies {' '.join(config.policies)} "
        f"--depth-options{''.join(' ' + spec for spec in config.depth_options)} "
        f"--baselines {' '.join(config.baselines)} --seeds {' '.join(map(str, config.seeds))} "
        f"--views {config.views}{'' if config.blank else ' --no-blank'} --out DIR")


def _runs(folder: Path) -> dict[str, list[dict]]:
    doc = json.loads((folder / "comparison.json").read_text())
    by_planner: dict[str, list[dict]] = {}
    for run in doc["runs"]:
        by_planner.setdefault(run["planner"], []).append(run)
    return by_planner


def _values(runs: list[dict], against: str, key: str) -> list[float]:
    return [r[against][key] for r in runs]


def online_report(budget: dict[str, dict[str, list[dict]]], coverage: dict[str, dict[str, float]],
                  one_pass: dict[str, dict[str, list[dict]]], policy: str, config: OnlineConfig,
                  checks: dict[str, list[dict]]) -> str:
    """The Markdown report: 13-view coverage per building (`coverage`, by planner label, `mean_coverage`)
    with the policy's margins, then one pass, then the acceptance checks (`checks`, by policy)."""
    labels = list(coverage)
    depth = depth_labels(config)
    rows = [[scene, *(f"{coverage[label][scene]:.1f}" for label in labels)] for scene in budget]
    overall = {label: building_mean(by) for label, by in coverage.items()}
    rows.append(["**mean**", *(f"**{overall[label]:.1f}**" for label in labels)])
    planning = {label: float(np.mean([r["planning_s"] for runs in budget.values() for r in runs[label]]))
                for label in labels}
    deciding = {label: float(np.mean([r["deciding_s"] for runs in budget.values() for r in runs[label]]))
                for label in labels}
    lines = [f"# Online NBV on held-out buildings (commit {git_commit()})", "",
             f"Coverage (%) of the true surface within {config.settings.metrics.threshold_cm:g} cm, "
             f"{config.views} views, mean over seeds {', '.join(map(str, config.seeds))}; "
             "policies act on their mode" + ("" if not config.depth_options else
                                             f" and read only images and poses; {', '.join(depth)} "
                                             "(the depth option) reads the depth it measures") + ".", "",
             f"Re-run: `{rerun_command(config)}`", "",
             markdown_table(["building", *labels], rows), "",
             "Flight per scan (m along the viewing shell from the start view through the views in order "
             "/ azimuth reversals; `plan.json`'s `flight_m` / `azimuth_reversals`), mean over seeds:", "",
             _flight_table(budget, labels), "",
             "Planning time per scan, s (all / without the simulated camera, i.e. loading the scene into "
             "the renderer and rendering the views flown to; `plan.json`'s `planning_s` / `deciding_s`): "
             + ", ".join(f"{label} {planning[label]:.2f} / {deciding[label]:.2f}" for label in labels), ""]
    for other in (*compared_planners(), *depth):
        if other in overall and policy in overall:
            lines.append(f"- {policy} minus {other}: {overall[policy] - overall[other]:+.1f} points")
    if "greedy" in deciding and policy in deciding:
        lines.append("- planning speed-up over greedy (without the simulated camera): "
                     f"{deciding['greedy'] / deciding[policy]:.0f}x")
    policies = [planner_label(spec) for spec in config.policies]
    if len(policies) > 1 and all(label in overall for label in policies):
        spread = [overall[label] for label in policies]
        lines.append(f"- spread over the {len(policies)} policies: "
                     f"{max(spread) - min(spread):.1f} points ("
                     + ", ".join(f"{label} {overall[label]:.1f}" for label in policies) + ")")
    if one_pass:
        lines += ["", "## One pass around the target (the paper's protocol), against the full 288-view scan",
                  "", _one_pass_table(one_pass, policies)]
    lines += acceptance_section(checks, len(budget), depth)
    if config.sfm:
        lines += _sfm_section(budget, one_pass, config.views)
    return "\n".join(lines) + "\n"


def _sfm_section(budget: dict[str, dict[str, list[dict]]], one_pass: dict[str, dict[str, list[dict]]],
                 views: int) -> list[str]:
    lines = ["", f"## Structure from motion (COLMAP) on each scan's views ({views} views"
             + (", then one pass" if one_pass else "") + "): views registered in the largest model per seed, "
             "models, its mean camera-centre error after a similarity fit", "", sfm_table(budget)]
    return lines + (["", sfm_table(one_pass)] if one_pass else [])


def _flight_table(budget: dict[str, dict[str, list[dict]]], labels: list[str]) -> str:
    flight = {label: per_building(budget, label, lambda r: r["flight_m"]) for label in labels}
    reversals = {label: per_building(budget, label, lambda r: r["azimuth_reversals"]) for label in labels}
    rows = [[scene, *(f"{flight[label][scene]:.1f} / {reversals[label][scene]:.1f}" for label in labels)]
            for scene in budget]
    rows.append(["**mean**", *(f"**{building_mean(flight[label]):.1f} / "
                               f"{building_mean(reversals[label]):.1f}**" for label in labels)])
    return markdown_table(["building", *labels], rows)


def _one_pass_table(one_pass: dict[str, dict[str, list[dict]]], policies: list[str]) -> str:
    rows = []
    for scene, runs in one_pass.items():
        for policy in policies:
            mine = runs[policy]
            rows.append([f"{scene} ({policy})", f"{np.mean([r['views'] for r in mine]):.1f}",
                         f"{100 * np.mean(_values(mine, 'reference', 'coverage')):.1f}",
                         f"{np.mean(_values(mine, 'reference', 'hausdorff_cm')):.2f}",
                         f"{np.mean(_values(mine, 'reference', 'chamfer_cm')):.2f}",
                         f"{100 * np.mean(_values(mine, 'gt', 'coverage')):.1f}",
                         f"{np.mean([r['flight_m'] for r in mine]):.1f}"])
    rows.append(["paper Fig. 1 (its training building)", FIG1_NBV["views"],
                 f"{100 * FIG1_NBV['coverage']:.1f}", f"{FIG1_NBV['hausdorff_cm']:.2f}",
                 f"{FIG1_NBV['chamfer_cm']:.2f}", "-", "-"])
    for scene, fig7 in FIG7_GENERALISATION.items():
        rows.append([f"paper Fig. 7 ({scene})", "-", "-", f"{fig7['hausdorff_cm']:.2f}",
                     f"{fig7['chamfer_cm']:.2f}", "-", "-"])
    return markdown_table(["episode", "views", "coverage % (ref)", "Hausdorff cm (ref)", "Chamfer cm (ref)",
                           "coverage % (gt)", "flight m"], rows)
