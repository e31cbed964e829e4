"""SIFT matches between views of a scene on opposite sides and between neighbours (issue 29's cause).

Renders views at radius 2 m, elevation 30 degrees, 320x240, spp 16, azimuths 0, 20, 90, 180 and 270
degrees, and prints for the pairs (0, 20), (0, 180), (90, 270) and (0, 90): OpenCV SIFT matches passing
Lowe's ratio test (0.8) and the inliers of a fundamental matrix fitted by RANSAC (1 px).

    nice -n 5 python scripts/opposite_matches.py medieval_tavern@tiled medieval_tavern
"""

from __future__ import annotations

import math
import sys

import cv2
import numpy as np

from render.camera import UAVCamera
from render.renderer import MitsubaRenderer
from render.settings import RenderSettings
from render.viewpoint import Viewpoint, viewpoint_to_c2w
from scenes.catalog import load_scene

AZIMUTHS_DEG = (0, 20, 90, 180, 270)
"""Where the views stand."""
PAIRS = ((0, 20), (0, 180), (90, 270), (0, 90))
"""Neighbours, two opposite pairs, a quarter turn."""


def features(scene_name: str) -> dict[int, tuple]:
    """SIFT keypoints and descriptors of each view of `scene_name`, by azimuth."""
    renderer = MitsubaRenderer(load_scene(scene_name), UAVCamera(320, 240), RenderSettings(spp=16))
    sift, out = cv2.SIFT_create(), {}
    for azimuth in AZIMUTHS_DEG:
        view = Viewpoint(2.0, math.radians(azimuth), math.radians(30.0))
        rgb = renderer.render_rgb(viewpoint_to_c2w(view, renderer.center), seed=0)
        out[azimuth] = sift.detectAndCompute(cv2.cvtColor(rgb, cv2.COLOR_RGB2GRAY), None)
    return out


def matches(a: tuple, b: tuple) -> tuple[int, int]:
    """Ratio-test matches between two views' features, and the fundamental-matrix inliers among them."""
    (ka, da), (kb, db) = a, b
    good = [p for p, q in cv2.BFMatcher().knnMatch(da, db, k=2) if p.distance < 0.8 * q.distance]
    if len(good) < 8:
        return len(good), 0
    pa = np.float32([ka[m.queryIdx].pt for m in good])
    pb = np.float32([kb[m.trainIdx].pt for m in good])
    _, mask = cv2.findFundamentalMat(pa, pb, cv2.FM_RANSAC, 1.0, 0.999)
    return len(good), 0 if mask is None else int(mask.sum())


def main(argv: list[str]) -> int:
    """Print one line per scene and pair."""
    for name in argv or ["medieval_tavern@tiled", "medieval_tavern"]:
        found = features(name)
        for a, b in PAIRS:
            ratio, inliers = matches(found[a], found[b])
            print(f"{name}: azimuth {a} vs {b}: {ratio} ratio matches, {inliers} inliers", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
