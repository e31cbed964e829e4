"""`nbv refine-sweep DATASET --ranges 5 7 9 11 --words 10 20 30 --out DIR`: paper Table 2's kept-view grid."""

from __future__ import annotations

import argparse
import csv
import time
from dataclasses import asdict, dataclass, field
from pathlib import Path

from tqdm import tqdm

from nbv.cli.config_args import add_config_arguments, config_from_args, positional
from nbv.refine import BoVOptions, kept_view_grid, load_views
from render.dataset import write_json


@dataclass(frozen=True)
class SweepCommand:
    """What `nbv refine-sweep` reads and writes."""

    dataset: Path = positional()
    """A view dataset folder, e.g. a 288-view hemisphere scan from `nbv scan`."""
    out: Path = field(default=None)
    """Folder for sweep.csv, sweep.md and sweep.json."""
    ranges: tuple[int, ...] = (5, 7, 9, 11)
    """Values of N (azimuth ranges), the columns' first key (paper Table 2: 5 7 9 11)."""
    words: tuple[int, ...] = (10, 20, 30)
    """Values of W (words per range), the columns' second key (paper Table 2: 10 20 30)."""

    def __post_init__(self) -> None:
        for name in ("ranges", "words"):
            if any(v < 1 for v in getattr(self, name)):
                raise ValueError(f"--{name} values must be >= 1, got {getattr(self, name)}")


def sweep(command: SweepCommand, options: BoVOptions) -> dict:
    """Run the grid and write sweep.csv, sweep.md and sweep.json into `command.out`; return the JSON."""
    start = time.perf_counter()
    with tqdm(desc="features", unit="view", leave=False) as bar:
        dataset, feats, azimuths = load_views(command.dataset, options, bar.update)
    descriptors = [f.descriptors for f in feats]
    with tqdm(total=len(command.ranges) * len(command.words), desc="grid", unit="run", leave=False) as bar:
        grid = kept_view_grid(descriptors, azimuths, command.ranges, command.words, options, bar.update)
    command.out.mkdir(parents=True, exist_ok=True)
    rows = [{"ranges": n, "words": w, "kept_views": len(r.kept), "source_views": len(dataset)}
            for (n, w), r in grid.items()]
    with open(command.out / "sweep.csv", "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=list(rows[0]))
        writer.writeheader()
        writer.writerows(rows)
    (command.out / "sweep.md").write_text(markdown_table(grid, len(dataset), str(command.dataset)))
    doc = {"dataset": str(command.dataset), "source_views": len(dataset), "grid": rows,
           "kept": {f"{n},{w}": r.kept for (n, w), r in grid.items()},
           "settings": {k: (str(v) if isinstance(v, Path) else v) for k, v in asdict(options).items()},
           "seconds": round(time.perf_counter() - start, 3)}
    write_json(command.out / "sweep.json", doc)
    return doc


def markdown_table(grid: dict, source_views: int, name: str) -> str:
    """Table 2's layout: one column per (N, W), one row of kept-view counts."""
    keys = list(grid)
    head = "| | " + " | ".join(f"N={n} W={w}" for n, w in keys) + " |"
    rule = "| --- | " + " | ".join("---:" for _ in keys) + " |"
    row = f"| kept views of {source_views} | " + " | ".join(str(len(grid[k].kept)) for k in keys) + " |"
    return f"# Bag-of-Views refinement of {name}\n\n{head}\n{rule}\n{row}\n"


def _run(args: argparse.Namespace) -> int:
    doc = sweep(config_from_args(SweepCommand, args), config_from_args(BoVOptions, args))
    print(markdown_table_from_doc(doc))
    return 0


def markdown_table_from_doc(doc: dict) -> str:
    """The grid of a sweep.json document as plain text lines (N W kept)."""
    lines = [f"{doc['source_views']} source views; kept per (N, W):"]
    lines += [f"  N={r['ranges']:>2} W={r['words']:>2}: {r['kept_views']}" for r in doc["grid"]]
    return "\n".join(lines)


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add the `refine-sweep` sub-command."""
    p = subparsers.add_parser("refine-sweep", help="kept-view counts over a grid of N and W (paper Table 2)")
    add_config_arguments(p, SweepCommand)
    add_config_arguments(p, BoVOptions)
    p.set_defaults(func=_run)
