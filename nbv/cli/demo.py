"""`nbv demo`: the main job end to end on a built-in scene (what `make demo` runs)."""

from __future__ import annotations

import argparse

from nbv.cli.config_args import add_config_arguments, config_from_args
from nbv.demo import DemoConfig, run_demo


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add the `demo` sub-command."""
    p = subparsers.add_parser("demo", help="scan, refine, reconstruct and evaluate a built-in scene")
    add_config_arguments(p, DemoConfig)
    p.set_defaults(func=demo)


def demo(args: argparse.Namespace) -> int:
    """Run the demo and print its table and the pictures it wrote."""
    config = config_from_args(DemoConfig, args)
    results = run_demo(config)
    print((config.out / "results.md").read_text())
    for name, path in results["figures"].items():
        print(f"{name}: {path}")
    return 0
