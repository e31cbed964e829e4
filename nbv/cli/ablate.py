"""`nbv ablate`: rendering-quality ablations, one axis at a time (what `make ablations` runs)."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

from tqdm import tqdm

from nbv.cli.parse import parse
from nbv.experiments.ablate import QUICK, AblateConfig, run_ablations, units


def main(args: Sequence[str], prog: str) -> int:
    """Parse `AblateConfig` (from `QUICK`'s defaults with `--quick`), measure every unit, print the table."""
    config = parse(AblateConfig, args, prog, default=QUICK if "--quick" in args else None)
    with tqdm(total=len(units(config)), desc="ablation units", unit="unit") as bar:
        run_ablations(config, bar.update)
    print((Path(config.out) / "ablations.md").read_text())
    return 0
