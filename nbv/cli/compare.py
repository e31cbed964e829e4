"""`nbv compare SCENE --planners P [P ...] --seeds S [S ...] --out DIR`: planners over seeds, one table."""

from __future__ import annotations

from collections.abc import Sequence

from nbv.cli.parse import parse
from nbv.experiments.compare import CompareConfig, compare_planners


def main(args: Sequence[str], prog: str) -> int:
    """Parse `CompareConfig`, run (or read back) every planner and seed, print the table."""
    print(compare_planners(parse(CompareConfig, args, prog)), end="")
    return 0
