"""`nbv bench`: run every bench area, print a table, write JSON and Markdown."""

from __future__ import annotations

import argparse
import importlib
import platform
import time
from pathlib import Path

from nbv.bench import AREAS, BenchResult
from nbv.provenance import git_commit
from render.dataset import write_json


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add the `bench` sub-command."""
    p = subparsers.add_parser("bench", help="measure throughput figures (make bench)")
    p.add_argument("--out", type=Path, default=Path("bench_out"), help="folder for bench.json and bench.md")
    p.add_argument("--area", action="append", choices=AREAS, help="run only these areas (repeatable)")
    p.add_argument("--quick", action="store_true", help="fewer repetitions (for smoke tests)")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Run the selected areas and report."""
    results: list[BenchResult] = []
    for area in args.area or AREAS:
        start = time.perf_counter()
        results.extend(importlib.import_module(f"nbv.bench.{area}").run(args.quick))
        print(f"[bench] {area} done in {time.perf_counter() - start:.1f} s", flush=True)
    args.out.mkdir(parents=True, exist_ok=True)
    header = {"machine": platform.processor() or platform.machine(), "commit": git_commit(),
              "time": time.strftime("%Y-%m-%d %H:%M:%S"), "quick": args.quick}
    write_json(args.out / "bench.json", {**header, "results": [r.as_dict() for r in results]})
    table = format_table(results)
    (args.out / "bench.md").write_text(f"# Bench ({header['time']}, commit {header['commit']})\n\n{table}\n")
    print(table)
    return 0


def format_table(results: list[BenchResult]) -> str:
    """A Markdown table of the results."""
    rows = ["| area | figure | value | unit | goal |", "| --- | --- | ---: | --- | --- |"]
    rows += [f"| {r.area} | {r.name} | {r.value:.4g} | {r.unit} | {r.goal} |" for r in results]
    return "\n".join(rows)

