"""Synthetic views for tests that must not depend on the renderer: SIFT-rich images and small datasets."""

from __future__ import annotations

import math
from pathlib import Path

import cv2
import numpy as np

from render.camera import UAVCamera
from render.dataset import DatasetWriter
from render.viewpoint import Viewpoint, viewpoint_to_c2w


def textured(h: int, w: int, seed: int) -> np.ndarray:
    """A multi-scale smooth-noise sRGB image: blobs at several scales, as SIFT likes."""
    rng = np.random.default_rng(seed)
    gray = np.zeros((h, w), np.float32)
    for cell in (4, 8, 16):
        noise = rng.random((h // cell + 2, w // cell + 2)).astype(np.float32)
        gray += cv2.resize(noise, (w, h), interpolation=cv2.INTER_CUBIC) / cell**0.3
    gray = (gray - gray.min()) / (gray.max() - gray.min())
    return np.repeat((gray * 255).astype(np.uint8)[..., None], 3, axis=2)


def write_circle_dataset(out: Path, contents: list[int | None], record_viewpoints: bool = True,
                         size: tuple[int, int] = (96, 72)) -> Path:
    """One view per entry, evenly around a circle; entry = texture seed, None = a flat grey view."""
    camera = UAVCamera(size[0], size[1])
    with DatasetWriter(out, camera, {"scene": "synthetic", "center": [0.0, 0.0, 0.5]}) as writer:
        for i, seed in enumerate(contents):
            view = Viewpoint(2.0, 2 * math.pi * i / len(contents), 0.3)
            rgb = (np.full((size[1], size[0], 3), 128, np.uint8) if seed is None
                   else textured(size[1], size[0], seed))
            writer.add(rgb, np.ones((size[1], size[0]), np.float32),
                       viewpoint_to_c2w(view, np.array([0.0, 0.0, 0.5])),
                       view if record_viewpoints else None)
    return out
