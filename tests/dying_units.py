"""Units of work for the executor tests: one that writes a result, ones whose worker dies mid-write.

Module-level functions, so spawned workers import them by name (Ray gets them by value).
"""

from __future__ import annotations

import os
import signal
from pathlib import Path

from common.io import atomic_folder


def write_result(out: Path, text: str) -> None:
    """Write `out/result.txt` atomically (the folder swapped in whole)."""
    with atomic_folder(out, overwrite=True) as tmp:
        (tmp / "result.txt").write_text(text)


def die_once(out: Path, marker: Path) -> None:
    """The first call kills its own process halfway through writing `out`; later calls write it."""
    if not marker.exists():
        marker.touch()
        _die_writing(out)
    write_result(out, "second try")


def always_die(out: Path) -> None:
    """Kill this process halfway through writing `out`, every time."""
    _die_writing(out)


def _die_writing(out: Path) -> None:
    with atomic_folder(out, overwrite=True) as tmp:
        (tmp / "result.txt").write_text("half")
        os.kill(os.getpid(), signal.SIGKILL)


def write_pid_and_env(out: Path, name: str) -> None:
    """Write `out/result.txt`: this process's id and the value of environment variable `name`."""
    write_result(out, f"{os.getpid()} {os.environ.get(name, '-')}")
