"""`nbv refine DATASET --ranges N --words W --out DIR`: Bag-of-Views refinement of a view dataset (Alg. 1)."""

from __future__ import annotations

import argparse
from dataclasses import dataclass, field
from pathlib import Path

from tqdm import tqdm

from nbv.cli.config_args import add_config_arguments, config_from_args, positional
from nbv.refine import RefineConfig, refine_dataset


@dataclass(frozen=True)
class RefineCommand:
    """What `nbv refine` reads and writes."""

    dataset: Path = positional()
    """A view dataset folder (transforms.json, images/, depth/), e.g. from `nbv scan`."""
    out: Path = field(default=None)
    """Folder for the refined dataset and refine.json."""
    overwrite: bool = False
    """Replace the output folder if it is not empty."""


def _run(args: argparse.Namespace) -> int:
    command = config_from_args(RefineCommand, args)
    with tqdm(desc="features", unit="view", leave=False) as bar:
        summary = refine_dataset(command.dataset, command.out, config_from_args(RefineConfig, args),
                                 command.overwrite, bar.update)
    print(f"kept {summary['kept_views']} of {summary['source_views']} views "
          f"(N={summary['settings']['ranges']}, W={summary['settings']['words']}) in "
          f"{summary['seconds']:.1f} s: {command.out}")
    return 0


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add the `refine` sub-command."""
    p = subparsers.add_parser("refine", help="keep the views a Bag of Views finds new (paper Alg. 1)")
    add_config_arguments(p, RefineCommand)
    add_config_arguments(p, RefineConfig)
    p.set_defaults(func=_run)
