"""Rendering throughput: RGB-D views/s per variant and resolution, first call and steady state."""

from __future__ import annotations

import time
from dataclasses import replace

from nbv.bench import BenchResult
from render.camera import UAVCamera
from render.renderer import MitsubaRenderer
from render.settings import RenderSettings
from render.variant import available_variants
from render.viewpoint import Viewpoint, viewpoint_to_c2w
from scenes import DEFAULT_SCENE, load_scene

RESOLUTIONS = ((320, 240), (640, 480))
GOAL_VIEWS_PER_S = 6.0


DENOISED = (RenderSettings(spp=4, denoiser="oidn"), RenderSettings(spp=1, denoiser="oidn"))
"""Denoised low-spp settings timed against the 16-spp default (issue: can one become the default?)."""


def measure(variant: str, width: int, height: int, views: int,
            settings: RenderSettings = RenderSettings(spp=16)) -> tuple[float, float]:
    """Seconds of the first RGB-D view (scene load included) and mean seconds of `views` more."""
    scene = load_scene(DEFAULT_SCENE)
    start = time.perf_counter()
    renderer = MitsubaRenderer(scene, UAVCamera(width, height), replace(settings, variant=variant))
    renderer.render(viewpoint_to_c2w(Viewpoint(2.0, 0.0, 0.4), renderer.center))
    first = time.perf_counter() - start
    start = time.perf_counter()
    for i in range(views):
        renderer.render(viewpoint_to_c2w(Viewpoint(2.0, 0.37 * (i + 1), 0.2 + 0.05 * i), renderer.center))
    return first, (time.perf_counter() - start) / views


def denoised(quick: bool) -> list[BenchResult]:
    """LLVM RGB-D views/s at 320x240 of each `DENOISED` setting, beside 16 spp timed in the same run."""
    views = 3 if quick else 12
    _, plain = measure("llvm_ad_rgb", 320, 240, views)
    results = []
    for settings in DENOISED:
        _, steady = measure("llvm_ad_rgb", 320, 240, views, settings)
        goal = f">= {GOAL_VIEWS_PER_S:g}: {'met' if 1 / steady >= GOAL_VIEWS_PER_S else 'NOT met'}"
        label = f"llvm_ad_rgb 320x240 {settings.spp} spp + OIDN"
        results.append(BenchResult("render", f"RGB-D views/s {label} steady", 1 / steady, "views/s", goal))
        results.append(BenchResult("render", f"speed-up of {label} over 16 spp (same run)", plain / steady,
                                   "x"))
    return results


def run(quick: bool) -> list[BenchResult]:
    """RGB-D views/s (16 spp) at 320x240 and 640x480 for each available variant, and the denoised
    low-spp settings on LLVM."""
    results = []
    for variant in available_variants():
        for width, height in RESOLUTIONS:
            views = 3 if quick or variant == "scalar_rgb" else 12
            first, steady = measure(variant, width, height, views)
            goal = ""
            if variant == "llvm_ad_rgb" and width == 320:
                goal = f">= {GOAL_VIEWS_PER_S:g}: {'met' if 1 / steady >= GOAL_VIEWS_PER_S else 'NOT met'}"
            label = f"{variant} {width}x{height} 16 spp"
            results.append(BenchResult("render", f"RGB-D views/s {label} steady", 1 / steady,
                                       "views/s", goal))
            results.append(BenchResult("render", f"first RGB-D view {label} (load + compile)", first, "s"))
    if "llvm_ad_rgb" in available_variants():
        results += denoised(quick)
    return results
