"""`nbv bench`: run the selected bench areas, write bench.json and bench.md (docs/data-formats.md §8).

The two files are swapped onto `--out` together once every area has run (`common.io.atomic_folder`):
an interrupted bench keeps the previous figures whole; other files in `--out` are kept.
"""

from __future__ import annotations

import importlib
import platform
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Annotated, Literal

from tyro.conf import UseAppendAction

from common.io import atomic_folder, markdown_table, write_json, write_text
from common.provenance import git_commit
from nbv.bench import AREAS, BenchResult

Area = Literal[AREAS]
"""A bench module under `nbv.bench`."""
OUTPUTS = ("bench.json", "bench.md")
"""What `nbv bench` writes into `--out` together."""


@dataclass(frozen=True, kw_only=True)
class BenchConfig:
    """Settings of `nbv bench`."""

    out: Path = Path("bench_out")
    """Folder for bench.json and bench.md."""
    area: Annotated[tuple[Area, ...], UseAppendAction] = ()
    """Run only these areas; give --area several times for several (default: every area, in order)."""
    quick: bool = False
    """Fewer repetitions and views (for smoke tests)."""


def run_bench(config: BenchConfig, done: Callable[[str, float], None] | None = None) -> list[BenchResult]:
    """Run the areas, write `out/bench.json` and `out/bench.md`, return every figure.

    `done` is called with each area's name and wall seconds once it finishes.
    """
    results: list[BenchResult] = []
    for area in config.area or AREAS:
        start = time.perf_counter()
        results.extend(importlib.import_module(f"nbv.bench.{area}").run(config.quick))
        if done is not None:
            done(area, time.perf_counter() - start)
    header = {"machine": platform.processor() or platform.machine(), "commit": git_commit(),
              "time": time.strftime("%Y-%m-%d %H:%M:%S"), "quick": config.quick}
    with atomic_folder(config.out, overwrite=True, outputs=OUTPUTS) as folder:
        write_text(folder / "bench.md", f"# Bench ({header['time']}, commit {header['commit']})\n\n"
                                        f"{format_table(results)}")
        write_json(folder / "bench.json", {**header, "results": [r.as_dict() for r in results]})
    return results


def format_table(results: list[BenchResult]) -> str:
    """A Markdown table of the results: area, figure, value (4 significant digits), unit, goal."""
    return markdown_table(["area", "figure", "value", "unit", "goal"],
                          [[r.area, r.name, f"{r.value:.4g}", r.unit, r.goal] for r in results])
