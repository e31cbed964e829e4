"""`nbv plan`: plan a scan with one planner, capture it, reconstruct it, score it.

Stages, each a verb: `choose_views` (the planner, on a one-worker env),
`capture_dataset` (RGB-D views on disk), `reconstruct_dataset` (TSDF fusion),
`evaluate` (`nbv evaluate`'s function, so `metrics.json` has its format)
against the ground-truth mesh (`gt`) and against the full-scan reconstruction
(`reference`, paper Sec. V-B), and the trajectory plot. The reference is
`--reference MESH` when given; otherwise the hemisphere scan of the same
scene and camera (`nbv.pipeline.full_scan`) is reconstructed once and cached
beside that scan.
"""

from __future__ import annotations

import dataclasses
import json
import time
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from nbv.cli.config_args import positional
from nbv.env import EnvConfig, NBVEnv
from nbv.evaluate import EvaluateCommand, evaluate
from nbv.figures import plot_planner_comparison, plot_trajectory
from nbv.metrics import MetricsConfig
from nbv.paper_numbers import FIG1_NBV
from nbv.pipeline import full_scan
from nbv.planners import Planner, make_planner, planner_label
from nbv.provenance import config_record, git_commit
from nbv.recon import ReconstructionConfig, reconstruct_dataset, save_reconstruction
from render.camera import UAVCamera
from render.capture import capture_dataset
from render.dataset import check_output_folder, read_dataset, write_json
from render.renderer import RenderSettings
from render.scan import HemispherePlan
from render.viewpoint import Viewpoint, viewpoint_to_c2w
from scenes import load_scene


@dataclass(frozen=True)
class PlanConfig:
    """Settings of `nbv plan`."""

    scene: str = positional()
    """The target scene (a preset, random:SEED, or a mesh file)."""
    planner: str = "random"
    """random, circle, greedy, hemisphere, policy:CHECKPOINT (a `nbv train` checkpoint.pt, its mode) or
    policy-sample:CHECKPOINT (seeded draws from the policy)."""
    out: Path = field(default=None)
    """Output folder: views/, mesh.ply, points.ply, gt.ply, metrics.json, heatmap.*, trajectory.png,
    plan.json."""
    views: int | None = None
    """Number of views; default: the policy's episode, the whole hemisphere, or 13 (paper Fig. 1)."""
    width: int = 320
    """Width of the captured views, pixels (a policy plans at its training resolution)."""
    height: int = 240
    """Image height, pixels."""
    spp: int = 16
    """RGB samples per pixel."""
    candidates: int = 8
    """Greedy planner: candidate viewpoints rendered per step."""
    reference: Path | None = None
    """Reference mesh (full-scan reconstruction); default: reconstruct the hemisphere scan, cached."""
    metric_points: int = 1_000_000
    """Points sampled per surface for the metrics."""
    threshold_cm: float = 1.0
    """Distance threshold of coverage and F-score, cm."""
    voxel_size_m: float = 0.004
    """TSDF voxel size, metres."""
    variant: str | None = None
    """Mitsuba variant; default: $NBV_VARIANT, else the fastest available."""
    seed: int = 0
    """Seed of the planner, the start view and the renders."""
    overwrite: bool = False
    """Replace a non-empty output folder."""


def planning_env_config(config: PlanConfig, planner: Planner) -> EnvConfig:
    """The env the planner works in: the policy's training settings on this scene, else the plan's camera."""
    if planner.name == "policy":
        saved = dict(planner.env_config)
        saved.update(scene=(config.scene,), variant=config.variant)
        return EnvConfig(**{k: tuple(v) if isinstance(v, list) else v for k, v in saved.items()})
    return EnvConfig(scene=(config.scene,), width=config.width, height=config.height, spp=config.spp,
                     variant=config.variant)


def choose_views(config: PlanConfig, planner: Planner,
                 env_config: EnvConfig) -> tuple[list[Viewpoint], float]:
    """The planner's viewpoints and the planning wall time in seconds (renders included)."""
    env = NBVEnv(env_config, seed=config.seed)
    start = time.perf_counter()
    views = planner.plan(env, config.views)
    return views, time.perf_counter() - start


def reference_mesh(config: PlanConfig) -> Path:
    """The full hemisphere scan's reconstruction (paper Sec. V-B), cached inside the cached scan's folder.

    The scan comes from `nbv.pipeline.full_scan`, re-rendered only when the scene, camera or settings
    change; a re-rendered scan replaces its folder, and the stale reconstruction with it.
    """
    if config.reference is not None:
        return Path(config.reference)
    env_config = EnvConfig(scene=(config.scene,), width=config.width, height=config.height)
    radius = (env_config.radius_min + env_config.radius_max) / 2.0
    settings = RenderSettings(config.spp, seed=config.seed)
    full = full_scan(load_scene(config.scene), env_config.camera, settings=settings, variant=config.variant,
                     plan=HemispherePlan(radius=radius), progress=False)
    folder = full.root / f"reconstruction_{config.voxel_size_m * 1000:g}mm"
    if not (folder / "mesh.ply").is_file():
        recon_config = ReconstructionConfig(config.voxel_size_m, 4 * config.voxel_size_m)
        save_reconstruction(reconstruct_dataset(full, recon_config), folder)
    return folder / "mesh.ply"


def plan_scan(config: PlanConfig) -> dict:
    """Run the whole `nbv plan` pipeline; return the plan.json document (planner, views, metrics).

    `out/metrics.json` is written by `nbv evaluate`'s own function, in its format.
    """
    out = Path(config.out)
    check_output_folder(out, config.overwrite)
    planner = make_planner(config.planner, config.seed, config.candidates)
    env_config = planning_env_config(config, planner)
    views, plan_s = choose_views(config, planner, env_config)
    scene = load_scene(config.scene)
    out.mkdir(parents=True, exist_ok=True)
    camera = UAVCamera(config.width, config.height)
    settings = RenderSettings(config.spp, seed=config.seed)
    dataset = capture_dataset(scene, camera, views, out / "views", settings, config.variant,
                              {"planner": config.planner}, overwrite=True, progress=False)
    recon_config = ReconstructionConfig(config.voxel_size_m, 4 * config.voxel_size_m)
    recon = reconstruct_dataset(read_dataset(dataset), recon_config)
    mesh_path, _ = save_reconstruction(recon, out)
    gt_path = out / "gt.ply"
    scene.target_mesh().export(gt_path)
    command = EvaluateCommand(mesh_path, reference_mesh(config), str(gt_path), out, overwrite=True)
    results = evaluate(command, MetricsConfig(config.metric_points, config.threshold_cm, config.seed))
    doc = {"planner": config.planner, "scene": config.scene, "views": len(views), "planning_s": plan_s,
           "viewpoints": [v.as_array().tolist() for v in views],
           "config": config_record(config),
           **{name: result.as_dict() for name, result in results.items()}}
    write_json(out / "plan.json", doc)
    center = scene.center()
    poses = np.stack([viewpoint_to_c2w(v, center) for v in views])
    plot_trajectory(poses, scene.target_mesh(), out / "trajectory.png",
                    title=f"{config.planner} on {config.scene}: {len(views)} views", numbered=True)
    return doc


COMPARED = (("coverage", "reference", 100.0, "coverage % (ref)"),
            ("chamfer_cm", "reference", 1.0, "Chamfer cm (ref)"),
            ("hausdorff_cm", "reference", 1.0, "Hausdorff cm (ref)"),
            ("coverage", "gt", 100.0, "coverage % (gt)"),
            ("chamfer_cm", "gt", 1.0, "Chamfer cm (gt)"),
            ("hausdorff_cm", "gt", 1.0, "Hausdorff cm (gt)"))
"""Table columns: (metric, against, display scale, header). The paper's Fig. 1 compares with the full scan
(`reference`); the same metrics against the ground-truth mesh (`gt`) follow."""


def compare_planners(base: PlanConfig, planners: Sequence[str], seeds: Sequence[int], out: str | Path) -> str:
    """Run `plan_scan` for every planner and seed; write comparison.{json,md,png}; return the table.

    Each run goes to `out/<label>-seed<seed>/` (`planner_label`); runs already there are read back.
    The table gives mean +- std over seeds beside the paper's Fig. 1 (13 views, SAC policy).
    """
    out = Path(out)
    runs = []
    for planner in planners:
        label = planner_label(planner)
        for seed in seeds:
            folder = out / f"{label}-seed{seed}"
            if (folder / "plan.json").is_file():
                doc = json.loads((folder / "plan.json").read_text())
            else:
                run = dataclasses.replace(base, planner=planner, seed=seed, out=folder, overwrite=True)
                doc = plan_scan(run)
            runs.append({"planner": label, "seed": seed, **{k: doc[k] for k in ("views", "gt", "reference")}})
    write_json(out / "comparison.json", {
        "scene": base.scene, "seeds": list(seeds), "planners": list(planners), "commit": git_commit(),
        "config": config_record(base), "runs": runs, "paper_fig1": FIG1_NBV})
    table = comparison_table(runs, base.scene, base.threshold_cm)
    (out / "comparison.md").write_text(table)
    plot_planner_comparison(runs, FIG1_NBV, out / "comparison.png",
                            f"Planners on {base.scene}, {len(seeds)} seeds")
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
