"""A contact sheet of scenes: each scene from four sides, one row per scene (`nbv scene gallery`)."""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Annotated

import numpy as np
from PIL import Image, ImageDraw
from tyro.conf import UseAppendAction

from common.io import atomic_path
from render.camera import UAVCamera
from render.renderer import MitsubaRenderer
from render.settings import RenderSettings
from render.viewpoint import Viewpoint, viewpoint_to_c2w
from scenes.catalog import PRESET_NAMES
from scenes.spec import MeshOrientation, SceneSet

AZIMUTHS_DEG = (45.0, 135.0, 225.0, 315.0)
"""The four sides each scene is shown from."""


@dataclass(frozen=True, kw_only=True)
class GalleryConfig(MeshOrientation):
    """Settings of `nbv scene gallery`: the scenes, the camera and how it renders, the PNG to write."""

    out: Path
    """PNG file to write."""
    scene: Annotated[tuple[str, ...], UseAppendAction] = ()
    """Scenes to show, one row each; give --scene several times (default: the four presets)."""
    camera: UAVCamera = UAVCamera()
    """The camera (each view is one image of the sheet)."""
    render: RenderSettings = RenderSettings()
    """How views are rendered."""
    radius: float = 2.0
    """Camera distance from the scene centre, metres."""
    elevation_deg: float = 25.0
    """Camera elevation, degrees."""

    def scenes(self) -> SceneSet:
        """The scenes to show (the presets when none were given), with the up axis of mesh files."""
        return SceneSet(scene=self.scene or PRESET_NAMES, up_axis=self.up_axis)


def render_gallery(config: GalleryConfig) -> Path:
    """Render every scene from azimuths 45, 135, 225 and 315 degrees into one labelled PNG sheet."""
    rows = []
    for spec in config.scenes().specs():
        renderer = MitsubaRenderer(spec.load(), config.camera, config.render)
        views = []
        for k, azimuth in enumerate(AZIMUTHS_DEG):
            view = Viewpoint(config.radius, math.radians(azimuth), math.radians(config.elevation_deg))
            views.append(renderer.render_rgb(viewpoint_to_c2w(view, renderer.center), seed=k))
        row = Image.fromarray(np.concatenate(views, axis=1))
        ImageDraw.Draw(row).text((6, 4), spec.scene, fill=(0, 0, 0))
        rows.append(np.asarray(row))
    sheet = Image.fromarray(np.concatenate(rows, axis=0))
    out = Path(config.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    with atomic_path(out) as tmp:
        sheet.save(tmp)
    return out
