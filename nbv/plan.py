"""`nbv plan`: plan a scan with one planner, capture it, reconstruct it, score it.

Stages, each a verb: `choose_views` (the planner, on a one-worker env),
`capture_dataset` (RGB-D views on disk), `reconstruct_dataset` (TSDF fusion),
`evaluate` (`nbv evaluate`'s function, so `metrics.json` has its format)
against the ground-truth mesh (`gt`) and against the full-scan reconstruction
(`reference`, paper Sec. V-B), and the trajectory plot. The reference is
`--reference MESH` when given; otherwise the hemisphere scan of the same
scene and camera is reconstructed once and cached under the cache folder
(`$NBV_CACHE_DIR/references/`).
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
import re
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from nbv.cli.config_args import positional
from nbv.cli.evaluate import EvaluateCommand, evaluate
from nbv.env import EnvConfig, NBVEnv
from nbv.figures import plot_trajectory
from nbv.metrics import MetricsConfig
from nbv.planners import HemispherePlanner, Planner, make_planner
from nbv.recon import ReconstructionConfig, reconstruct_dataset, save_reconstruction
from render.capture import capture_dataset
from render.dataset import check_output_folder, read_dataset, write_json
from render.renderer import RenderSettings
from render.viewpoint import Viewpoint, viewpoint_to_c2w
from scenes import load_scene
from scenes.cache import cache_dir


@dataclass(frozen=True)
class PlanConfig:
    """Settings of `nbv plan`."""

    scene: str = positional()
    """The target scene (a preset, random:SEED, or a mesh file)."""
    planner: str = "random"
    """random, circle, greedy, hemisphere, or policy:CHECKPOINT (a `nbv train` checkpoint.pt)."""
    out: Path = field(default=None)
    """Output folder: views/, mesh.ply, points.ply, gt.ply, metrics.json, heatmap.*, trajectory.png,
    plan.json."""
    views: int | None = None
    """Number of views; default: the policy's episode, the whole hemisphere, or 13 (paper Fig. 1)."""
    width: int = 320
    """Image width, pixels (policy: its training resolution is used for planning)."""
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
    """The full hemisphere scan's reconstruction of the scene (cached by scene, camera and settings)."""
    if config.reference is not None:
        return Path(config.reference)
    key = json.dumps([config.scene, config.width, config.height, config.spp, config.voxel_size_m,
                      config.seed])
    digest = hashlib.sha1(key.encode()).hexdigest()[:12]
    folder = cache_dir() / "references" / f"{re.sub(r'[^A-Za-z0-9_.-]', '_', config.scene)[:40]}-{digest}"
    if not (folder / "mesh.ply").is_file():
        env_config = EnvConfig(scene=(config.scene,), width=config.width, height=config.height)
        views = HemispherePlanner().plan(NBVEnv(env_config), None)
        scene = load_scene(config.scene)
        capture_dataset(scene, env_config.camera, views, folder / "views",
                        RenderSettings(config.spp, seed=config.seed), config.variant,
                        {"planner": "hemisphere"}, overwrite=True, progress=False)
        recon_config = ReconstructionConfig(config.voxel_size_m, 4 * config.voxel_size_m)
        recon = reconstruct_dataset(read_dataset(folder / "views"), recon_config)
        save_reconstruction(recon, folder)
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
    dataset = capture_dataset(scene, env_config.camera, views, out / "views",
                              RenderSettings(env_config.spp, seed=config.seed), config.variant,
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
           "config": json.loads(json.dumps(dataclasses.asdict(config), default=str)),
           **{name: result.as_dict() for name, result in results.items()}}
    write_json(out / "plan.json", doc)
    center = scene.center()
    poses = np.stack([viewpoint_to_c2w(v, center) for v in views])
    plot_trajectory(poses, scene.target_mesh(), out / "trajectory.png",
                    title=f"{config.planner} on {config.scene}: {len(views)} views", numbered=True)
    return doc
