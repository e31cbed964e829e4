"""`nbv tables`: reproduce the paper's Table 2 (what `make tables` runs)."""

from __future__ import annotations

import argparse

from nbv.cli.config_args import add_config_arguments, config_from_args
from nbv.tables import TablesConfig, run_tables


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add the `tables` sub-command."""
    p = subparsers.add_parser("tables", help="reproduce the paper's Table 2 beside its numbers")
    add_config_arguments(p, TablesConfig)
    p.set_defaults(func=tables)


def tables(args: argparse.Namespace) -> int:
    """Run the tables and print the Markdown."""
    config = config_from_args(TablesConfig, args)
    run_tables(config)
    print((config.out / "table2.md").read_text())
    return 0
