"""`nbv refine-sweep DATASET --ranges 5 7 9 11 --words 10 20 30 --out DIR`: paper Table 2's kept-view grid."""

from __future__ import annotations

from collections.abc import Sequence

from tqdm import tqdm

from nbv.bov.sweep import SweepConfig, sweep, sweep_summary
from nbv.cli.parse import parse
from render.captures.frame import describe_frame


def main(args: Sequence[str], prog: str) -> int:
    """Parse `SweepConfig`, run the grid, print the kept-view counts."""
    config = parse(SweepConfig, args, prog)
    cells = len(config.ranges) * len(config.words)
    with (tqdm(desc="features", unit="view", leave=False) as features,
          tqdm(total=cells, desc="grid", unit="run", leave=False) as grid):
        doc = sweep(config, features.update, grid.update)
    if "capture" in doc:
        print(describe_frame(doc["capture"]))
    print(sweep_summary(doc))
    return 0
