"""`nbv online [--policies P ...] --out DIR`: both shipped policies vs the baselines, held-out buildings."""

from __future__ import annotations

from collections.abc import Sequence

from nbv.cli.parse import parse
from nbv.experiments.online import OnlineConfig, run_online


def main(args: Sequence[str], prog: str) -> int:
    """Parse `OnlineConfig`, run (or read back) every comparison, print the report."""
    print(run_online(parse(OnlineConfig, args, prog)), end="")
    return 0
