"""`nbv plan SCENE --planner {policy[-sample]:CKPT,random,circle,greedy,hemisphere} [--views N] --out DIR`."""

from __future__ import annotations

import argparse
import json

from nbv.cli.config_args import add_config_arguments, config_from_args
from nbv.plan import PlanConfig, plan_scan


def run(args: argparse.Namespace) -> int:
    """Plan, capture, reconstruct and score; print the metrics."""
    doc = plan_scan(config_from_args(PlanConfig, args))
    print(json.dumps({k: doc[k] for k in ("planner", "views", "gt", "reference")}, indent=2))
    return 0


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add the `plan` sub-command."""
    p = subparsers.add_parser("plan", help="plan a scan with a planner, reconstruct it and score it")
    add_config_arguments(p, PlanConfig)
    p.set_defaults(func=run)
