"""`nbv plan`: plan a scan with one planner, capture it, reconstruct it, score it.

Stages, each a verb: `choose_views` (the planner, in a `PlanningWorld`),
`capture_dataset` (RGB-D views on disk), `reconstruct_dataset` (TSDF fusion),
`evaluate` (`nbv evaluate`'s function, so `metrics.json` has its format)
against the ground-truth mesh (`gt`) and against the full-scan reconstruction
(`reference`, paper Sec. V-B), the flight from the start view through the views in order along the
viewing shell (`nbv.flight`: `flight_m`, `legs_m`, `azimuth_reversals` in plan.json) and the trajectory
plot with the flown path. The reference is
`--reference MESH` when given; otherwise the hemisphere scan of the same
scene and camera (`render.scan_cache.full_scan`) is reconstructed once and
cached beside that scan (docs/rl.md §10, docs/reconstruction.md). The output
folder is written whole into a temporary folder and swapped into place at the
end (`common.io.atomic_folder`): an interrupted run leaves `--out` as it was.
"""

from __future__ import annotations

import json
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

from common.io import atomic_folder, check_output_folder, write_json
from common.provenance import config_record, run_record
from common.threads import chosen_threads, limit_torch_threads, worker_threads
from nbv.flight import flight_record, shell_path
from nbv.planning.base import Planner
from nbv.planning.config import PlanConfig, PlanSettings
from nbv.planning.registry import make_planner
from nbv.planning.world import PlanningWorld, start_view
from nbv.recon.evaluate import EvaluateConfig, GroundTruth, write_evaluation
from nbv.recon.metrics import load_geometry
from nbv.recon.tsdf import reconstruct_dataset, save_reconstruction
from nbv.rl.config import EnvConfig
from nbv.viz.figures import plot_trajectory
from render.capture import capture_dataset
from render.dataset import read_dataset
from render.scan import HemispherePlan
from render.scan_cache import full_scan
from render.viewpoint import Viewpoint, viewpoint_to_c2w
from scenes.model import Scene
from scenes.spec import SceneSet, SceneSpec

RECONSTRUCTION_KEY = "reconstruction.json"
"""The settings a cached reference reconstruction was fused with, beside its mesh."""


def scan_env_config(scene: SceneSpec, settings: PlanSettings) -> EnvConfig:
    """The plan's own env: its scene, camera, rendering and Bag of Views, the default viewpoint ranges."""
    scenes = SceneSet(scene=(scene.scene,), up_axis=scene.up_axis)
    return EnvConfig(scenes=scenes, camera=settings.camera, render=settings.render, bov=settings.bov)


def planning_env_config(config: PlanConfig, planner: Planner) -> EnvConfig:
    """The env settings the planner works in: the ones it declares (`Planner.planning_env`) given the
    plan's own, `scan_env_config` (a policy: its training settings on this scene, exact renders)."""
    return planner.planning_env(scan_env_config(config.scene, config.settings))


def choose_views(config: PlanConfig, planner: Planner,
                 env_config: EnvConfig) -> tuple[list[Viewpoint], float, float]:
    """The planner's viewpoints, the planning wall time in seconds (renders included) and the part of it
    spent simulating the camera: loading the scene into the renderer, and rendering the views flown to
    (per kind of image, RGB or depth, the mean render time times their count, or times the images
    rendered if fewer), images a real camera captures anyway. Greedy's other candidate renders stay
    planning time.

    Torch runs on the thread policy's count (`common.threads.worker_threads`, 1) while planning, unless
    this process already chose its threads; the previous count is restored afterwards.
    """
    world = PlanningWorld(env_config, seed=config.seed)
    threads = 0 if chosen_threads() is not None else worker_threads()
    with limit_torch_threads(threads):
        start = time.perf_counter()
        views = planner.plan(world, config.views)
        seconds = time.perf_counter() - start
    clock = world.source
    camera = (clock.setup_seconds + flown_seconds(clock.render_seconds, clock.views_rendered, len(views))
              + flown_seconds(clock.depth_seconds, clock.depths_rendered, len(views)))
    return views, seconds, min(camera, seconds)


def flown_seconds(seconds: float, rendered: int, flown: int) -> float:
    """The share of `seconds` spent on `rendered` images that belongs to the views flown to: the mean per
    image times `flown`, at most times `rendered` (a planner may render fewer images than it flies to)."""
    return seconds / rendered * min(rendered, flown) if rendered else 0.0


def reference_settings(settings: PlanSettings) -> PlanSettings:
    """What the full-scan reference of `reference_mesh` depends on (camera, rendering, fusion, a given
    reference), the rest left at defaults: studies differing in any other knob share one reference."""
    return PlanSettings(camera=settings.camera, render=settings.render, recon=settings.recon,
                        reference=settings.reference)


def reference_mesh(scene: SceneSpec, settings: PlanSettings, loaded: Scene | None = None) -> Path:
    """The full hemisphere scan's reconstruction (paper Sec. V-B), cached inside the cached scan's folder.

    The scan comes from `render.scan_cache.full_scan`, re-rendered only when the scene, camera or
    settings change (a re-rendered scan replaces its folder, the stale reconstruction with it); the
    reconstruction is redone when its settings (`RECONSTRUCTION_KEY`) change. The scan renders at the
    plan's render settings with their own seed, not the run's: every seed is scored against one reference.
    """
    if settings.reference is not None:
        return Path(settings.reference)
    env_config = scan_env_config(scene, settings)
    radius = (env_config.radius_min + env_config.radius_max) / 2.0
    full = full_scan(loaded or scene.load(), settings.camera, settings=settings.render,
                     plan=HemispherePlan(radius=radius), progress=False)
    folder = full.root / f"reconstruction_{settings.recon.voxel_size_m * 1000:g}mm"
    key = config_record(settings.recon)
    if not (folder / "mesh.ply").is_file() or _stored(folder / RECONSTRUCTION_KEY) != key:
        recon = reconstruct_dataset(full, settings.recon)
        with atomic_folder(folder, overwrite=True) as tmp:
            save_reconstruction(recon, tmp)
            write_json(tmp / RECONSTRUCTION_KEY, key)
    return folder / "mesh.ply"


def _stored(path: Path) -> dict | None:
    return json.loads(path.read_text()) if path.is_file() else None


def plan_scan(config: PlanConfig) -> dict:
    """Run the whole `nbv plan` pipeline; return the plan.json document (planner, views, metrics).

    `out/metrics.json` is written by `nbv evaluate`'s own function, in its format.
    """
    out = Path(config.out)
    check_output_folder(out, config.overwrite)
    shared = config.settings
    planner = make_planner(config.planner, shared, config.seed)
    env_config = planning_env_config(config, planner)
    views, plan_s, camera_s = choose_views(config, planner, env_config)
    flight = flight_record(start_view(env_config, config.seed), views)
    scene = config.scene.load()
    settings = replace(shared.render, seed=config.seed)
    meta = {"planner": config.planner, "up_axis": config.scene.up_axis}
    with atomic_folder(out, config.overwrite) as folder:
        dataset = capture_dataset(scene, shared.camera, views, folder / "views", settings,
                                  meta, overwrite=True, progress=False)
        recon = reconstruct_dataset(read_dataset(dataset), shared.recon)
        save_reconstruction(recon, folder)
        scene.target_mesh().export(folder / "gt.ply")
        reference = reference_mesh(config.scene, shared, scene) if shared.full_scan else None
        gt = GroundTruth(gt=str(out / "gt.ply"))  # the normalised target: z up whatever the scene file's axis
        evaluation = EvaluateConfig(mesh=out / "mesh.ply", reference=reference, ground_truth=gt, out=out,
                                    metrics=shared.metrics, seed=config.seed, overwrite=True)
        references = {"gt": load_geometry(folder / "gt.ply", "gt")}
        if reference is not None:
            references["reference"] = load_geometry(reference, "reference")
        results = write_evaluation(evaluation, load_geometry(folder / "mesh.ply", "mesh"), references, folder)
        doc = {"planner": config.planner, "scene": config.scene.scene, "views": len(views),
               "planning_s": plan_s, "deciding_s": plan_s - camera_s,
               "viewpoints": [v.as_array().tolist() for v in views], **flight,
               **run_record("nbv plan", config),
               **{name: result.as_dict() for name, result in results.items()}}
        if config.sfm:
            from nbv.sfm.check import sfm_summary  # pycolmap only when asked for

            doc["sfm"] = sfm_summary(read_dataset(dataset), config.sfm_settings, config.seed, folder / "sfm",
                                     run_record("nbv plan", config))
        write_json(folder / "plan.json", doc)
        poses = np.stack([viewpoint_to_c2w(v, scene.center()) for v in views])
        flown = shell_path(start_view(env_config, config.seed), views).points + scene.center()
        plot_trajectory(poses, scene.target_mesh(), folder / "trajectory.png",
                        title=f"{config.planner} on {Path(config.scene.scene).name}: {len(views)} views, "
                              f"{flight['flight_m']:.1f} m flown", numbered=True, flown=flown)
    return doc
