"""Rendering a list of viewpoints into a view dataset on disk, with a progress bar."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import asdict, replace
from pathlib import Path
from typing import Any

from tqdm import tqdm

from common.io import check_output_folder
from common.provenance import run_record
from render.camera import UAVCamera
from render.dataset import DatasetWriter
from render.renderer import MitsubaRenderer
from render.scan import ScanConfig, plan_record
from render.settings import RenderSettings
from render.viewpoint import Viewpoint, viewpoint_to_c2w
from scenes.model import Scene


def capture_dataset(scene: Scene, camera: UAVCamera, viewpoints: Sequence[Viewpoint], out: str | Path,
                    settings: RenderSettings = RenderSettings(), meta: dict[str, Any] | None = None,
                    overwrite: bool = False, progress: bool = True) -> Path:
    """Render `viewpoints` of `scene` and write them atomically as a dataset at `out`.

    View i is rendered with seed `settings.view_seed(i)`, so a dataset is
    reproducible bit for bit on the same machine and variant (`settings.variant`). Images have the
    camera's size times `settings.resolution_scale` (field of view kept), and the
    dataset records that camera. An interruption leaves nothing at `out` (or the
    previous content, with `overwrite`).
    """
    if not viewpoints:
        raise ValueError("a scan needs at least one viewpoint")
    check_output_folder(Path(out), overwrite)
    renderer = MitsubaRenderer(scene, camera, settings)
    doc = {"scene": scene.name, "center": renderer.center.tolist(), "variant": renderer.variant,
           "render": asdict(settings), "seed": settings.seed, **(meta or {})}
    with DatasetWriter(out, renderer.camera, doc, overwrite) as writer:
        for i, view in enumerate(tqdm(viewpoints, desc=f"scan {scene.name}", unit="view",
                                      disable=not progress)):
            c2w = viewpoint_to_c2w(view, renderer.center)
            rgb, depth = renderer.render(c2w, seed=settings.view_seed(i))
            writer.add(rgb, depth, c2w, view)
    return Path(out)


def scan_dataset(config: ScanConfig) -> Path:
    """Render the scan `config` describes (`nbv scan`) and return the dataset folder."""
    views = config.viewpoints()
    meta = {"plan": plan_record(config.plan, len(views)), "up_axis": config.scene.up_axis,
            **run_record("nbv scan", config)}
    return capture_dataset(config.scene.load(), config.camera, views, config.out,
                           replace(config.render, seed=config.seed), meta, config.overwrite)
