"""`nbv demo`: the main job end to end on a built-in scene (what `make demo` runs)."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

from tqdm import tqdm

from nbv.cli.parse import parse
from nbv.experiments.demo import DemoConfig, run_demo


def main(args: Sequence[str], prog: str) -> int:
    """Parse `DemoConfig`, run the demo, print its table and the pictures it wrote."""
    config = parse(DemoConfig, args, prog)
    with tqdm(desc="features", unit="view") as bar:
        results = run_demo(config, bar.update)
    print((Path(config.out) / "results.md").read_text())
    for name, path in results["figures"].items():
        print(f"{name}: {path}")
    return 0
