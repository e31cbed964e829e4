"""Shared fixtures: one per Mitsuba variant (skipped where the backend is missing), a private cache, and
the fan-out's kept workers closed and Dr.Jit's thread count restored after each test module."""

from __future__ import annotations

import os
import sys

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


@pytest.fixture(autouse=True, scope="module")
def _close_kept_workers():
    """The fan-out keeps its local pools and its Ray connection for the process; a test module's are shut
    down after it, so no module inherits another's workers (or finds Ray already connected). A training env
    sets Dr.Jit's thread count for its process (reproducible renders); later modules get theirs back."""
    drjit = sys.modules.get("drjit")
    threads = drjit.thread_count() if drjit is not None else None
    yield
    drjit = sys.modules.get("drjit")
    if drjit is not None:
        drjit.set_thread_count(threads if threads is not None else os.cpu_count() or 1)
    if "nbv.fanout.processes" in sys.modules:
        sys.modules["nbv.fanout.processes"].close_pools()
    if "nbv.fanout.ray_pool" in sys.modules:
        sys.modules["nbv.fanout.ray_pool"].disconnect()
