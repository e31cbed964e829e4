"""Where generated assets (textures) are cached on disk."""

from __future__ import annotations

import os
from pathlib import Path


def cache_dir() -> Path:
    """The cache root: `$NBV_CACHE_DIR` (if set and not empty), else `~/.cache/nbv`; created on demand."""
    root = Path(os.environ.get("NBV_CACHE_DIR") or Path.home() / ".cache" / "nbv")
    root.mkdir(parents=True, exist_ok=True)
    return root
