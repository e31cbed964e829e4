"""Bag-of-Views throughput: SIFT ms/view (Kornia vs OpenCV), score + update ms/view, refine of 288 views.

Images are rendered views of the default scene (distinct poses on a
hemisphere). The 288-view refinement cycles those renders through the 288
viewpoints of a hemisphere-like plan, so features are extracted for every
frame as in a real scan. Kornia and OpenCV are timed alternately on the same
images; both wall time and process CPU time are reported, since on a shared
machine wall time also measures the neighbours.
"""

from __future__ import annotations

import math
import tempfile
import time
from collections.abc import Callable
from pathlib import Path

import cv2
import numpy as np
import torch

from nbv.bench import BenchResult
from nbv.bov.bag import BagOfViews
from nbv.bov.config import BoVConfig
from nbv.bov.refine import RefineConfig, refine_dataset
from nbv.features.sift import FeatureConfig, extract_features
from render.camera import UAVCamera
from render.dataset import DatasetWriter
from render.renderer import MitsubaRenderer
from render.settings import RenderSettings
from render.viewpoint import Viewpoint, viewpoint_to_c2w
from scenes import DEFAULT_SCENE, load_scene

RESOLUTIONS = ((320, 240), (640, 480))
GOAL_RATIO = 3.0
GOAL_BOV_MS = 5.0
REFINE_VIEWS = 288


def hemisphere_views(count: int) -> list[Viewpoint]:
    """`count` viewpoints on 8 rings from 10 to 80 degrees of elevation, radius 2 m."""
    rings = 8
    return [Viewpoint(2.0, 2 * math.pi * (i // rings) / math.ceil(count / rings),
                      math.radians(10 + 10 * (i % rings))) for i in range(count)]


def render_views(width: int, height: int, count: int) -> tuple[np.ndarray, list[Viewpoint], np.ndarray]:
    """(count, H, W, 3) sRGB renders of the default scene, their viewpoints and the scene centre."""
    renderer = MitsubaRenderer(load_scene(DEFAULT_SCENE), UAVCamera(width, height), RenderSettings(spp=16))
    views = hemisphere_views(count)
    images = [renderer.render(viewpoint_to_c2w(v, renderer.center), seed=i)[0] for i, v in enumerate(views)]
    return np.stack(images), views, renderer.center


def timed(fn: Callable[[], object], repeats: int) -> tuple[float, float]:
    """Best wall and best CPU seconds of `fn` over `repeats` runs (after one warm-up)."""
    fn()
    wall, cpu = math.inf, math.inf
    for _ in range(repeats):
        w, c = time.perf_counter(), time.process_time()
        fn()
        wall, cpu = min(wall, time.perf_counter() - w), min(cpu, time.process_time() - c)
    return wall, cpu


def bench_features(images: np.ndarray, label: str, repeats: int) -> list[BenchResult]:
    """Kornia (batched) and OpenCV SIFT on the same views, alternately, and their ratio."""
    n = len(images)
    kornia_cfg, opencv_cfg = FeatureConfig(), FeatureConfig(backend="opencv")
    k_wall, k_cpu = timed(lambda: extract_features(images, kornia_cfg), repeats)
    o_wall, o_cpu = timed(lambda: extract_features(images, opencv_cfg), repeats)
    ratio_wall, ratio_cpu = k_wall / o_wall, k_cpu / o_cpu
    goal = f"<= {GOAL_RATIO:g}: {'met' if ratio_cpu <= GOAL_RATIO else 'NOT met'} (CPU time)"
    kp = np.mean([len(f) for f in extract_features(images, kornia_cfg)])
    return [
        BenchResult("bov", f"SIFT Kornia {label} batch 8, wall", 1000 * k_wall / n, "ms/view"),
        BenchResult("bov", f"SIFT OpenCV {label} wall", 1000 * o_wall / n, "ms/view"),
        BenchResult("bov", f"SIFT Kornia {label} CPU time", 1000 * k_cpu / n, "ms/view"),
        BenchResult("bov", f"SIFT OpenCV {label} CPU time", 1000 * o_cpu / n, "ms/view"),
        BenchResult("bov", f"SIFT Kornia / OpenCV {label} wall", ratio_wall, "x"),
        BenchResult("bov", f"SIFT Kornia / OpenCV {label} CPU time ({kp:.0f} keypoints/view)", ratio_cpu,
                    "x", goal),
    ]


def bench_bov(descriptors: list[torch.Tensor], label: str, ranges: int = 9, words: int = 30,
              views: int = REFINE_VIEWS) -> list[BenchResult]:
    """Mean ms of `score` and of `update` per view over `views` views cycling through the ranges."""
    bov = BagOfViews(ranges, words, memory_cap=2048)
    score_s = update_s = 0.0
    for i in range(views):
        desc, azimuth = descriptors[i % len(descriptors)], 2 * math.pi * i / views * 7 % (2 * math.pi)
        start = time.perf_counter()
        bov.score(desc, azimuth)
        mid = time.perf_counter()
        bov.update(desc, azimuth)
        score_s, update_s = score_s + mid - start, update_s + time.perf_counter() - mid
    total = 1000 * (score_s + update_s) / views
    goal = f"<= {GOAL_BOV_MS:g}: {'met' if total <= GOAL_BOV_MS else 'NOT met'}"
    name = f"N={ranges} W={words} cap 2048, {label}"
    return [BenchResult("bov", f"BoV score {name}", 1000 * score_s / views, "ms/view"),
            BenchResult("bov", f"BoV update (reservoir + k-means) {name}", 1000 * update_s / views,
                        "ms/view"),
            BenchResult("bov", f"BoV score + update {name}", total, "ms/view", goal)]


def bench_refine(images: np.ndarray, center: np.ndarray) -> list[BenchResult]:
    """Refine a 288-frame dataset end to end: read, features (no cache), Alg. 1, write the subset."""
    height, width = images.shape[1:3]
    with tempfile.TemporaryDirectory() as tmp:
        source = Path(tmp) / "scan"
        with DatasetWriter(source, UAVCamera(width, height), {"scene": DEFAULT_SCENE,
                                                               "center": center.tolist()}) as writer:
            for i, view in enumerate(hemisphere_views(REFINE_VIEWS)):
                writer.add(images[i % len(images)], np.ones((height, width), np.float32),
                           viewpoint_to_c2w(view, center), view)
        start = time.perf_counter()
        config = RefineConfig(dataset=source, out=Path(tmp) / "out", bov=BoVConfig(ranges=9, words=20),
                              cache_dir=Path(tmp) / "cache")
        summary = refine_dataset(config)
        seconds = time.perf_counter() - start
    return [BenchResult("bov", f"refine {REFINE_VIEWS} views {width}x{height} end to end (features, Alg. 1, "
                               f"write; N=9 W=20, kept {summary['kept_views']})", seconds, "s")]


def run(quick: bool) -> list[BenchResult]:
    """Features at 320x240 and 640x480, BoV score + update, refine of 288 views, torch and OpenCV on 1 thread.

    One thread: on cores shared with other jobs, 2 OpenMP threads made the same
    work up to 15x slower (wall and CPU time alike), which measures the neighbours.
    """
    threads, cv_threads = torch.get_num_threads(), cv2.getNumThreads()
    torch.set_num_threads(1)
    cv2.setNumThreads(1)
    try:
        return _run(quick)
    finally:
        torch.set_num_threads(threads)
        cv2.setNumThreads(cv_threads)


def _run(quick: bool) -> list[BenchResult]:
    results: list[BenchResult] = []
    count, repeats = (8, 1) if quick else (24, 3)
    small = None
    for width, height in RESOLUTIONS:
        images, _, center = render_views(width, height, count)
        results += bench_features(images, f"{width}x{height}", repeats)
        if small is None:
            small = (images, center)
    images, center = small
    real = [f.descriptors for f in extract_features(images, FeatureConfig())]
    results += bench_bov(real, "rendered views' SIFT")
    generator = torch.Generator().manual_seed(0)
    dense = [torch.nn.functional.normalize(torch.rand(500, 128, generator=generator) ** 4, dim=1)
             for _ in range(16)]
    results += bench_bov(dense, "random 500 descriptors/view (worst case)")
    results += bench_refine(images, center)
    return results
