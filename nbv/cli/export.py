"""`nbv export DATASET --format colmap --out DIR`: a view dataset as a COLMAP model."""

from __future__ import annotations

from collections.abc import Sequence

from nbv.cli.parse import parse
from render.colmap import ExportConfig, export_dataset


def main(args: Sequence[str], prog: str) -> int:
    """Parse `ExportConfig`, write the export, print its folder."""
    print(export_dataset(parse(ExportConfig, args, prog)))
    return 0
