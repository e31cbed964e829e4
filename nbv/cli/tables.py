"""`nbv tables`: every result the paper reports, beside the paper's numbers (what `make tables` runs)."""

from __future__ import annotations

from collections.abc import Sequence

from tqdm import tqdm

from nbv.cli.parse import parse
from nbv.experiments.paper import QUICK, PaperConfig, run_paper


def main(args: Sequence[str], prog: str) -> int:
    """Parse `PaperConfig` (from `QUICK`'s defaults with `--quick`), run its parts, say where each went."""
    config = parse(PaperConfig, args, prog, default=QUICK if "--quick" in args else None)
    rows = len(config.scenes) * len(config.seeds) * (1 + len(config.ranges) * len(config.words))
    with tqdm(total=rows if "table2" in config.parts else 0, desc="table 2 rows", unit="row") as bar:
        run_paper(config, bar.update, lambda part, s: tqdm.write(f"[tables] {part} done in {s:.0f} s"))
    print(f"results and their index: {config.out}/README.md")
    return 0
