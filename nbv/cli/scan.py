"""`nbv scan SCENE --plan {hemisphere,circle} --out DIR`: render a scan plan into a view dataset."""

from __future__ import annotations

import argparse
from dataclasses import dataclass, field
from pathlib import Path
from typing import Literal

from nbv.cli.config_args import add_config_arguments, config_from_args, positional
from render.camera import UAVCamera
from render.capture import capture_dataset
from render.renderer import RenderSettings
from render.scan import CirclePlan, HemispherePlan, circle_scan, hemisphere_scan
from render.viewpoint import Viewpoint
from scenes import load_scene


@dataclass(frozen=True)
class ScanConfig:
    """Settings of `nbv scan`."""

    scene: str = positional()
    """A built-in scene name (see `nbv scene list`) or a mesh / Mitsuba XML file path."""
    up_axis: Literal["z", "y"] = "z"
    """Up axis of a mesh file SCENE (built-in scenes are z up)."""
    out: Path = field(default=None)
    """Dataset folder to write (atomically)."""
    plan: Literal["hemisphere", "circle"] = "hemisphere"
    """Scan plan: full-coverage hemisphere (paper Sec. V-B) or one circle."""
    width: int = 320
    """Image width, pixels."""
    height: int = 240
    """Image height, pixels."""
    focal_mm: float = 35.0
    """Focal length, mm, on the 36 x 24 mm sensor."""
    spp: int = 16
    """RGB samples per pixel."""
    radius: float = 2.0
    """Camera distance from the scene centre, metres."""
    end_overlap: float = 0.86
    """Overlap of consecutive images along a ring (hemisphere; circle when --views is not given)."""
    side_overlap: float = 0.8
    """Overlap of images on neighbouring rings (hemisphere)."""
    views: int | None = None
    """Number of views (circle); default: derived from --end-overlap."""
    elevation: float = 30.0
    """Elevation of the circle, degrees (circle)."""
    variant: Literal["scalar_rgb", "llvm_ad_rgb", "cuda_ad_rgb"] | None = None
    """Mitsuba variant; default: $NBV_VARIANT, else the fastest available."""
    seed: int = 0
    """Base seed of the per-view render seeds."""
    overwrite: bool = False
    """Replace an existing non-empty output folder (only once the new scan is complete)."""


def plan_viewpoints(config: ScanConfig, camera: UAVCamera) -> list[Viewpoint]:
    """The viewpoints the config's plan asks for."""
    if config.plan == "hemisphere":
        return hemisphere_scan(camera, HemispherePlan(config.radius, config.end_overlap, config.side_overlap))
    return circle_scan(camera, CirclePlan(config.radius, config.elevation, config.views, config.end_overlap))


def scan(config: ScanConfig) -> Path:
    """Render the scan the config describes and return the dataset folder."""
    camera = UAVCamera(config.width, config.height, config.focal_mm)
    views = plan_viewpoints(config, camera)
    scene = load_scene(config.scene, config.up_axis)
    meta = {"plan": {"name": config.plan, "radius": config.radius, "end_overlap": config.end_overlap,
                     "side_overlap": config.side_overlap, "views": len(views),
                     "elevation_deg": config.elevation}}
    return capture_dataset(scene, camera, views, config.out, RenderSettings(spp=config.spp, seed=config.seed),
                           config.variant, meta, config.overwrite)


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add the `scan` sub-command."""
    p = subparsers.add_parser("scan", help="render a hemisphere or circle scan into a view dataset")
    add_config_arguments(p, ScanConfig)
    p.set_defaults(func=lambda args: print(scan(config_from_args(ScanConfig, args))))
