"""Every preset shows at least 300 SIFT keypoints on the building in each of 8 views at 320 x 240."""

from __future__ import annotations

import cv2
import numpy as np
import pytest

from render.camera import UAVCamera
from render.renderer import MitsubaRenderer
from render.settings import RenderSettings
from render.viewpoint import Viewpoint, viewpoint_to_c2w
from scenes import load_scene
from scenes.presets import PRESETS

RADIUS_M = 1.6
"""Viewing distance: the 1 m building fills about two thirds of the image width at 35 mm."""
ELEVATION_DEG = 30.0


def building_keypoints(rgb: np.ndarray, depth: np.ndarray, c2w: np.ndarray, camera: UAVCamera) -> int:
    """SIFT keypoints whose pixel sees the building (a hit above the ground plane), not ground or sky."""
    h, w = depth.shape
    fx = camera.focal_mm * w / 36.0
    v, u = np.mgrid[0:h, 0:w]
    rays = (
        np.stack([(u - (w - 1) / 2) / fx, (v - (h - 1) / 2) / fx, np.ones_like(depth)], -1) * depth[..., None]
    )
    height = rays @ c2w[2, :3] + c2w[2, 3]
    building = (depth > 0) & (height > 0.005)
    keypoints = cv2.SIFT_create().detect(cv2.cvtColor(rgb, cv2.COLOR_RGB2GRAY), None)
    return sum(bool(building[int(round(k.pt[1])), int(round(k.pt[0]))]) for k in keypoints)


@pytest.mark.slow
@pytest.mark.parametrize("name", list(PRESETS))
def test_preset_has_300_building_keypoints_in_every_view(name):
    scene = load_scene(name)
    camera = UAVCamera(width=320, height=240, focal_mm=35.0)
    renderer = MitsubaRenderer(scene, camera, RenderSettings(spp=16))
    counts = []
    for k in range(8):
        c2w = viewpoint_to_c2w(
            Viewpoint(RADIUS_M, 2 * np.pi * k / 8, np.radians(ELEVATION_DEG)), scene.center()
        )
        rgb, depth = renderer.render(c2w, seed=k)
        counts.append(building_keypoints(rgb, depth, c2w, camera))
    print(name, counts)
    assert min(counts) >= 300, counts
