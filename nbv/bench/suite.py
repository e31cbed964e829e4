"""`nbv bench`: run the selected bench areas, write bench.json and bench.md (docs/data-formats.md §8)."""

from __future__ import annotations

import importlib
import platform
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Annotated, Literal

from tyro.conf import UseAppendAction

from common.io import markdown_table, write_json, write_text
from common.provenance import git_commit
from nbv.bench import AREAS, BenchResult

Area = Literal[AREAS]
"""A bench module under `nbv.bench`."""


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
    out = Path(config.out)
    out.mkdir(parents=True, exist_ok=True)
    header = {"machine": platform.processor() or platform.machine(), "commit": git_commit(),
              "time": time.strftime("%Y-%m-%d %H:%M:%S"), "quick": config.quick}
    write_json(out / "bench.json", {**header, "results": [r.as_dict() for r in results]})
    write_text(out / "bench.md", f"# Bench ({header['time']}, commit {header['commit']})\n\n"
                                 f"{format_table(results)}")
    return results


def format_table(results: list[BenchResult]) -> str:
    """A Markdown table of the results: area, figure, value (4 significant digits), unit, goal."""
    return markdown_table(["area", "figure", "value", "unit", "goal"],
                          [[r.area, r.name, f"{r.value:.4g}", r.unit, r.goal] for r in results])
