"""Shared fixtures: one per Mitsuba variant (skipped where the backend is missing), a private cache."""

from __future__ import annotations

import pytest

from render.variant import available_variants

VARIANTS = ("scalar_rgb", "llvm_ad_rgb", "cuda_ad_rgb")


@pytest.fixture(params=VARIANTS)
def variant(request) -> str:
    """Each rendering variant this machine has."""
    if request.param not in available_variants():
        pytest.skip(f"{request.param} is not available on this machine")
    return request.param


@pytest.fixture(autouse=True, scope="session")
def _private_cache(tmp_path_factory) -> None:
    """Generated assets go to a per-session cache, never the user's."""
    mp = pytest.MonkeyPatch()
    mp.setenv("NBV_CACHE_DIR", str(tmp_path_factory.mktemp("nbv_cache")))
    yield
    mp.undo()
