"""Scene figures: texture generation (cold) and per-preset build time with a warm texture cache."""

from __future__ import annotations

import time

from nbv.bench import BenchResult, temporary_cache
from scenes.presets import PRESETS, build_preset
from scenes.textures import make_texture

BUILD_GOAL_S = 2.0
"""Issue goal: each preset builds in <= 2 s with a warm texture cache."""


def run(quick: bool) -> list[BenchResult]:
    """Time one 1024 px texture from scratch and each preset's build (best of 1 or 3, warm cache)."""
    results = []
    start = time.perf_counter()
    make_texture("brick_red", 0)
    results.append(
        BenchResult("scenes", "texture generation brick_red 1024 px (cold)", time.perf_counter() - start, "s")
    )
    repeats = 1 if quick else 3
    with temporary_cache():
        for name in PRESETS:
            start = time.perf_counter()
            build_preset(name)
            results.append(
                BenchResult(
                    "scenes", f"{name} build, cold texture cache", time.perf_counter() - start, "s"
                )
            )
            best = min(_timed_build(name) for _ in range(repeats))
            met = "met" if best <= BUILD_GOAL_S else "NOT met"
            results.append(
                BenchResult(
                    "scenes",
                    f"{name} build, warm texture cache",
                    best,
                    "s",
                    f"<= {BUILD_GOAL_S:g} ({met})",
                )
            )
    return results


def _timed_build(name: str) -> float:
    start = time.perf_counter()
    build_preset(name)
    return time.perf_counter() - start
