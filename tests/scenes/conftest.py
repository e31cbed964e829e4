"""Fixtures for scene tests: a fresh texture cache where a test needs one."""

from __future__ import annotations

from pathlib import Path

import pytest


@pytest.fixture
def fresh_cache(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """An empty `NBV_CACHE_DIR` for this test only."""
    path = tmp_path / "cache"
    monkeypatch.setenv("NBV_CACHE_DIR", str(path))
    return path
