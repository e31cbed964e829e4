"""Copy a finished `nbv train` run into the package as the shipped policy (issue 11).

`nbv.rl.members.export_run` does the copying (DEST/policy.pt, config.json, training.png and the logs; a
run of several members also members.csv and memberK/), with the run folder in the recorded configs
replaced by `--name`, so no machine path is committed.

    python scripts/ship_policy.py --run runs/default --dest nbv/planning/shipped --name runs/default
"""

from __future__ import annotations

import argparse
from pathlib import Path

from nbv.rl.members import export_run


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--run", type=Path, required=True)
    parser.add_argument("--dest", type=Path, required=True)
    parser.add_argument("--name", default="runs/default")
    args = parser.parse_args()
    export_run(args.run, args.dest, args.name)


if __name__ == "__main__":
    main()
