"""`nbv ablate`: what rendering quality changes, one axis at a time around a reference setting.

The unit of work is one level of one axis on one building with one seed
(`measure_unit`): it renders a hemisphere scan with the level's settings and
measures, against the reference render settings (`ablation_axes`):
- render time per RGB-D view (median over the scan);
- PSNR and SSIM of a few scan views against a high-spp render of the same
  poses with the reference settings (a resolution level is resized to the
  reference size first, bicubic);
- SIFT keypoints per view; repeatability and the matching inlier ratio of
  those views' keypoints against the high-spp render's, with ground-truth
  correspondences from the exact depth and poses (`nbv.features.repeatability`);
- Bag of Views refinement of the scan (paper Alg. 1): the views kept (their
  Jaccard overlap with the reference level's is computed in the summary);
- the TSDF reconstruction of the kept views against the ground-truth mesh;
- for lighting axes, greedy Bag of Views planning (`nbv plan --planner greedy`)
  at 13 views, its coverage of the true surface.
Each unit writes its own JSON atomically into a cache folder keyed by the
settings and the commit, so an interrupted run resumes and a new commit
measures afresh, and runs where `--workers` / `--ray` say (`nbv.fanout`);
`run_ablations` then writes the tables, plots and README
(`nbv.experiments.ablation_report`) onto `--out` together.
"""

from __future__ import annotations

import hashlib
import json
import tempfile
import time
from collections.abc import Callable
from dataclasses import asdict, dataclass, replace
from pathlib import Path
from typing import Annotated, Any, Literal

import numpy as np
from PIL import Image
from tyro.conf import UseAppendAction

from common.cache import write_cache
from common.io import atomic_path, cache_dir, write_json
from common.provenance import git_commit, run_cache
from common.threads import apply_thread_policy
from nbv.bov.config import BoVConfig
from nbv.experiments.ablation_axes import AXES, Unit, apply_level, check_axes, unit_path, units
from nbv.fanout.config import ExecutorConfig
from nbv.fanout.executor import run_tasks
from nbv.fanout.task import Task
from nbv.recon.config import MetricsConfig, ReconstructionConfig
from render.camera import UAVCamera
from render.scan import HemispherePlan
from render.settings import RenderSettings
from scenes.spec import MeshOrientation

AxisName = Literal[tuple(AXES)]  # type: ignore[valid-type]
"""The names `--axis` accepts: the keys of `AXES`."""
DEFAULT_SCENES = ("medieval_tavern", "forest_ruin_house")
"""The buildings of a default run: the paper's Table 2 pair, both training buildings."""
REFERENCE_SEED = 1_000_000
"""Render seed of the high-spp reference views: no unit's seed, so no level shares its sample stream."""
Progress = Callable[[int], None]
"""Called with a count of units just measured (e.g. a tqdm bar's `update`)."""


@dataclass(frozen=True, kw_only=True)
class AblateConfig(MeshOrientation):
    """Settings of `nbv ablate` (`--quick` starts from `QUICK` instead of these defaults)."""

    out: Path = Path("paper_results/ablations")
    """Folder for ablations.{csv,md,json}, one plot per axis, quality_vs_time.png, crops.png, README.md."""
    axis: Annotated[tuple[AxisName, ...], UseAppendAction] = ()
    """Axes to vary, one at a time (repeat --axis; default: all)."""
    scene: Annotated[tuple[str, ...], UseAppendAction] = ()
    """Buildings (repeat --scene); default: the Table 2 training buildings (`test_building` with --quick);
    nothing held out is looked at."""
    seeds: tuple[int, ...] = (0, 1, 2)
    """Seeds of the renders, the Bag of Views, the greedy planner and the metric samples."""
    camera: UAVCamera = UAVCamera(160, 120)
    """The camera of every scan (a resolution level scales it)."""
    render: RenderSettings = RenderSettings()
    """The reference render settings every level changes one thing of."""
    plan: HemispherePlan = HemispherePlan(end_overlap=0.4, side_overlap=0.3)
    """The hemisphere scan each level renders and refines (25 views by default)."""
    bov: BoVConfig = BoVConfig()
    """The Bag of Views of the refinement (paper Alg. 1) and its features."""
    recon: ReconstructionConfig = ReconstructionConfig()
    """TSDF fusion of the kept views."""
    metrics: MetricsConfig = MetricsConfig(n_points=30_000)
    """How reconstructions are compared with the ground truth."""
    reference_spp: int = 256
    """Samples per pixel of the reference render of the quality views."""
    quality_views: int = 4
    """Scan views (evenly spread) scored by PSNR, SSIM, repeatability and matching."""
    tolerance_px: float = 1.5
    """Repeatability and match radius, pixels of the reference render."""
    greedy_views: int = 13
    """Views of the greedy Bag of Views plan scored on lighting axes (paper Fig. 1's count)."""
    greedy_candidates: int = 4
    """Candidate viewpoints the greedy planner renders per step (`nbv plan` takes 8; 4 keeps
    `make ablations` within the hour)."""
    quick: bool = False
    """A small run (one building, one seed, a small camera and scan): the defaults of `QUICK`."""
    executor: ExecutorConfig = ExecutorConfig()
    """Where the units run: this process, local workers or Ray (render times are then per worker)."""

    def __post_init__(self) -> None:
        check_axes(self.axes)
        if not self.seeds:
            raise ValueError("an ablation needs at least one seed")
        if min(self.seeds) < 0:
            raise ValueError(f"seeds must be >= 0, got {self.seeds}")
        for name in ("reference_spp", "quality_views", "greedy_views", "greedy_candidates"):
            if getattr(self, name) < 1:
                raise ValueError(f"{name} must be >= 1, got {getattr(self, name)}")
        if not self.tolerance_px > 0:
            raise ValueError(f"tolerance_px must be positive, got {self.tolerance_px}")
        RenderSettings(spp=self.reference_spp)

    @property
    def axes(self) -> tuple[str, ...]:
        """The axes measured: those asked for, else all."""
        return self.axis or tuple(AXES)

    @property
    def scenes(self) -> tuple[str, ...]:
        """The buildings measured: those asked for, else the default ones."""
        return self.scene or (("test_building",) if self.quick else DEFAULT_SCENES)

    @property
    def greedy(self) -> bool:
        """Whether greedy planning is scored: some chosen axis is a lighting axis."""
        return any(AXES[name].lighting for name in self.axes)


QUICK = AblateConfig(quick=True, seeds=(0,), camera=UAVCamera(96, 72),
                     plan=HemispherePlan(end_overlap=0.3, side_overlap=0.2),
                     quality_views=2, greedy_views=4, greedy_candidates=3,
                     metrics=MetricsConfig(n_points=10_000))
"""`nbv ablate --quick`: every axis on the test building, one seed, 96x72, a 20-view scan, 4 greedy views."""


def quality_indices(views: int, count: int) -> list[int]:
    """`count` scan views spread evenly from the first to the last (fewer if the scan is shorter)."""
    return sorted({int(i) for i in np.linspace(0, views - 1, min(count, views)).round()})


def _reference_views(config: AblateConfig, scene, viewpoints: list, picks: list[int]) -> dict[str, Any]:
    """The high-spp reference renders of the quality views with their features (cached on disk)."""
    from nbv.features.sift import extract_features
    from render.renderer import MitsubaRenderer
    from render.scan_cache import scene_digest
    from render.viewpoint import viewpoint_to_c2w

    settings = replace(config.render, spp=config.reference_spp, seed=REFERENCE_SEED)
    key = json.dumps([scene_digest(scene), asdict(config.camera), asdict(settings),
                      [viewpoints[i].as_array().round(9).tolist() for i in picks]], default=str)
    path = cache_dir() / "ablations" / "references" / f"{hashlib.sha1(key.encode()).hexdigest()[:16]}.npz"
    if not path.exists():
        renderer = MitsubaRenderer(scene, config.camera, settings)
        poses = [viewpoint_to_c2w(viewpoints[i], renderer.center) for i in picks]
        pairs = [renderer.render(pose, seed=settings.view_seed(i)) for i, pose in zip(picks, poses)]
        stored = {"rgb": np.stack([p[0] for p in pairs]), "depth": np.stack([p[1] for p in pairs]),
                  "K": renderer.camera.K}
        write_cache(path, lambda tmp: np.savez_compressed(tmp, **stored))  # if it fails: a warning
    else:
        stored = np.load(path)
    feats = extract_features(list(stored["rgb"]), config.bov.feature_config())
    return {"rgb": stored["rgb"], "depth": stored["depth"], "K": stored["K"], "features": feats}


def _resized(image: np.ndarray, shape: tuple[int, ...]) -> np.ndarray:
    """`image` at `shape`'s height and width (bicubic), or as is."""
    if image.shape == shape:
        return image
    return np.asarray(Image.fromarray(image).resize((shape[1], shape[0]), Image.BICUBIC))


def _quality(config: AblateConfig, rgbs, depths, poses, feats, K, picks, reference) -> dict[str, float]:
    """PSNR, SSIM, repeatability and inlier ratio of the picked views against the reference renders."""
    from nbv.features.repeatability import match_inlier_ratio, repeatability
    from render.quality import psnr, ssim

    scores: dict[str, list[float]] = {"psnr_db": [], "ssim": [], "repeatability": [], "inlier_ratio": []}
    for j, i in enumerate(picks):
        ref_rgb, ref_depth, ref_feat = reference["rgb"][j], reference["depth"][j], reference["features"][j]
        image = _resized(rgbs[i], ref_rgb.shape)
        scores["psnr_db"].append(psnr(image, ref_rgb))
        scores["ssim"].append(ssim(image, ref_rgb))
        f = feats[i]
        shared = dict(depth_a=depths[i], K_a=K, c2w_a=poses[i], K_b=reference["K"], c2w_b=poses[i],
                      depth_b=ref_depth, tol_px=config.tolerance_px)
        scores["repeatability"].append(repeatability(f.keypoints.numpy(), ref_feat.keypoints.numpy(),
                                                     **shared))
        scores["inlier_ratio"].append(match_inlier_ratio(f.keypoints.numpy(), f.descriptors.numpy(),
                                                         ref_feat.keypoints.numpy(),
                                                         ref_feat.descriptors.numpy(), **shared))
    return {k: float(np.mean(v)) for k, v in scores.items()}


def _greedy_coverage(config: AblateConfig, unit: Unit, settings: RenderSettings) -> dict[str, float]:
    """Greedy Bag of Views planning at `greedy_views` views under `settings`: coverage of the true surface."""
    from nbv.planning.config import PlanConfig, PlanSettings
    from nbv.planning.plan import plan_scan
    from scenes.spec import SceneSpec

    with tempfile.TemporaryDirectory(prefix="nbv-ablate-") as tmp:
        shared = PlanSettings(camera=config.camera, render=settings, candidates=config.greedy_candidates,
                              full_scan=False, metrics=config.metrics, recon=config.recon)
        doc = plan_scan(PlanConfig(scene=SceneSpec(scene=unit.scene, up_axis=config.up_axis),
                                   views=config.greedy_views, planner="greedy", seed=unit.seed,
                                   out=Path(tmp) / "plan", settings=shared))
    return {"greedy_coverage": doc["gt"]["coverage"], "greedy_deciding_s": doc["deciding_s"]}


def measure_unit(config: AblateConfig, unit: Unit, folder: Path) -> dict[str, Any]:
    """Measure one unit and write its JSON (and, for the first building and seed, its first quality view as
    PNG) under `folder`; a unit already there is read back instead."""
    from nbv.bov.refine import refine_with
    from nbv.features.sift import extract_features
    from nbv.recon.metrics import evaluate_surfaces
    from nbv.recon.tsdf import reconstruct_views
    from render.renderer import MitsubaRenderer
    from render.scan import hemisphere_scan
    from render.viewpoint import viewpoint_to_c2w
    from scenes.catalog import load_scene

    path = unit_path(folder, unit)
    if path.exists():
        return json.loads(path.read_text())
    apply_thread_policy()
    scene = load_scene(unit.scene, config.up_axis)
    settings = apply_level(replace(config.render, seed=unit.seed), unit.level)
    viewpoints = hemisphere_scan(config.camera, config.plan)
    picks = quality_indices(len(viewpoints), config.quality_views)
    reference = _reference_views(config, scene, viewpoints, picks)
    renderer = MitsubaRenderer(scene, config.camera, settings)
    rgbs, depths, poses, seconds = [], [], [], []
    for i, view in enumerate(viewpoints):
        poses.append(viewpoint_to_c2w(view, renderer.center))
        start = time.perf_counter()
        rgb, depth = renderer.render(poses[-1], seed=settings.view_seed(i))
        seconds.append(time.perf_counter() - start)
        rgbs.append(rgb)
        depths.append(depth)
    feats = extract_features(rgbs, config.bov.feature_config())
    kept = refine_with(config.bov, [f.descriptors for f in feats], [v.azimuth for v in viewpoints],
                       config.bov.ranges, config.bov.words, unit.seed).kept
    recon = reconstruct_views(((rgbs[i], depths[i], poses[i]) for i in kept), renderer.camera.K,
                              config.recon)
    metrics = replace(config.metrics, seed=unit.seed)
    gt = evaluate_surfaces(recon.mesh, {"gt": scene.target_mesh()}, metrics)["gt"]
    doc = {"scene": unit.scene, "axis": unit.axis, "level": unit.level.label, "seed": unit.seed,
           "overrides": [[k, v] for k, v in unit.level.overrides], "commit": git_commit(),
           "render_s_per_view": float(np.median(seconds[1:] or seconds)),
           "keypoints": float(np.mean([len(f) for f in feats])),
           **_quality(config, rgbs, depths, poses, feats, renderer.camera.K, picks, reference),
           "scan_views": len(viewpoints), "kept_views": len(kept), "kept": kept,
           "gt_chamfer_cm": gt.chamfer_cm, "gt_hausdorff_cm": gt.hausdorff_cm, "gt_coverage": gt.coverage}
    lighting = AXES[unit.axis].lighting if unit.axis in AXES else config.greedy
    if lighting:
        doc.update(_greedy_coverage(config, unit, settings))
    path.parent.mkdir(parents=True, exist_ok=True)
    if unit.scene == config.scenes[0] and unit.seed == config.seeds[0]:
        with atomic_path(path.with_suffix(".png")) as tmp:
            Image.fromarray(_resized(rgbs[picks[0]], reference["rgb"][0].shape)).save(tmp)
    write_json(path, doc)
    return doc


def run_ablations(config: AblateConfig, progress: Progress | None = None) -> list[dict[str, Any]]:
    """Measure every unit (resuming those already measured at this commit) and write the report onto
    `config.out`; returns the units' documents."""
    from nbv.experiments.ablation_report import write_report

    folder = run_cache("ablations", config, unkeyed=("out", "axis", "scene", "seeds", "executor"))
    start = time.perf_counter()
    todo = units(config)
    tasks = [Task(unit.name, measure_unit, {"config": config, "unit": unit, "folder": folder},
                  unit_path(folder, unit)) for unit in todo]
    skipped = sum(task.done() for task in tasks)
    if progress is not None and skipped:
        progress(skipped)
    run_tasks(tasks, config.executor, None if progress is None else lambda task: progress(1))
    docs = [json.loads(unit_path(folder, unit).read_text()) for unit in todo]
    write_report(config, docs, folder, time.perf_counter() - start)
    return docs
