"""Where a result came from: the commit that produced it."""

from __future__ import annotations

import json
import subprocess
from dataclasses import asdict
from typing import Any


def _git(*args: str) -> str:
    return subprocess.run(["git", *args], capture_output=True, text=True, check=True).stdout.strip()


def config_record(config: Any) -> dict:
    """A config dataclass as JSON-compatible nested dicts (tuples as lists, paths as strings)."""
    return json.loads(json.dumps(asdict(config), default=str))


def git_commit() -> str:
    """Short hash of the checked-out commit (with '+dirty' for uncommitted changes), or 'unknown'."""
    try:
        dirty = "+dirty" if _git("status", "--porcelain", "-uno") else ""
        return _git("rev-parse", "--short", "HEAD") + dirty
    except (OSError, subprocess.CalledProcessError):
        return "unknown"
