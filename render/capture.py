"""Rendering a list of viewpoints into a view dataset on disk, with a progress bar."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import asdict
from pathlib import Path
from typing import Any

from tqdm import tqdm

from render.camera import UAVCamera
from render.dataset import DatasetWriter, check_output_folder
from render.renderer import MitsubaRenderer, RenderSettings
from render.viewpoint import Viewpoint, viewpoint_to_c2w
from scenes.model import Scene


def capture_dataset(scene: Scene, camera: UAVCamera, viewpoints: Sequence[Viewpoint], out: str | Path,
                    settings: RenderSettings = RenderSettings(), variant: str | None = None,
                    meta: dict[str, Any] | None = None, overwrite: bool = False,
                    progress: bool = True) -> Path:
    """Render `viewpoints` of `scene` and write them atomically as a dataset at `out`.

    View i is rendered with seed `settings.view_seed(i)`, so a dataset is
    reproducible bit for bit on the same machine and variant. An interruption
    leaves nothing at `out` (or the previous content, with `overwrite`).
    """
    if not viewpoints:
        raise ValueError("a scan needs at least one viewpoint")
    check_output_folder(Path(out), overwrite)
    renderer = MitsubaRenderer(scene, camera, settings, variant)
    doc = {"scene": scene.name, "center": renderer.center.tolist(), "variant": renderer.variant,
           "render": asdict(settings), "seed": settings.seed, **(meta or {})}
    with DatasetWriter(out, camera, doc, overwrite) as writer:
        for i, view in enumerate(tqdm(viewpoints, desc=f"scan {scene.name}", unit="view",
                                      disable=not progress)):
            c2w = viewpoint_to_c2w(view, renderer.center)
            rgb, depth = renderer.render(c2w, seed=settings.view_seed(i))
            writer.add(rgb, depth, c2w, view)
    return Path(out)
