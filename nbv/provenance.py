"""Where a result came from: the commit that produced it."""

from __future__ import annotations

import subprocess


def git_commit() -> str:
    """Short hash of the checked-out commit (with '+dirty' for uncommitted changes), or 'unknown'."""
    try:
        run = lambda *args: subprocess.run(["git", *args], capture_output=True, text=True,  # noqa: E731
                                           check=True).stdout.strip()
        return run("rev-parse", "--short", "HEAD") + ("+dirty" if run("status", "--porcelain", "-uno") else "")
    except (OSError, subprocess.CalledProcessError):
        return "unknown"
