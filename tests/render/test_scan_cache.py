"""A cached scan renders once, in the variant its render settings name, and again when they change."""

from __future__ import annotations

import pytest

from render.camera import UAVCamera
from render.scan import ring
from render.scan_cache import ensure_scan
from render.settings import RenderSettings
from render.variant import available_variants
from scenes import load_scene


def test_the_variant_comes_from_the_render_settings_and_keys_the_scan(tmp_path):
    if not {"scalar_rgb", "llvm_ad_rgb"} <= set(available_variants()):
        pytest.skip("needs scalar_rgb and llvm_ad_rgb")
    scene, camera, views = load_scene("test_building"), UAVCamera(32, 24), ring(2.0, 0.3, 2)
    folder = tmp_path / "scan"

    def scan(variant: str):
        settings = RenderSettings(spp=1, variant=variant)
        return ensure_scan(scene, camera, views, folder, settings, progress=False)

    first = scan("scalar_rgb")
    assert first.meta["variant"] == first.meta["scan_key"]["variant"] == "scalar_rgb"
    stamp = (folder / "transforms.json").stat().st_mtime_ns
    again = scan("scalar_rgb")
    assert (folder / "transforms.json").stat().st_mtime_ns == stamp and again.meta == first.meta  # reused
    other = scan("llvm_ad_rgb")
    assert other.meta["variant"] == other.meta["scan_key"]["variant"] == "llvm_ad_rgb"  # re-rendered
