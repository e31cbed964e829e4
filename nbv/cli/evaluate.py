"""`nbv evaluate MESH [--reference MESH] [--gt MESH] --out DIR`: surface metrics and a heat map.

The work is `nbv.evaluate.evaluate`; see its module for what is written.
"""

from __future__ import annotations

import argparse

from nbv.cli.config_args import add_config_arguments, config_from_args
from nbv.evaluate import EvaluateCommand, evaluate, format_metrics
from nbv.heatmap import HeatmapConfig
from nbv.metrics import MetricsConfig


def _run(args: argparse.Namespace) -> int:
    command = config_from_args(EvaluateCommand, args)
    results = evaluate(command, config_from_args(MetricsConfig, args), config_from_args(HeatmapConfig, args))
    print(format_metrics(results))
    print(f"wrote {command.out / 'metrics.json'}")
    return 0


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add the `evaluate` sub-command."""
    p = subparsers.add_parser("evaluate", help="Chamfer, Hausdorff, coverage and F-score against "
                              "a reference and/or ground truth, with a heat map")
    add_config_arguments(p, EvaluateCommand)
    add_config_arguments(p, MetricsConfig)
    add_config_arguments(p, HeatmapConfig)
    p.set_defaults(func=_run)
