"""Overlay the learning curves of `nbv train` runs (reward per step, episode return, steps per episode).

    .venv/bin/python scripts/plot_training.py relative=runs/rel absolute=runs/abs --out curves.png
"""

from __future__ import annotations

import argparse
from pathlib import Path

from nbv.figures import plot_training_curves


def main() -> None:
    """Parse LABEL=RUN pairs and write the PNG."""
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("runs", nargs="+", help="LABEL=RUN_FOLDER, or RUN_FOLDER (labelled by its name)")
    parser.add_argument("--out", type=Path, required=True, help="PNG to write")
    parser.add_argument("--window", type=int, default=500, help="frames averaged over per point")
    args = parser.parse_args()
    runs = {}
    for spec in args.runs:
        label, _, folder = spec.rpartition("=")
        csv_path = Path(folder) / "metrics.csv"
        if not csv_path.is_file():
            parser.error(f"{csv_path} not found: is {folder} an `nbv train` run folder?")
        runs[label or Path(folder).name] = csv_path
    print(plot_training_curves(runs, args.out, args.window))


if __name__ == "__main__":
    main()
