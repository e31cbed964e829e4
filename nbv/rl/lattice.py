"""A per-scene view lattice rendered once, so training steps need no renderer (docs/rl.md §6).

Rendering is the cost of an env step on CPU (about 0.09 s at 160x120, 4 spp,
against a few ms for the Bag of Views). With a lattice, each scene's views on
a grid of (R, azimuth, elevation) are rendered once at the training settings;
the policy frame and the SIFT descriptors of every node are cached on disk,
keyed by scene content, camera, render settings, lattice, frame size and
feature settings. During training the env keeps the exact viewpoint and
shows the frame and descriptors of its nearest node (azimuth on the circle);
evaluation and `nbv plan` render exact viewpoints. The image's snapping error
is at most half a step per coordinate: `EnvConfig.snapping_error`. Before
training, each scene's lattice is a unit of work (`lattice_tasks`): `nbv
train --workers N` or `--ray` renders them side by side, and envs (Ray
actors included) then only read the cache.
"""

from __future__ import annotations

import hashlib
import io
import json
import math
from collections.abc import Callable
from dataclasses import asdict
from pathlib import Path

import numpy as np
import torch
from tqdm import tqdm

from common.cache import write_cache
from common.io import cache_dir
from nbv.fanout.task import Task
from nbv.features.sift import FeatureConfig, extract_features
from nbv.features.source import gray_frame
from nbv.rl.config import EnvConfig, LatticeConfig
from render.renderer import MitsubaRenderer
from render.scan_cache import scene_digest
from render.variant import select_variant
from render.viewpoint import TWO_PI, Viewpoint, viewpoint_to_c2w
from scenes.model import Scene
from scenes.spec import SceneSpec

CACHE_VERSION = 1
"""Bumped when the cached layout or its meaning changes."""


def lattice_axes(config: EnvConfig) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The node coordinates along R (m), azimuth and elevation (rad) within the env's allowed ranges."""
    grid: LatticeConfig = config.lattice
    radii = np.linspace(config.radius_min, config.radius_max, grid.lattice_radii)
    azimuths = np.arange(grid.lattice_azimuths) * TWO_PI / grid.lattice_azimuths
    low, high = config.elevation_min_deg, config.elevation_max_deg
    elevations = np.radians(np.linspace(low, high, grid.lattice_elevations))
    return radii, azimuths, elevations


def _nearest(axis: np.ndarray, value: float) -> int:
    return int(np.argmin(np.abs(axis - value)))


class ViewLattice:
    """The cached frames and descriptors of one scene's lattice nodes, with snapping.

    Args:
        frames: (N, S, S) uint8 policy frames, node order (R, azimuth, elevation) row-major.
        counts: (N,) descriptors per node.
        descriptors: (sum(counts), 128) float32 SIFT descriptors, nodes concatenated.
        axes: the node coordinates from `lattice_axes`.
    """

    def __init__(self, frames: np.ndarray, counts: np.ndarray, descriptors: torch.Tensor,
                 axes: tuple[np.ndarray, np.ndarray, np.ndarray]) -> None:
        self.frames, self.axes = frames, axes
        self._descriptors = torch.split(descriptors, [int(c) for c in counts])
        self._shape = tuple(len(a) for a in axes)
        if len(frames) != math.prod(self._shape) or len(self._descriptors) != len(frames):
            raise ValueError(f"lattice cache holds {len(frames)} nodes, the lattice has {self._shape}")

    def snap(self, view: Viewpoint) -> tuple[Viewpoint, int]:
        """The node nearest to `view` (azimuth wrapped) and its index."""
        radii, azimuths, elevations = self.axes
        step = TWO_PI / len(azimuths)
        i, j = _nearest(radii, view.radius), int(round((view.azimuth % TWO_PI) / step)) % len(azimuths)
        k = _nearest(elevations, view.elevation)
        node = Viewpoint(float(radii[i]), float(azimuths[j]), float(elevations[k]))
        return node, int(np.ravel_multi_index((i, j, k), self._shape))

    def observe(self, index: int) -> tuple[np.ndarray, torch.Tensor]:
        """The policy frame (S x S uint8) and SIFT descriptors (M, 128) of node `index`."""
        return self.frames[index], self._descriptors[index]


def lattice_key(scene: Scene, config: EnvConfig, features: FeatureConfig, variant: str) -> str:
    """A digest of everything a scene's lattice depends on."""
    doc = {"version": CACHE_VERSION, "scene": scene_digest(scene), "camera": asdict(config.camera),
           "render": {**asdict(config.render), "variant": variant}, "lattice": asdict(config.lattice),
           "bounds": [config.radius_min, config.radius_max, config.elevation_min_deg,
                      config.elevation_max_deg], "obs_size": config.obs_size,
           "features": {k: v for k, v in asdict(features).items() if k not in ("device", "batch_size")}}
    return hashlib.sha1(json.dumps(doc, sort_keys=True).encode()).hexdigest()[:20]


def lattice_path(scene: Scene, config: EnvConfig, features: FeatureConfig, variant: str) -> Path:
    """Where the scene's lattice is cached: `$NBV_CACHE_DIR/lattice/<lattice_key>.pt`."""
    return cache_dir() / "lattice" / f"{lattice_key(scene, config, features, variant)}.pt"


def build_lattice(scene: Scene, make_renderer: Callable[[], MitsubaRenderer], config: EnvConfig,
                  features: FeatureConfig, progress: bool = True) -> ViewLattice:
    """The scene's lattice, read from the cache, or rendered now (node i with render seed i) by the
    renderer `make_renderer` gives (asked for only then: its variant is `config.render`'s) and cached."""
    axes = lattice_axes(config)
    path = lattice_path(scene, config, features, select_variant(config.render.variant).variant())
    if path.is_file():
        doc = torch.load(path, weights_only=True)
        return ViewLattice(doc["frames"].numpy(), doc["counts"].numpy(), doc["descriptors"].float(), axes)
    renderer = make_renderer()
    nodes = [Viewpoint(float(r), float(a), float(e)) for r in axes[0] for a in axes[1] for e in axes[2]]
    frames, descriptors = [], []
    for i, node in enumerate(tqdm(nodes, desc=f"lattice {scene.name}", unit="view", disable=not progress)):
        rgb = renderer.render_rgb(viewpoint_to_c2w(node, renderer.center), seed=i)
        frames.append(gray_frame(rgb, config.obs_size))
        descriptors.append(torch.as_tensor(extract_features([rgb], features)[0].descriptors))
    counts = torch.tensor([len(d) for d in descriptors], dtype=torch.long)
    stacked = torch.from_numpy(np.stack(frames))
    flat = torch.cat(descriptors) if descriptors else torch.zeros(0, 128)
    buffer = io.BytesIO()  # saved in memory first: torch.save hides a full disk's errno in a RuntimeError
    torch.save({"frames": stacked, "counts": counts, "descriptors": flat.half()}, buffer)
    write_cache(path, lambda tmp: tmp.write_bytes(buffer.getbuffer()))  # locked; if it fails: a warning
    return ViewLattice(stacked.numpy(), counts.numpy(), flat.half().float(), axes)


def render_lattice(config: EnvConfig, scene: SceneSpec) -> None:
    """Render one scene's lattice into the cache (a unit of work: `lattice_tasks`)."""
    loaded = scene.load()
    build_lattice(loaded, lambda: MitsubaRenderer(loaded, config.camera, config.render), config,
                  config.bov.feature_config(), progress=False)


def lattice_tasks(config: EnvConfig) -> list[Task]:
    """One unit per training scene whose lattice is not cached yet, so an executor renders them side by
    side before training, instead of every env (or Ray actor) that visits a scene rendering it again."""
    variant = select_variant(config.render.variant).variant()
    features = config.bov.feature_config()
    return [Task(f"view lattice of {spec.scene}", render_lattice, {"config": config, "scene": spec},
                 lattice_path(spec.load(), config, features, variant)) for spec in config.scenes.specs()]
