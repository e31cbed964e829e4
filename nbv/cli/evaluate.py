"""`nbv evaluate MESH [--reference MESH] [--gt MESH_OR_SCENE [--up-axis y]] --out DIR`: metrics, heat map.

The work is `nbv.recon.evaluate.evaluate`; see its module for what is written.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

from nbv.cli.parse import parse
from nbv.recon.evaluate import EvaluateConfig, evaluate, format_metrics


def main(args: Sequence[str], prog: str) -> int:
    """Parse `EvaluateConfig`, compare the surfaces, print the metrics."""
    config = parse(EvaluateConfig, args, prog)
    print(format_metrics(evaluate(config)))
    print(f"wrote {Path(config.out) / 'metrics.json'}")
    return 0
