"""The `nbv` command: one entry point, one module per sub-command.

Each module in `COMMANDS` exposes `register(subparsers)`, which adds its parser
and sets `func(args) -> int` as the handler.
"""

from __future__ import annotations

import argparse
import importlib
import sys

COMMANDS = (
    "scene",
    "scan",
    "refine",
    "refine_sweep",
    "reconstruct",
    "evaluate",
    "train",
    "plan",
    "demo",
    "tables",
    "bench",
)
"""Sub-command modules under `nbv.cli`, in `--help` order."""


def build_parser() -> argparse.ArgumentParser:
    """The top-level parser with every sub-command registered."""
    parser = argparse.ArgumentParser(
        prog="nbv", description="Appearance-based next-best-view planning toolkit (Bag of Views).")
    subparsers = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    for name in COMMANDS:
        importlib.import_module(f"nbv.cli.{name}").register(subparsers)
    return parser


def main(argv: list[str] | None = None) -> int:
    """Run the `nbv` command line; bad input exits with status 2 and a one-line message."""
    args = build_parser().parse_args(argv)
    try:
        return int(args.func(args) or 0)
    except (ValueError, FileExistsError, FileNotFoundError, PermissionError) as err:
        print(f"nbv {args.command}: error: {err}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
