"""`nbv tables`: reproduce the paper's Table 2 and Fig. 6 (what `make tables` runs)."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

from tqdm import tqdm

from nbv.cli.parse import parse
from nbv.experiments.table2 import TablesConfig, run_tables


def main(args: Sequence[str], prog: str) -> int:
    """Parse `TablesConfig`, measure every building, print the Markdown table."""
    config = parse(TablesConfig, args, prog)
    rows = len(config.scenes) * (1 + len(config.ranges) * len(config.words))
    with tqdm(total=rows, desc="table 2 rows", unit="row") as bar:
        run_tables(config, bar.update)
    print((Path(config.out) / "table2.md").read_text())
    return 0
