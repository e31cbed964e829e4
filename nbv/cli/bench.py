"""`nbv bench [--area AREA ...] [--quick] --out DIR`: measure throughput figures (what `make bench` runs)."""

from __future__ import annotations

from collections.abc import Sequence

from nbv.bench.suite import BenchConfig, format_table, run_bench
from nbv.cli.parse import parse


def main(args: Sequence[str], prog: str) -> int:
    """Parse `BenchConfig`, run the areas, print the table."""
    config = parse(BenchConfig, args, prog)
    results = run_bench(config, lambda area, s: print(f"[bench] {area} done in {s:.1f} s", flush=True))
    print(format_table(results), end="")
    return 0
