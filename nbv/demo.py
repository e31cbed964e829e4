"""`make demo`: the main job end to end on a built-in scene.

Stages: the full hemisphere scan (paper Sec. V-B), its contact sheet and
camera trajectory.
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from pathlib import Path
from typing import Literal

from nbv.figures import contact_sheet, plot_trajectory
from render.camera import UAVCamera
from render.capture import capture_dataset
from render.dataset import DatasetError, read_dataset
from render.renderer import RenderSettings
from render.scan import HemispherePlan, hemisphere_scan
from scenes import DEFAULT_SCENE, load_scene


@dataclass(frozen=True)
class DemoConfig:
    """Settings of `nbv demo`."""

    out: Path = Path("demo_out")
    """Folder for the datasets, figures and tables."""
    scene: str = DEFAULT_SCENE
    """Built-in scene name or mesh path."""
    width: int = 320
    """Image width, pixels."""
    height: int = 240
    """Image height, pixels."""
    spp: int = 16
    """RGB samples per pixel."""
    variant: Literal["scalar_rgb", "llvm_ad_rgb", "cuda_ad_rgb"] | None = None
    """Mitsuba variant; default: $NBV_VARIANT, else the fastest available."""
    seed: int = 0
    """Seed of the renders."""
    end_overlap: float = HemispherePlan.end_overlap
    """End overlap of the full hemisphere scan (the default gives the paper's 288 views)."""
    side_overlap: float = HemispherePlan.side_overlap
    """Side overlap of the full hemisphere scan."""
    fresh: bool = False
    """Rescan even if the output folder already holds a full scan made with these settings."""


def run_demo(config: DemoConfig) -> dict:
    """Run every stage; return a summary (paths and timings)."""
    config.out.mkdir(parents=True, exist_ok=True)
    scene = load_scene(config.scene)
    camera = UAVCamera(config.width, config.height)
    timings: dict[str, float] = {}
    full_dir = config.out / "full_scan"
    start = time.perf_counter()
    plan = HemispherePlan(end_overlap=config.end_overlap, side_overlap=config.side_overlap)
    settings = RenderSettings(spp=config.spp, seed=config.seed)
    scan_key = {"scene": scene.name, "w": config.width, "h": config.height, "spp": config.spp,
                "seed": config.seed, "end_overlap": plan.end_overlap, "side_overlap": plan.side_overlap}
    if config.fresh or _stored_scan_key(full_dir) != scan_key:
        capture_dataset(scene, camera, hemisphere_scan(camera, plan), full_dir, settings, config.variant,
                        {"plan": {"name": "hemisphere"}, "demo_scan_key": scan_key}, overwrite=True)
    timings["scan_s"] = time.perf_counter() - start
    full = read_dataset(full_dir)
    figures = {
        "contact_sheet": contact_sheet(full, config.out / "contact_sheet.png"),
        "trajectory": plot_trajectory(full.poses(), scene.target_mesh(), config.out / "trajectory.png",
                                      f"{scene.name}: hemisphere scan"),
    }
    return {"scene": scene.name, "views": len(full), "dataset": full_dir, "figures": figures,
            "timings": timings}


def _stored_scan_key(folder: Path) -> dict | None:
    """The settings a previous demo scan in `folder` was made with, if it is intact."""
    try:
        return read_dataset(folder).meta.get("demo_scan_key")
    except DatasetError:
        return None
