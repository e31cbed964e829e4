"""`nbv scan SCENE [hemisphere|circle] [PLAN FLAGS] --out DIR`: render a scan plan into a view dataset.

The plan is a subcommand (default: hemisphere), each with its own flags: `nbv scan SCENE circle --help`.
"""

from __future__ import annotations

from collections.abc import Sequence

from nbv.cli.parse import parse
from render.capture import scan_dataset
from render.scan import ScanConfig


def main(args: Sequence[str], prog: str) -> int:
    """Parse `ScanConfig`, render the scan, print the dataset folder."""
    print(scan_dataset(parse(ScanConfig, args, prog)))
    return 0
