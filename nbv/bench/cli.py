"""Start-up figures: wall time of `nbv --help` and `nbv scene list`, each a fresh Python process."""

from __future__ import annotations

import subprocess
import sys
import time

from nbv.bench import BenchResult

START_GOAL_S = 1.0
"""Issue goal: `nbv --help` and `nbv scene list` start in under 1 s on 2 cores."""
COMMANDS = (("--help",), ("scene", "list"))
"""The start-up commands measured."""


def _seconds(argv: tuple[str, ...]) -> float:
    start = time.perf_counter()
    subprocess.run([sys.executable, "-m", "nbv.cli", *argv], check=True, capture_output=True)
    return time.perf_counter() - start


def run(quick: bool) -> list[BenchResult]:
    """The best of 3 (1 when quick) start-up times of each command, beside the goal."""
    results = []
    for argv in COMMANDS:
        best = min(_seconds(argv) for _ in range(1 if quick else 3))
        met = "met" if best < START_GOAL_S else "NOT met"
        results.append(BenchResult("cli", f"nbv {' '.join(argv)} start-up (fresh process)", best, "s",
                                   f"< {START_GOAL_S:g} s, {met}"))
    return results
