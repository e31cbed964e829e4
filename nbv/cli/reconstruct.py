"""`nbv reconstruct DATASET --out DIR`: TSDF fusion of a view dataset into DIR/mesh.ply and DIR/points.ply."""

from __future__ import annotations

from collections.abc import Sequence

from nbv.cli.parse import parse
from nbv.recon.reconstruct import ReconstructConfig, reconstruct


def main(args: Sequence[str], prog: str) -> int:
    """Parse `ReconstructConfig`, fuse the dataset, print what was written."""
    summary = reconstruct(parse(ReconstructConfig, args, prog))
    print(f"{summary['views']} views fused in {summary['seconds']:.1f} s: {summary['mesh']} "
          f"({summary['faces']} faces), {summary['points']} ({summary['n_points']} points)")
    return 0
