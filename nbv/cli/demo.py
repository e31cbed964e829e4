"""`nbv demo`: the main job end to end on a built-in scene (what `make demo` runs)."""

from __future__ import annotations

import argparse

from nbv.cli.config_args import add_config_arguments, config_from_args
from nbv.demo import DemoConfig, run_demo


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add the `demo` sub-command."""
    p = subparsers.add_parser("demo", help="scan, refine, reconstruct and evaluate a built-in scene")
    add_config_arguments(p, DemoConfig)
    p.set_defaults(func=lambda args: _report(run_demo(config_from_args(DemoConfig, args))))


def _report(summary: dict) -> int:
    print(f"scene {summary['scene']}: {summary['views']} views in {summary['dataset']}")
    for name, path in summary["figures"].items():
        print(f"  {name}: {path}")
    for name, seconds in summary["timings"].items():
        print(f"  {name}: {seconds:.1f}")
    return 0
