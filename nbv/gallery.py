"""A contact sheet of scenes: each scene from four sides, one row per scene (`nbv scene gallery`)."""

from __future__ import annotations

import math
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Literal

import numpy as np
from PIL import Image, ImageDraw

from render.camera import UAVCamera
from render.renderer import MitsubaRenderer, RenderSettings
from render.viewpoint import Viewpoint, viewpoint_to_c2w
from scenes import load_scene
from scenes.presets import PRESETS


@dataclass(frozen=True)
class GalleryConfig:
    """Settings of `nbv scene gallery`."""

    out: Path = field(default=None)
    """PNG file to write."""
    scene: tuple[str, ...] = tuple(PRESETS)
    """Scenes to show, one row each (default: the four presets)."""
    width: int = 320
    """Width of each view, pixels."""
    height: int = 240
    """Height of each view, pixels."""
    spp: int = 16
    """RGB samples per pixel."""
    radius: float = 2.0
    """Camera distance from the scene centre, metres."""
    elevation: float = 25.0
    """Camera elevation, degrees."""
    up_axis: Literal["z", "y"] = "z"
    """Up axis of mesh files among the scenes: z or y."""


def render_gallery(config: GalleryConfig) -> Path:
    """Render every scene from azimuths 45, 135, 225 and 315 degrees into one labelled PNG sheet."""
    camera = UAVCamera(width=config.width, height=config.height, focal_mm=35.0)
    rows = []
    for name in config.scene:
        scene = load_scene(name, config.up_axis)
        renderer = MitsubaRenderer(scene, camera, RenderSettings(spp=config.spp))
        views = []
        for k in range(4):
            view = Viewpoint(config.radius, math.radians(45.0 + 90.0 * k), math.radians(config.elevation))
            views.append(renderer.render_rgb(viewpoint_to_c2w(view, renderer.center), seed=k))
        row = Image.fromarray(np.concatenate(views, axis=1))
        ImageDraw.Draw(row).text((6, 4), name, fill=(0, 0, 0))
        rows.append(np.asarray(row))
    sheet = Image.fromarray(np.concatenate(rows, axis=0))
    out = Path(config.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    tmp = out.with_name(f".{out.stem}.{os.getpid()}.png")
    sheet.save(tmp)
    tmp.replace(out)
    return out
