"""Kept-view counts over a grid of Bag of Views sizes (paper Table 2's N x W grid), from one feature pass.

`sweep` reads a dataset's features once (cached), runs Alg. 1 for every
(N, W) and writes `sweep.csv` (one row per cell), `sweep.md` (Table 2's
layout: one column per cell) and `sweep.json` (rows, kept indices, settings).
"""

from __future__ import annotations

import csv
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from common.io import atomic_folder, atomic_path, markdown_table, write_json, write_text
from common.provenance import run_record
from nbv.bov.config import BoVRule, check_size
from nbv.bov.refine import DatasetRun, Progress, RefineResult, capture_record, kept_view_grid, load_views

PAPER_RANGES = (5, 7, 9, 11)
"""The N values of the paper's Table 2."""
PAPER_WORDS = (10, 20, 30)
"""The W values of the paper's Table 2."""


OUTPUTS = ("sweep.csv", "sweep.md", "sweep.json")
"""Files `nbv refine-sweep` writes into its output folder (other files there are kept)."""


@dataclass(frozen=True, kw_only=True)
class SweepConfig(DatasetRun):
    """Settings of `nbv refine-sweep`: a dataset, the grid of N and W, the rule shared by every cell."""

    out: Path
    """Folder for sweep.csv, sweep.md and sweep.json."""
    ranges: tuple[int, ...] = PAPER_RANGES
    """Values of N (azimuth ranges), the columns' first key (paper Table 2: 5 7 9 11)."""
    words: tuple[int, ...] = PAPER_WORDS
    """Values of W (words per range), the columns' second key (paper Table 2: 10 20 30)."""
    rule: BoVRule = BoVRule()
    """The Bag of Views rule and features of every cell."""

    def __post_init__(self) -> None:
        super().__post_init__()
        if not self.ranges or not self.words:
            raise ValueError(f"ranges and words need a value each, got {self.ranges}, {self.words}")
        for n in self.ranges:
            for w in self.words:
                check_size(n, w)


def sweep(config: SweepConfig, progress: Progress | None = None,
          grid_progress: Progress | None = None) -> dict[str, Any]:
    """Run the grid and write sweep.csv, sweep.md and sweep.json into `config.out`; return the JSON.

    `progress` is called per view whose features were just extracted, `grid_progress` per cell done.
    """
    start = time.perf_counter()
    dataset, feats, azimuths = load_views(config, config.rule, progress)
    grid = kept_view_grid([f.descriptors for f in feats], azimuths, config.ranges, config.words,
                          config.rule, config.seed, config.device, grid_progress)
    rows = grid_rows(grid, len(dataset))
    doc = {"dataset": str(config.dataset), "source_views": len(dataset), "grid": rows,
           "kept": {f"{n},{w}": r.kept for (n, w), r in grid.items()},
           "settings": config.settings(config.rule),
           "seconds": round(time.perf_counter() - start, 3), **capture_record(dataset),
           **run_record("nbv refine-sweep", config)}
    with atomic_folder(config.out, overwrite=True, outputs=OUTPUTS) as folder:  # the three files together
        write_csv(folder / "sweep.csv", rows)
        write_text(folder / "sweep.md", sweep_markdown(rows, str(config.dataset)))
        write_json(folder / "sweep.json", doc)
    return doc


def grid_rows(grid: dict[tuple[int, int], RefineResult], source_views: int) -> list[dict[str, int]]:
    """One row per (N, W): `ranges`, `words`, `kept_views`, `source_views`."""
    return [{"ranges": n, "words": w, "kept_views": len(r.kept), "source_views": source_views}
            for (n, w), r in grid.items()]


def write_csv(path: Path, rows: list[dict[str, Any]], fieldnames: list[str] | None = None) -> Path:
    """Write dict rows as CSV, atomically; columns: `fieldnames` (default: the first row's keys).

    A row lacking a column leaves its cell blank.
    """
    with atomic_path(path) as tmp, open(tmp, "w", newline="") as handle:
        writer = csv.DictWriter(handle, fieldnames=fieldnames or list(rows[0]))
        writer.writeheader()
        writer.writerows(rows)
    return path


def sweep_markdown(rows: list[dict[str, int]], name: str) -> str:
    """Table 2's layout: one column per (N, W), one row of kept-view counts."""
    header = ["", *(f"N={r['ranges']} W={r['words']}" for r in rows)]
    counts = [f"kept views of {rows[0]['source_views']}", *(r["kept_views"] for r in rows)]
    return f"# Bag-of-Views refinement of {name}\n\n" + markdown_table(header, [counts])


def sweep_summary(doc: dict[str, Any]) -> str:
    """The grid of a sweep.json document as plain text lines (N W kept)."""
    lines = [f"{doc['source_views']} source views; kept per (N, W):"]
    lines += [f"  N={r['ranges']:>2} W={r['words']:>2}: {r['kept_views']}" for r in doc["grid"]]
    return "\n".join(lines)
